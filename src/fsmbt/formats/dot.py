"""Graphviz DOT: write FSMs (flat or hierarchical) and BTs; read simple state digraphs.

Written FSMs: every state a node (``doublecircle`` when final), the initial arrow from a
``point``-shaped start node (``__start__``, or the start pseudo-state's name, its edge labelled
with the initial event), transitions as edges labelled with their event, composite states as
``cluster_`` subgraphs with their own start point. A state whose action differs from its name
carries an ``action`` attribute (Graphviz ignores unknown attributes) and shows it in its label.
Written BTs: a top-down tree per behavior tree (→ Sequence, ? Fallback, ⇉ Parallel; conditions
as ellipses, actions as rounded boxes, decorators as hexagons, SubTree as 3-D boxes).

Read (docs/formats/dot.md) is the simple subset hand-written state digraphs use, parsed by a
small tokenizer here (no pydot): ``[strict] digraph [name] { ... }`` with node statements,
edge chains ``a -> b -> c [label="ev"]``, ``node [...]`` defaults (the classic
``node [shape=doublecircle]; F1 F2; node [shape=circle];`` idiom), and ignored graph/edge
attributes. A node with ``shape=point`` or named ``__start__`` is the start marker: its edge
names the initial state (its label, if any, the initial event). Without a marker the first
node is initial. ``shape=doublecircle`` marks a final state; an edge's ``label`` is its event
(no label: an eventless transition); ``action=`` gives a state's action (else its name);
node labels are display only. Subgraphs, undirected graphs, ports and HTML labels raise a clear
error. Tokenizing and parsing are O(n) in the input size.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model import Model
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State

START_NODE = "__start__"


# -- tokenizer ------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Token:
    kind: str  # "id" | "punct" | "edgeop"
    text: str
    line: int
    column: int


_TOKEN = re.compile(r"""
    (?P<space>[ \t\r\f\v]+)
  | (?P<newline>\n)
  | (?P<line_comment>//[^\n]*)
  | (?P<block_comment>/\*.*?\*/)
  | (?P<quoted>"(?:[^"\\]|\\.|\\\n)*")
  | (?P<edgeop>->|--)
  | (?P<number>-?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?))
  | (?P<name>[A-Za-z_\u0080-\U0010ffff][A-Za-z_0-9\u0080-\U0010ffff]*)
  | (?P<punct>[{}\[\];,=:])
  | (?P<html><)
""", re.VERBOSE | re.DOTALL)


def _tokenize(text: str, ctx: ReadContext) -> list[_Token]:
    tokens: list[_Token] = []
    position, line, line_start = 0, 1, 0
    at_line_start = True
    while position < len(text):
        if at_line_start and text.startswith("#", position):  # C-preprocessor style line
            end = text.find("\n", position)
            position = len(text) if end < 0 else end
            continue
        match = _TOKEN.match(text, position)
        column = position - line_start + 1
        if match is None:
            raise InputError(f"unexpected character {text[position]!r} in DOT",
                             location=ctx.location(line, column))
        kind = match.lastgroup or ""
        value = match.group()
        if kind == "html":
            raise UnsupportedError("HTML-like labels (<...>) are not read",
                                   location=ctx.location(line, column))
        if kind == "block_comment" and not value.endswith("*/"):
            raise InputError("unterminated comment", location=ctx.location(line, column))
        if kind == "quoted":
            tokens.append(_Token("id", value[1:-1].replace("\\\n", "").replace('\\"', '"'),
                                 line, column))
        elif kind in ("name", "number"):
            tokens.append(_Token("id", value, line, column))
        elif kind in ("punct", "edgeop"):
            tokens.append(_Token(kind, value, line, column))
        newlines = value.count("\n")
        if newlines:
            line += newlines
            line_start = position + value.rfind("\n") + 1
        at_line_start = kind == "newline" or (at_line_start and kind == "space")
        position = match.end()
    return tokens


# -- parser ---------------------------------------------------------------------------------
class _DotReader:
    """Recursive descent over a flat statement list; no recursion (subgraphs are refused)."""

    def __init__(self, tokens: list[_Token], ctx: ReadContext) -> None:
        self.tokens = tokens
        self.pos = 0
        self.ctx = ctx
        self.node_defaults: dict[str, str] = {}
        self.nodes: dict[str, dict[str, str]] = {}  # id -> attrs, in order of first mention
        self.node_line: dict[str, int] = {}
        self.edges: list[tuple[str, str, dict[str, str], int]] = []

    def peek(self) -> _Token | None:
        return self.tokens[self.pos] if self.pos < len(self.tokens) else None

    def take(self) -> _Token:
        token = self.peek()
        if token is None:
            last = self.tokens[-1] if self.tokens else None
            raise InputError("unexpected end of DOT input (missing '}'?)",
                             location=self.ctx.location(last.line if last else None))
        self.pos += 1
        return token

    def error(self, token: _Token, message: str, unsupported: bool = False) -> InputError:
        cls = UnsupportedError if unsupported else InputError
        return cls(message, location=self.ctx.location(token.line, token.column))

    def expect(self, text: str) -> _Token:
        token = self.take()
        if token.text != text or token.kind == "id" and text in "{}[];,=":
            raise self.error(token, f"expected '{text}', found '{token.text}'")
        return token

    def read(self) -> FSM:
        first = self.take()
        if first.kind == "id" and first.text.lower() == "strict":
            first = self.take()
        if first.kind != "id" or first.text.lower() not in ("digraph", "graph"):
            raise self.error(first, f"a DOT file starts with 'digraph', found '{first.text}'")
        if first.text.lower() == "graph":
            raise self.error(first, "an undirected graph is not a state machine; use 'digraph'",
                             unsupported=True)
        name = "fsm"
        token = self.peek()
        if token is not None and token.kind == "id":
            name = self.take().text
        elif self.ctx.path is not None:
            name = self.ctx.path.stem
        self.expect("{")
        while True:
            token = self.peek()
            if token is None:
                raise InputError("unexpected end of DOT input: missing '}'",
                                 location=self.ctx.location(self.tokens[-1].line))
            if token.kind == "punct" and token.text == "}":
                self.take()
                break
            if token.kind == "punct" and token.text in ";,":
                self.take()
                continue
            self.statement()
        extra = self.peek()
        if extra is not None:
            raise self.error(extra, "text after the closing '}' (one graph per file)")
        return self.build(name)

    def attributes(self) -> dict[str, str]:
        """Zero or more ``[a=b, c=d]`` lists."""
        attrs: dict[str, str] = {}
        while (token := self.peek()) is not None and token.kind == "punct" and token.text == "[":
            self.take()
            while True:
                token = self.take()
                if token.kind == "punct" and token.text == "]":
                    break
                if token.kind == "punct" and token.text in ";,":
                    continue
                if token.kind != "id":
                    raise self.error(token, f"expected an attribute name, found '{token.text}'")
                self.expect("=")
                value = self.take()
                if value.kind != "id":
                    raise self.error(value, f"expected a value for '{token.text}'")
                attrs[token.text] = value.text
        return attrs

    def statement(self) -> None:
        token = self.take()
        if token.kind == "punct" and token.text == "{" or (
                token.kind == "id" and token.text.lower() == "subgraph"):
            raise self.error(token, "subgraphs and clusters are not read (fsmbt reads simple "
                                    "state digraphs; composite states: use Mermaid, SCXML or "
                                    "JSON)", unsupported=True)
        if token.kind != "id":
            raise self.error(token, f"unexpected '{token.text}'")
        keyword = token.text.lower()
        following = self.peek()
        if keyword in ("graph", "node", "edge") and following is not None and following.text == "[":
            attrs = self.attributes()
            if keyword == "node":
                self.node_defaults.update(attrs)
            return
        if following is not None and following.kind == "punct" and following.text == "=":
            self.take()
            self.take()  # graph attribute such as rankdir=LR: display only
            return
        if following is not None and following.kind == "punct" and following.text == ":":
            raise self.error(following, "node ports (a:port) are not read", unsupported=True)
        chain = [token]
        while (op := self.peek()) is not None and op.kind == "edgeop":
            self.take()
            if op.text == "--":
                raise self.error(op, "'--' is an undirected edge; a digraph uses '->'")
            target = self.take()
            if target.kind != "id":
                raise self.error(target, f"expected a node after '->', found '{target.text}'")
            chain.append(target)
        attrs = self.attributes()
        for node in chain:
            self.mention(node, {} if len(chain) > 1 else attrs)
        for source, target in zip(chain, chain[1:]):
            self.edges.append((source.text, target.text, attrs, source.line))

    def mention(self, token: _Token, attrs: dict[str, str]) -> None:
        if token.text not in self.nodes:
            self.nodes[token.text] = dict(self.node_defaults)
            self.node_line[token.text] = token.line
        self.nodes[token.text].update(attrs)

    def build(self, name: str) -> FSM:
        fsm = FSM(name=name)
        markers = {n for n, a in self.nodes.items()
                   if n == START_NODE or a.get("shape", "").lower() == "point"}
        for node, attrs in self.nodes.items():
            if node in markers:
                continue
            action: str | None = attrs.get("action", node)
            fsm.add_state(State(node, action=action or None,
                                final=attrs.get("shape", "").lower() == "doublecircle",
                                location=self.ctx.location(self.node_line[node])))
        fsm.initial = next(iter(fsm.states), None)
        start_edges = [e for e in self.edges if e[0] in markers]
        if len(start_edges) > 1:
            raise InputError("more than one initial arrow (edges from the start marker)",
                             location=self.ctx.location(start_edges[1][3]))
        for source, target, attrs, line in self.edges:
            if target in markers:
                raise InputError(f"edge into the start marker '{target}'",
                                 location=self.ctx.location(line))
            label = attrs.get("label") or None
            if source in markers:
                fsm.initial = target
                if source != START_NODE:
                    fsm.start_name = source
                if label is not None:
                    fsm.initial_event = label
                    fsm.start_name = fsm.start_name or "Start"
                continue
            fsm.add_transition(source, label, target, location=self.ctx.location(line))
        if not fsm.states:
            raise InputError("the digraph has no states", location=self.ctx.location())
        return fsm


def read_dot(text: str, ctx: ReadContext) -> Model:
    tokens = _tokenize(text, ctx)
    if not tokens:
        raise InputError("empty DOT input", location=ctx.location())
    return _DotReader(tokens, ctx).read()


# -- writer ---------------------------------------------------------------------------------
def quote(text: str) -> str:
    """A DOT double-quoted string (``"`` escaped; a trailing backslash cannot end it)."""
    body = text.replace('"', '\\"')
    if body.endswith("\\") and not body.endswith('\\"'):
        body += " "
    return f'"{body}"'


def _label(text: str) -> str:
    """A label: backslash sequences (\\n, \\N) would be interpreted, so backslashes double."""
    return quote(text.replace("\\", "\\\\"))


def write_fsm_dot(fsm: FSM) -> str:
    lines = [f"digraph {quote(fsm.name)} {{", "    rankdir=LR;", "    compound=true;",
             "    node [shape=circle, fontname=\"Helvetica\"];",
             "    edge [fontname=\"Helvetica\", fontsize=10];"]
    # explicit stack of (machine, path prefix, indent); composite states become clusters
    stack: list[tuple[FSM, str, int, str | None]] = [(fsm, "", 1, None)]
    body: list[str] = []
    edges: list[str] = []
    while stack:
        machine, prefix, depth, closing = stack.pop()
        pad = "    " * depth
        if closing is not None:
            body.append(closing)
            continue
        start_id = f"{prefix}{machine.start_name or START_NODE}"
        anchor = {name: f"{prefix}{name}" for name in machine.states}
        cluster = {name: f"cluster_{prefix}{name}" for name, s in machine.states.items()
                   if s.regions}
        if machine.initial is not None:
            body.append(f"{pad}{quote(start_id)} [shape=point, width=0.15, label=\"\"];")
            start_attrs = f" [label={_label(machine.initial_event)}]" if machine.initial_event else ""
            target = anchor.get(machine.initial, f"{prefix}{machine.initial}")
            extra = ""
            if machine.initial in cluster:
                target = f"{prefix}{machine.initial}/{machine.states[machine.initial].regions[0].start_name or START_NODE}"
                extra = f" [lhead={quote(cluster[machine.initial])}]"
            edges.append(f"    {quote(start_id)} -> {quote(target)}{start_attrs}{extra}")
        for state in machine.states.values():
            node_id = anchor[state.name]
            if state.regions:
                continue
            attrs = []
            if state.final:
                attrs.append("shape=doublecircle")
            shown = state.name if state.action in (state.name, None) else f"{state.name}\n/ {state.action}"
            if state.action != state.name:
                attrs.append(f"action={quote(state.action or '')}")
            attrs.append(f"label={quote(shown)}")
            body.append(f"{pad}{quote(node_id)} [{', '.join(attrs)}];")
        for t in machine.transitions:
            source, target = anchor.get(t.source, prefix + t.source), anchor.get(t.target, prefix + t.target)
            edge_attrs: list[str] = []
            if t.source in cluster:
                inner = machine.states[t.source].regions[0]
                source = f"{prefix}{t.source}/{inner.start_name or START_NODE}"
                edge_attrs.append(f"ltail={quote(cluster[t.source])}")
            if t.target in cluster:
                inner = machine.states[t.target].regions[0]
                target = f"{prefix}{t.target}/{inner.start_name or START_NODE}"
                edge_attrs.append(f"lhead={quote(cluster[t.target])}")
            if t.event is not None:
                edge_attrs.insert(0, f"label={_label(t.event)}")
            suffix = f" [{', '.join(edge_attrs)}]" if edge_attrs else ""
            edges.append(f"    {quote(source)} -> {quote(target)}{suffix}")
        for state in reversed([s for s in machine.states.values() if s.regions]):
            inner_prefix = f"{prefix}{state.name}/"
            stack.append((machine, prefix, depth, f"{pad}}}"))
            for index, region in reversed(list(enumerate(state.regions))):
                region_prefix = inner_prefix if len(state.regions) == 1 else f"{inner_prefix}{index}:"
                stack.append((region, region_prefix, depth + 1, None))
            title = state.name + (" (parallel)" if state.is_parallel else "")
            stack.append((machine, prefix, depth,
                          f"{pad}subgraph {quote(cluster[state.name])} {{\n{pad}    "
                          f"label={_label(title)}; style=rounded;"))
    return "\n".join(lines + body + edges + ["}"]) + "\n"


_SYMBOLS = {
    "Sequence": "→", "SequenceWithMemory": "→*", "ReactiveSequence": "R→", "AsyncSequence": "→",
    "Fallback": "?", "ReactiveFallback": "R?", "AsyncFallback": "?",
    "Parallel": "⇉", "ParallelAll": "⇉",
}
_SHAPES = {
    NodeKind.CONTROL: 'shape=box, style="filled", fillcolor="#dddddd"',
    NodeKind.DECORATOR: 'shape=hexagon, style="filled", fillcolor="#f3e6c4"',
    NodeKind.CONDITION: 'shape=ellipse, style="filled", fillcolor="#d5ecd4"',
    NodeKind.ACTION: 'shape=box, style="rounded,filled", fillcolor="#d4e4f7"',
    NodeKind.SUBTREE: 'shape=box3d, style="filled", fillcolor="#eeeeee"',
}


def _bt_label(node: BTNode) -> str:
    symbol = _SYMBOLS.get(node.type)
    if node.kind is NodeKind.SUBTREE:
        head = f"SubTree {node.subtree_id or '?'}"
        return head if node.name in (None, node.subtree_id) else f"{head}\n{node.name}"
    if symbol is not None:
        return symbol if node.name in (None, node.type) else f"{symbol}\n{node.name}"
    if node.name and node.name != node.type:
        return f"{node.name}\n({node.type})"
    return node.type


def write_bt_dot(doc: BTDocument) -> str:
    lines = ["digraph \"bt\" {", "    rankdir=TB;", "    ordering=out;",
             "    node [fontname=\"Helvetica\"];"]
    counter = 0
    several = len(doc.trees) > 1
    for tree in doc.trees.values():
        pad = "        " if several else "    "
        if several:
            main = " (main)" if tree.id == doc.main.id else ""
            lines.append(f"    subgraph {quote('cluster_' + tree.id)} {{")
            lines.append(f"        label={_label(tree.id + main)}; style=rounded;")
        if tree.root is None:
            lines.append(f"{pad}{quote(f'n{counter}')} [label={_label(tree.id + ' (empty)')}];")
            counter += 1
        else:
            stack: list[tuple[BTNode, str | None]] = [(tree.root, None)]
            while stack:  # iterative pre-order: trees may be 100 000 deep
                node, parent = stack.pop()
                node_id = f"n{counter}"
                counter += 1
                lines.append(f"{pad}{node_id} [label={_label(_bt_label(node))}, "
                             f"{_SHAPES[node.kind]}];")
                if parent is not None:
                    lines.append(f"{pad}{parent} -> {node_id};")
                stack.extend((child, node_id) for child in reversed(node.children))
        if several:
            lines.append("    }")
    lines.append("}")
    return "\n".join(lines) + "\n"


def write_dot(model: Model) -> str:
    return write_fsm_dot(model) if isinstance(model, FSM) else write_bt_dot(model)


def _sniff(text: str) -> bool:
    """The first word (after comments) is ``digraph``, ``graph`` or ``strict``."""
    head = re.sub(r"//[^\n]*|/\*.*?\*/|^#[^\n]*", "", text[:4096], flags=re.S | re.M).lstrip()
    return re.match(r"(?i)(strict\s+)?(di)?graph\b", head) is not None


register(Format("dot", (".dot", ".gv"), frozenset({"fsm", "bt"}),
                "Graphviz DOT (write FSM/BT; read simple state digraphs)",
                read_dot, write_dot, _sniff, priority=26))
