"""Graphviz DOT: write FSMs (flat or hierarchical) and BTs; read simple state digraphs.

Writing goes through the one DOT writer, ``fsmbt.render`` (``fsm_to_dot(..., exchange=True)``,
``bt_to_dot``), so ``fsmbt convert --to dot`` and ``fsmbt render x.dot`` draw with the same
shapes, symbols and clusters. Written FSMs: every state a node whose id is its name (a path
inside composite states; ``doublecircle`` when final, an ``action`` attribute when its action
differs from its name), the initial arrow from a ``point``-shaped start node (``__start__``, or
the start pseudo-state's name, its edge labelled with the initial event), one edge per
transition labelled with its event, composite states as ``cluster_`` subgraphs with their own
start point. Written BTs: the picture's top-down tree per behavior tree (write-only).

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
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.render.bt_graph import bt_to_dot
from fsmbt.render.fsm_graph import START_NODE, fsm_to_dot


# -- tokenizer ------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Token:
    kind: str  # "id" | "punct" | "edgeop"
    text: str
    line: int
    column: int


_TOKEN = re.compile(
    r"""
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
""",
    re.VERBOSE | re.DOTALL,
)


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
            raise InputError(
                f"unexpected character {text[position]!r} in DOT",
                location=ctx.location(line, column),
            )
        kind = match.lastgroup or ""
        value = match.group()
        if kind == "html":
            raise UnsupportedError(
                "HTML-like labels (<...>) are not read", location=ctx.location(line, column)
            )
        if kind == "block_comment" and not value.endswith("*/"):
            raise InputError("unterminated comment", location=ctx.location(line, column))
        if kind == "quoted":
            tokens.append(
                _Token("id", value[1:-1].replace("\\\n", "").replace('\\"', '"'), line, column)
            )
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
            raise InputError(
                "unexpected end of DOT input (missing '}'?)",
                location=self.ctx.location(last.line if last else None),
            )
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
            raise self.error(
                first, "an undirected graph is not a state machine; use 'digraph'", unsupported=True
            )
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
                raise InputError(
                    "unexpected end of DOT input: missing '}'",
                    location=self.ctx.location(self.tokens[-1].line),
                )
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
        if (
            token.kind == "punct"
            and token.text == "{"
            or (token.kind == "id" and token.text.lower() == "subgraph")
        ):
            raise self.error(
                token,
                "subgraphs and clusters are not read (fsmbt reads simple "
                "state digraphs; composite states: use Mermaid, SCXML or "
                "JSON)",
                unsupported=True,
            )
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
        markers = {
            n
            for n, a in self.nodes.items()
            if n == START_NODE or a.get("shape", "").lower() == "point"
        }
        for node, attrs in self.nodes.items():
            if node in markers:
                continue
            action: str | None = attrs.get("action", node)
            fsm.add_state(
                State(
                    node,
                    action=action or None,
                    final=attrs.get("shape", "").lower() == "doublecircle",
                    location=self.ctx.location(self.node_line[node]),
                )
            )
        fsm.initial = next(iter(fsm.states), None)
        start_edges = [e for e in self.edges if e[0] in markers]
        if len(start_edges) > 1:
            raise InputError(
                "more than one initial arrow (edges from the start marker)",
                location=self.ctx.location(start_edges[1][3]),
            )
        for source, target, attrs, line in self.edges:
            if target in markers:
                raise InputError(
                    f"edge into the start marker '{target}'", location=self.ctx.location(line)
                )
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
def write_dot(model: Model) -> str:
    """The DOT file of ``model``, written by the one DOT writer (``fsmbt.render``).

    FSMs use its exchange mode (state names as node ids, one edge per transition, exact event
    labels) so that ``read_dot`` reads a flat FSM back exactly; BTs are the picture's DOT
    (write-only). No size limit applies, unlike ``fsmbt render``.

    Args:
        model: an FSM or a BT document.

    Returns:
        The DOT source text.
    """
    if isinstance(model, FSM):
        return fsm_to_dot(model, max_nodes=None, exchange=True)
    return bt_to_dot(model, max_nodes=None)


def _sniff(text: str) -> bool:
    """The first word (after comments) is ``digraph``, ``graph`` or ``strict``."""
    head = re.sub(r"//[^\n]*|/\*.*?\*/|^#[^\n]*", "", text[:4096], flags=re.S | re.M).lstrip()
    return re.match(r"(?i)(strict\s+)?(di)?graph\b", head) is not None


register(
    Format(
        "dot",
        (".dot", ".gv"),
        frozenset({"fsm", "bt"}),
        "Graphviz DOT (write FSM/BT; read simple state digraphs)",
        read_dot,
        write_dot,
        _sniff,
        priority=26,
    )
)
