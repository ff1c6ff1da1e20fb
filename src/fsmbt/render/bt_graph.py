"""A behavior tree document as a Graphviz picture, top-down, children left to right.

Symbols (the usual BT notation, BehaviorTree.CPP v4 meaning): Sequence ``→``, Fallback ``?``,
Parallel ``⇉``; reactive variants prefixed ``R`` (``R→``, ``R?``), memory variant ``→*``, async
variants suffixed ``async``. Control nodes are grey boxes with the symbol; decorators are
hexagons with their name (Inverter ``¬``); conditions are ellipses, actions boxes with rounded
corners; a SubTree reference is a folder tab. A node's name (when it differs from its type) and
its attributes (ports, parameters; long values shortened) are shown under the symbol.

Every tree of the document is drawn, each in a cluster when there are several: the main tree
first, alone on the top row, the others below it in rows of at most ``ROW_LEAVES`` leaves (each
row hangs under the previous one by invisible edges), so a 24-tree file reads top to bottom
instead of as one strip tens of thousands of pixels wide. A picture holds at most
``PICTURE_MAX_NODES`` nodes: past it, trees are drawn in that order while they fit and a note
(``notes``) says how many were left out and how to draw them (``tree=ID``). With
``expand_subtrees`` only the main tree is drawn and each SubTree reference gets the tree it names
below it, in a dashed cluster (a recursive reference is not expanded again). Built with an
explicit stack; complexity O(N) for N drawn nodes, refused beyond ``max_nodes``.

This is also the DOT file format's BT writer (``fsmbt convert --to dot``, through
``fsmbt.formats.diagrams.dot``, with no size limit); BT DOT is write-only (docs/formats/dot.md).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

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
#: Trees after the main one are packed into rows of at most this many leaves (a width proxy).
ROW_LEAVES = 24
#: The most nodes drawn in one multi-tree picture before the remaining trees are left out.
PICTURE_MAX_NODES = 600


def _tree_size(root: BTNode | None) -> tuple[int, int, int]:
    """(nodes, leaves, depth) of one tree, explicit stack."""
    if root is None:
        return 1, 1, 1
    nodes = leaves = depth = 0
    stack = [(root, 1)]
    while stack:
        node, level = stack.pop()
        nodes += 1
        depth = max(depth, level)
        if not node.children:
            leaves += 1
        stack.extend((child, level + 1) for child in node.children)
    return nodes, leaves, depth


def bt_to_dot(
    doc: BTDocument,
    *,
    expand_subtrees: bool = False,
    max_nodes: int | None = DEFAULT_MAX_NODES,
    tree: str | None = None,
    notes: list[str] | None = None,
    anchors: bool = False,
    marks: Mapping[str, Mapping[str, str]] | None = None,
    ghosts: Sequence[Ghost] = (),
) -> str:
    """DOT source of the picture of ``doc``.

    Args:
        doc: the behavior tree document.
        expand_subtrees: draw the main tree only, each SubTree reference with its tree below it.
        max_nodes: refuse (``TooLargeError``) more drawn nodes than this; ``None``: no limit.
        tree: draw only this tree (with ``expand_subtrees``: its SubTrees inlined).
        notes: told what was left out of the picture and how to draw it.
        anchors: give every node an SVG id from its place (``fsmbt.render.anchor_ids``): the
            child-index path from the main root with ``expand_subtrees`` (the interpreter's
            path, docs/semantics.md), else the tree's id and the path inside that tree.
        marks: extra Graphviz attributes per node, keyed by the node's anchor id (as above,
            whether or not ``anchors`` is set): how a diff highlights changed nodes.
        ghosts: nodes that are not in ``doc`` (a diff's removed nodes), drawn dashed and grey
            under the node whose anchor they name (or alone).

    Returns:
        The DOT source text.

    Raises:
        InputError: no tree, or ``tree`` names none (the message lists the trees).
    """
    if not doc.trees:
        raise InputError("the document holds no behavior tree")
    if tree is not None:
        if tree not in doc.trees:
            raise InputError(f"no tree '{tree}' (trees: {', '.join(doc.trees)})", element=tree)
        doc = dataclasses.replace(doc, main_tree=tree)
    if not expand_subtrees and max_nodes is not None:
        check_size(sum(1 for _ in doc.nodes()), max_nodes, "nodes")
    root = graphviz.Digraph(name="bt")
    root.attr(rankdir="TB", ordering="out", fontname=FONT, nodesep="0.25", ranksep="0.45")
    root.attr("node", fontname=FONT, fontsize="11", height="0.4")
    root.attr("edge", arrowsize="0.6", color="gray25")
    builder = _Builder(doc, root, max_nodes, expand_subtrees, anchors)
    builder.marks = marks or {}
    if expand_subtrees or tree is not None:
        main = doc.main
        builder.draw_tree(main.root, root, parent=None, path=(main.id,))
    else:
        _draw_all_trees(doc, root, builder, notes)
    builder.draw_ghosts(ghosts)
    return builder.finish()


@dataclasses.dataclass(frozen=True)
class Ghost:
    """A node drawn although it is not in the document (a diff's removed node).

    Attributes:
        label: its text.
        parent: the anchor id of the drawn node it hangs under, or ``None`` (drawn alone).
    """

    label: str
    parent: str | None = None


#: How a ghost looks: dashed, grey, no fill.
GHOST_STYLE = {"style": "dashed,rounded", "color": "gray55", "fontcolor": "gray45", "shape": "box"}


def _draw_all_trees(
    doc: BTDocument, root: graphviz.Digraph, builder: _Builder, notes: list[str] | None
) -> None:
    """Every tree (main first, then rows), each in a cluster when there are several."""
    main_id = doc.main.id
    order = [doc.trees[main_id]] + [t for t in doc.trees.values() if t.id != main_id]
    if len(order) == 1:
        builder.draw_tree(order[0].root, root, parent=None, path=(main_id,))
        return
    sizes = {t.id: _tree_size(t.root) for t in order}
    total = sum(n for n, _, _ in sizes.values())
    left_out: list[str] = []
    rows: list[list[str]] = [[main_id]]  # the main tree alone on the top row
    drawn = sizes[main_id][0]
    row_leaves = ROW_LEAVES  # so the first other tree opens a new row
    for t in order[1:]:
        nodes, leaves, _ = sizes[t.id]
        if drawn + nodes > PICTURE_MAX_NODES:
            left_out.append(t.id)
            continue
        drawn += nodes
        if row_leaves + leaves > ROW_LEAVES:
            rows.append([])
            row_leaves = 0
        rows[-1].append(t.id)
        row_leaves += leaves
    previous_bottom: str | None = None
    for row in rows:
        deepest: tuple[int, str] | None = None
        for tree_id in row:
            t = doc.trees[tree_id]
            holder = graphviz.Digraph(name=builder.next_id("cluster_"))
            title = f"{tree_id} (main)" if tree_id == main_id else tree_id
            holder.attr(
                label=label_text(title),
                style="rounded",
                color="gray40",
                fontname=FONT,
                fontsize="12",
                labeljust="l",
            )
            builder.clusters.append((holder, root))
            first = builder.serial + 1
            builder.draw_tree(t.root, holder, parent=None, path=(tree_id,))
            if previous_bottom is not None:  # hang this row under the previous one
                builder.edges.append(
                    (previous_bottom, f"n{first}", {"style": "invis", "weight": "0"})
                )
            depth = sizes[tree_id][2]
            if deepest is None or depth > deepest[0]:
                deepest = (depth, builder.deepest)
        previous_bottom = deepest[1] if deepest is not None else previous_bottom
    if left_out and notes is not None:
        shown = ", ".join(left_out[:8]) + (
            f", ... (+{len(left_out) - 8})" if len(left_out) > 8 else ""
        )
        notes.append(
            f"picture capped at {PICTURE_MAX_NODES} nodes: drew {len(order) - len(left_out)}"
            f" of {len(order)} trees ({drawn} of {total} nodes); left out: {shown}; "
            "draw one tree alone with tree=ID"
        )


class _Builder:
    def __init__(
        self,
        doc: BTDocument,
        root: graphviz.Digraph,
        max_nodes: int | None,
        expanding: bool,
        anchors: bool = False,
    ) -> None:
        self.doc = doc
        self.anchors = anchors
        self.expanding = expanding
        self.root = root
        self.max_nodes = max_nodes
        self.count = 0
        self.serial = 0
        self.deepest = ""  # the deepest node id of the last tree drawn
        self.edges: list[tuple[str, str, dict[str, str]]] = []
        self.clusters: list[tuple[graphviz.Digraph, graphviz.Digraph]] = []  # pre-order
        self.marks: Mapping[str, Mapping[str, str]] = {}
        self.by_anchor: dict[str, str] = {}  # anchor id -> DOT node id, for ghosts

    def next_id(self, prefix: str) -> str:
        self.serial += 1
        return f"{prefix}{self.serial}"

    def draw_tree(
        self,
        top: BTNode | None,
        graph: graphviz.Digraph,
        *,
        parent: str | None,
        path: tuple[str, ...],
    ) -> None:
        if top is None:
            self.deepest = self.next_id("n")
            graph.node(self.deepest, label="(empty tree)", shape="plaintext")
            return
        stack: list[tuple[BTNode, str | None, graphviz.Digraph, tuple[str, ...], str, int]] = [
            (top, parent, graph, path, "", 1)
        ]
        deepest_level = 0
        while stack:
            node, parent_id, holder, trees, where, level = stack.pop()
            self.count += 1
            if self.max_nodes is not None and self.count > self.max_nodes:
                raise TooLargeError(
                    f"too large to draw: more than {self.max_nodes} nodes (limit {self.max_nodes})",
                    hints=(Hint.MAX_NODES, Hint.NO_EXPANSION),
                )
            node_id = self.next_id("n")
            if level > deepest_level:
                deepest_level, self.deepest = level, node_id
            attrs = node_attrs(node, recursive=node.subtree_id in trees)
            anchor = node_anchor(where, None if self.expanding else trees[0])
            self.by_anchor.setdefault(anchor, node_id)
            if self.anchors:
                attrs["id"] = anchor
            attrs.update(self.marks.get(anchor, {}))
            holder.node(node_id, **attrs)
            if parent_id is not None:
                self.edges.append((parent_id, node_id, {}))
            ref = node.subtree_id
            if self.expanding and ref is not None and ref in self.doc.trees and ref not in trees:
                cluster = graphviz.Digraph(name=self.next_id("cluster_"))
                cluster.attr(
                    label=label_text(ref),
                    style="dashed,rounded",
                    color="gray50",
                    fontname=FONT,
                    fontsize="10",
                    labeljust="l",
                )
                self.clusters.append((cluster, holder))
                sub_root = self.doc.trees[ref].root
                if sub_root is not None:
                    stack.append(
                        (sub_root, node_id, cluster, (*trees, ref), child_path(where, 0), level + 1)
                    )
            stack.extend(
                (child, node_id, holder, trees, child_path(where, index), level + 1)
                for index, child in reversed(list(enumerate(node.children)))
            )

    def draw_ghosts(self, ghosts: Sequence[Ghost]) -> None:
        for ghost in ghosts:
            ghost_id = self.next_id("g")
            self.root.node(ghost_id, label=label_text(ghost.label), **GHOST_STYLE)
            parent = self.by_anchor.get(ghost.parent) if ghost.parent is not None else None
            if parent is not None:
                self.edges.append((parent, ghost_id, {"style": "dashed", "color": "gray55"}))

    def finish(self) -> str:
        return assemble(
            self.root,
            self.clusters,
            [edge_line(tail, head, attrs) for tail, head, attrs in self.edges],
        )


def node_attrs(node: BTNode, *, recursive: bool = False) -> dict[str, str]:
    """Shape, style and label of one node."""
    type_name = canonical_type(node.type)
    shown = [
        (k, v) for k, v in node.attrs.items() if not (node.kind is NodeKind.SUBTREE and k == "ID")
    ]
    details = [f"{k}={_shorten(v)}" for k, v in shown[:MAX_ATTRS_SHOWN]]
    if len(shown) > MAX_ATTRS_SHOWN:
        details.append(f"… (+{len(shown) - MAX_ATTRS_SHOWN})")
    name = [node.name] if node.name is not None and node.name != node.type else []
    if node.kind is NodeKind.CONTROL:
        symbol = CONTROL_SYMBOLS.get(type_name, type_name)
        return {
            "label": html_label([symbol, *name], details, head_size=16 if len(symbol) <= 2 else 12),
            "shape": "box",
            "style": "filled",
            "fillcolor": "gray88",
        }
    if node.kind is NodeKind.DECORATOR:
        symbol = DECORATOR_SYMBOLS.get(type_name, type_name)
        return {
            "label": html_label(
                [symbol, *name], details, head_size=16 if len(symbol) <= 2 else None
            ),
            "shape": "hexagon",
            "style": "filled",
            "fillcolor": "lightcyan",
        }
    if node.kind is NodeKind.SUBTREE:
        ref = node.subtree_id or "?"
        head = [f"SubTree {ref}"] + [n for n in name if n != ref]
        if recursive:
            details.insert(0, "(recursive: not expanded)")
        return {
            "label": html_label(head, details),
            "shape": "tab",
            "style": "filled",
            "fillcolor": "lavender",
        }
    head = [node.label] + ([f"({node.type})"] if name else [])
    if node.kind is NodeKind.CONDITION:
        return {
            "label": html_label(head, details),
            "shape": "ellipse",
            "style": "filled",
            "fillcolor": "honeydew",
        }
    # An action whose kind nobody declared (assumed Action) gets a dashed border.
    style = "rounded,filled" if node.kind_declared else "rounded,filled,dashed"
    return {
        "label": html_label(head, details),
        "shape": "box",
        "style": style,
        "fillcolor": "lightyellow",
    }


def _shorten(value: str) -> str:
    value = " ".join(value.split())
    return value if len(value) <= MAX_VALUE_CHARS else value[: MAX_VALUE_CHARS - 1] + "…"
