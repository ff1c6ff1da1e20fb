"""A behavior tree document as a Graphviz picture, top-down, children left to right.

Symbols (the usual BT notation, BehaviorTree.CPP v4 meaning): Sequence ``→``, Fallback ``?``,
Parallel ``⇉``; reactive variants prefixed ``R`` (``R→``, ``R?``), memory variant ``→*``, async
variants suffixed ``async``. Control nodes are grey boxes with the symbol; decorators are
hexagons with their name (Inverter ``¬``); conditions are ellipses, actions boxes with rounded
corners; a SubTree reference is a folder tab. A node's name (when it differs from its type) and
its attributes (ports, parameters; long values shortened) are shown under the symbol.

Every tree of the document is drawn, each in a cluster when there are several. With
``expand_subtrees`` only the main tree is drawn and each SubTree reference gets the tree it names
below it, in a dashed cluster (a recursive reference is not expanded again). Built with an
explicit stack; complexity O(N) for N drawn nodes, refused beyond ``max_nodes``.

This is also the DOT file format's BT writer (``fsmbt convert --to dot``, through
``fsmbt.formats.dot``, with no size limit); BT DOT is write-only (docs/formats/dot.md).
"""

from __future__ import annotations

import graphviz

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind, canonical_type
from fsmbt.model.errors import Hint, InputError
from fsmbt.render.anchor_ids import child_path, node_anchor
from fsmbt.render.dot import (
    DEFAULT_MAX_NODES,
    FONT,
    TooLargeError,
    assemble,
    check_size,
    edge_line,
    html_label,
    label_text,
)

CONTROL_SYMBOLS: dict[str, str] = {
    "Sequence": "→",
    "ReactiveSequence": "R→",
    "SequenceWithMemory": "→*",
    "AsyncSequence": "→ async",
    "Fallback": "?",
    "ReactiveFallback": "R?",
    "AsyncFallback": "? async",
    "Parallel": "⇉",
    "ParallelAll": "⇉ all",
    "ManualSelector": "? manual",
    "IfThenElse": "if / then / else",
    "WhileDoElse": "while / do / else",
}
DECORATOR_SYMBOLS: dict[str, str] = {
    "Inverter": "¬",
    "ForceSuccess": "ForceSuccess ✓",
    "ForceFailure": "ForceFailure ✗",
    "Repeat": "Repeat ↻",
    "RetryUntilSuccessful": "Retry ↻",
    "KeepRunningUntilFailure": "KeepRunning ↻",
}
#: Attribute values longer than this are shortened in labels.
MAX_VALUE_CHARS = 32
#: At most this many attributes are listed under a node.
MAX_ATTRS_SHOWN = 4


def bt_to_dot(doc: BTDocument, *, expand_subtrees: bool = False,
              max_nodes: int | None = DEFAULT_MAX_NODES, anchors: bool = False) -> str:
    """DOT source of the picture of ``doc``.

    Args:
        doc: the behavior tree document.
        expand_subtrees: draw the main tree only, each SubTree reference with its tree below it.
        max_nodes: refuse (``TooLargeError``) more drawn nodes than this; ``None``: no limit.
        anchors: give every node an SVG id from its place (``fsmbt.render.anchor_ids``): the
            child-index path from the main root with ``expand_subtrees`` (the interpreter's
            path, docs/semantics.md), else the tree's id and the path inside that tree.

    Returns:
        The DOT source text.
    """
    if not doc.trees:
        raise InputError("the document holds no behavior tree")
    if not expand_subtrees and max_nodes is not None:
        check_size(sum(1 for _ in doc.nodes()), max_nodes, "nodes")
    root = graphviz.Digraph(name="bt")
    root.attr(rankdir="TB", ordering="out", fontname=FONT, nodesep="0.25", ranksep="0.45")
    root.attr("node", fontname=FONT, fontsize="11", height="0.4")
    root.attr("edge", arrowsize="0.6", color="gray25")
    builder = _Builder(doc, root, max_nodes, expand_subtrees, anchors)
    if expand_subtrees:
        main = doc.main
        builder.draw_tree(main.root, root, parent=None, path=(main.id,))
    else:
        several = len(doc.trees) > 1
        for tree in doc.trees.values():
            holder = root
            if several:
                holder = graphviz.Digraph(name=builder.next_id("cluster_"))
                title = f"{tree.id} (main)" if tree.id == doc.main.id else tree.id
                holder.attr(label=label_text(title), style="rounded", color="gray40",
                            fontname=FONT, fontsize="12", labeljust="l")
                builder.clusters.append((holder, root))
            builder.draw_tree(tree.root, holder, parent=None, path=(tree.id,))
    return builder.finish()


class _Builder:
    def __init__(self, doc: BTDocument, root: graphviz.Digraph, max_nodes: int | None,
                 expanding: bool, anchors: bool = False) -> None:
        self.doc = doc
        self.anchors = anchors
        self.expanding = expanding
        self.root = root
        self.max_nodes = max_nodes
        self.count = 0
        self.serial = 0
        self.edges: list[tuple[str, str, dict[str, str]]] = []
        self.clusters: list[tuple[graphviz.Digraph, graphviz.Digraph]] = []  # pre-order

    def next_id(self, prefix: str) -> str:
        self.serial += 1
        return f"{prefix}{self.serial}"

    def draw_tree(self, top: BTNode | None, graph: graphviz.Digraph, *, parent: str | None,
                  path: tuple[str, ...]) -> None:
        if top is None:
            graph.node(self.next_id("n"), label="(empty tree)", shape="plaintext")
            return
        stack: list[tuple[BTNode, str | None, graphviz.Digraph, tuple[str, ...], str]] = [
            (top, parent, graph, path, "")]
        while stack:
            node, parent_id, holder, trees, where = stack.pop()
            self.count += 1
            if self.max_nodes is not None and self.count > self.max_nodes:
                raise TooLargeError(f"too large to draw: more than {self.max_nodes} nodes "
                                    f"(limit {self.max_nodes})",
                                    hints=(Hint.MAX_NODES, Hint.NO_EXPANSION))
            node_id = self.next_id("n")
            attrs = node_attrs(node, recursive=node.subtree_id in trees)
            if self.anchors:
                attrs["id"] = node_anchor(where, None if self.expanding else trees[0])
            holder.node(node_id, **attrs)
            if parent_id is not None:
                self.edges.append((parent_id, node_id, {}))
            ref = node.subtree_id
            if self.expanding and ref is not None and ref in self.doc.trees and ref not in trees:
                cluster = graphviz.Digraph(name=self.next_id("cluster_"))
                cluster.attr(label=label_text(ref), style="dashed,rounded", color="gray50",
                             fontname=FONT, fontsize="10", labeljust="l")
                self.clusters.append((cluster, holder))
                sub_root = self.doc.trees[ref].root
                if sub_root is not None:
                    stack.append((sub_root, node_id, cluster, (*trees, ref), child_path(where, 0)))
            stack.extend((child, node_id, holder, trees, child_path(where, index))
                         for index, child in reversed(list(enumerate(node.children))))

    def finish(self) -> str:
        return assemble(self.root, self.clusters,
                        [edge_line(tail, head, attrs) for tail, head, attrs in self.edges])


def node_attrs(node: BTNode, *, recursive: bool = False) -> dict[str, str]:
    """Shape, style and label of one node."""
    type_name = canonical_type(node.type)
    shown = [(k, v) for k, v in node.attrs.items()
             if not (node.kind is NodeKind.SUBTREE and k == "ID")]
    details = [f"{k}={_shorten(v)}" for k, v in shown[:MAX_ATTRS_SHOWN]]
    if len(shown) > MAX_ATTRS_SHOWN:
        details.append(f"… (+{len(shown) - MAX_ATTRS_SHOWN})")
    name = [node.name] if node.name is not None and node.name != node.type else []
    if node.kind is NodeKind.CONTROL:
        symbol = CONTROL_SYMBOLS.get(type_name, type_name)
        return {"label": html_label([symbol, *name], details, head_size=16 if len(symbol) <= 2 else 12),
                "shape": "box", "style": "filled", "fillcolor": "gray88"}
    if node.kind is NodeKind.DECORATOR:
        symbol = DECORATOR_SYMBOLS.get(type_name, type_name)
        return {"label": html_label([symbol, *name], details, head_size=16 if len(symbol) <= 2 else None),
                "shape": "hexagon", "style": "filled", "fillcolor": "lightcyan"}
    if node.kind is NodeKind.SUBTREE:
        ref = node.subtree_id or "?"
        head = [f"SubTree {ref}"] + [n for n in name if n != ref]
        if recursive:
            details.insert(0, "(recursive: not expanded)")
        return {"label": html_label(head, details), "shape": "tab", "style": "filled",
                "fillcolor": "lavender"}
    head = [node.label] + ([f"({node.type})"] if name else [])
    if node.kind is NodeKind.CONDITION:
        return {"label": html_label(head, details), "shape": "ellipse", "style": "filled",
                "fillcolor": "honeydew"}
    # An action whose kind nobody declared (assumed Action) gets a dashed border.
    style = "rounded,filled" if node.kind_declared else "rounded,filled,dashed"
    return {"label": html_label(head, details), "shape": "box", "style": style,
            "fillcolor": "lightyellow"}


def _shorten(value: str) -> str:
    value = " ".join(value.split())
    return value if len(value) <= MAX_VALUE_CHARS else value[: MAX_VALUE_CHARS - 1] + "…"
