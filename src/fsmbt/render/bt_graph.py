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

With ``fold`` (the default of ``fsmbt render`` and the web page, not of the DOT format) a big
tree is drawn to be read at 100 %: ``fsmbt.render.bt_fold`` chooses which nodes to show; a
folded node gets a dashed ``[k nodes]`` box naming its path (``focus``), the children of a wide
composite are drawn in rows, each row after the first hanging from a junction point (a small
dot joined to the composite, or to the previous junction, by a dashed line) with invisible
edges keeping the rows in columns; several trees are packed in rows while they fit the height
budget (each row under the previous row's first root), and a ``size`` cap of 4 096 pixels is
set only when something was folded, wrapped or left out. ``notes`` tells what was folded.

This is also the DOT file format's BT writer (``fsmbt convert --to dot``, through
``fsmbt.formats.diagrams.dot``, with no size limit); BT DOT is write-only (docs/formats/dot.md).
"""

from __future__ import annotations

import dataclasses
import html
import re
from collections.abc import Mapping, Sequence

import graphviz

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind, canonical_type
from fsmbt.model.errors import Hint, InputError
from fsmbt.render.anchor_ids import child_path, node_anchor
from fsmbt.render.bt_fold import (
    NODE_BUDGET,
    TARGET_INCHES,
    FoldPlan,
    drawn_children,
    find_focus,
    plan_folds,
    walk,
)
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
#: A folded (default) picture of several trees: at most this many nodes, rows of this many
#: leaves (for a layout ``TARGET_INCHES`` wide; a smaller target shrinks both).
FOLDED_MAX_NODES = 300
FOLDED_ROW_LEAVES = 16
#: Graphviz ``size`` of a folded picture: larger is scaled down to fit, so a PNG (96 dpi) stays
#: within 4 096 x 4 096 pixels. Folding keeps most pictures well inside it (no scaling).
MAX_PICTURE_INCHES = "42.6,42.6"
#: Label size estimate (inches): per character, per line, and the shape's margins.
CHAR_INCHES = 0.085
LINE_INCHES = 0.19


def _row_inches(depth: int) -> float:
    """Estimated height (inches) of a row of trees at most ``depth`` levels deep, cluster
    frame and title included (about 0.85 inch a level)."""
    return 0.85 * depth + 0.7


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
    fold: bool = False,
    depth: int | None = None,
    focus: str | None = None,
    target: float = TARGET_INCHES,
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
        fold: a picture to read at 100 %: subtrees past the node budget are folded into a
            ``[k nodes]`` box and wide levels wrapped (``fsmbt.render.bt_fold``), and the
            picture is capped at 4 096 x 4 096 pixels (scaled down only as a last resort).
        depth: fold every node more than this many levels below the drawn root (0: the root
            alone); no node budget then. Implies ``fold``.
        focus: draw only the subtree under this node: a child-index path (``0/2/1``, as the
            fold boxes show it) or the name of exactly one node. Draws one tree (the main one,
            or ``tree``); implies ``fold``.
        target: with ``fold``, the side (inches) the estimated picture stays within; a caller
            that measured Graphviz's layout too big draws again with a smaller one (the
            multi-tree picture's rows and node cap shrink in proportion).

    Returns:
        The DOT source text.

    Raises:
        InputError: no tree, or ``tree`` names none (the message lists the trees), or
        ``focus`` names no node (or several).
    """
    fold = fold or depth is not None or focus is not None
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
    builder.folding, builder.depth, builder.target = fold, depth, target
    if focus is not None:
        main = doc.main
        if main.root is None:
            raise InputError(f"tree '{main.id}' is empty: nothing to focus on", element=focus)
        items = walk(doc, main.root, (main.id,), "", expanding=expand_subtrees, max_nodes=max_nodes)
        item = items[find_focus(items, focus)]
        builder.draw_tree(item.node, root, parent=None, path=item.trees, where=item.where)
    elif expand_subtrees or tree is not None:
        main = doc.main
        builder.draw_tree(main.root, root, parent=None, path=(main.id,))
    else:
        _draw_all_trees(doc, root, builder, notes)
    if any(plan.folded or plan.rows for plan in builder.plans) or builder.capped:
        root.attr(size=MAX_PICTURE_INCHES)  # the last resort; a picture that fits is unchanged
    if notes is not None:
        notes.extend(_fold_notes(builder.plans, depth))
    builder.draw_ghosts(ghosts)
    return builder.finish()


def _fold_notes(plans: list[FoldPlan], depth: int | None) -> list[str]:
    """What folding left out and how to draw it, one note for the picture."""
    folded = [(where, hidden) for plan in plans for where, hidden in plan.folded.items()]
    cuts = [
        f"drew the first {shown} of {shown + rest} children of {where or 'root'} (the others, "
        f"{hidden} nodes, in one box; draw one with focus=PATH)"
        for plan in plans
        for where, (shown, rest, hidden) in plan.cut.items()
    ]
    if not folded:
        return cuts
    shown = sum(plan.shown for plan in plans)
    total = sum(plan.total for plan in plans)
    why = (
        f"more than {depth} levels below the top"
        if depth is not None
        else f"to fit 4096 x 4096 pixels at 100 % (about {NODE_BUDGET} nodes)"
    )
    biggest = sorted(folded, key=lambda f: -f[1])[:3]
    listed = ", ".join(f"{where or 'root'} ({hidden})" for where, hidden in biggest)
    return [
        f"folded {len(folded)} subtree{'' if len(folded) == 1 else 's'} {why}: drew {shown} of {total} nodes, each fold a "
        f"'[k nodes]' box with its path; the largest: {listed}; draw one with focus=PATH, "
        "more levels with depth=N",
        *cuts,
    ]


@dataclasses.dataclass(frozen=True)
class Ghost:
    """A node drawn although it is not in the document (a diff's removed node).

    Attributes:
        label: its text.
        parent: the anchor id of the drawn node it hangs under, or ``None`` (drawn alone).
    """

    label: str
    parent: str | None = None


#: With anchors, a fold box's SVG id is this prefix and its folded node's anchor path
#: (``fold@0/2``, ``fold@root``; without SubTrees expanded ``fold@<tree>@<path>``) and its class
#: ``FOLD_CLASS``: what a page clicks to draw the folded subtree (``focus``).
FOLD_PREFIX = "fold@"
FOLD_CLASS = "fold"
#: How a fold box (hidden nodes) looks.
FOLD_STYLE = {"shape": "box", "style": "dashed,rounded", "color": "gray45", "fontcolor": "gray25"}
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
    if builder.folding:  # the depth each tree is drawn with (folds, wrapped rows)
        for t in order:
            if t.root is not None:
                nodes, leaves, _ = sizes[t.id]
                height = builder.plan_only(t.root, (t.id,), "").height
                sizes[t.id] = (nodes, leaves, height + 1)
    total = sum(n for n, _, _ in sizes.values())
    left_out: list[str] = []
    rows: list[list[str]] = [[main_id]]  # the main tree alone on the top row
    drawn = sizes[main_id][0]
    cap, row_max = PICTURE_MAX_NODES, ROW_LEAVES
    if builder.folding:  # a picture to read at 100 %: fewer nodes, narrower rows
        share = builder.target / TARGET_INCHES
        cap = max(20, int(FOLDED_MAX_NODES * share * share))
        row_max = max(4, int(FOLDED_ROW_LEAVES * share))
    row_leaves = row_max  # so the first other tree opens a new row
    # folding: the rows' estimated height stays within the target too
    tall = _row_inches(sizes[main_id][2])
    row_tall = 0.0
    for t in order[1:]:
        nodes, leaves, depth = sizes[t.id]
        opens = row_leaves + leaves > row_max
        grows = _row_inches(depth) - (0.0 if opens else row_tall)
        if drawn + nodes > cap or (builder.folding and tall + max(0.0, grows) > builder.target):
            left_out.append(t.id)
            continue
        drawn += nodes
        if opens:
            rows.append([])
            row_leaves = 0
            row_tall = 0.0
        tall += max(0.0, grows)
        row_tall = max(row_tall, _row_inches(depth))
        rows[-1].append(t.id)
        row_leaves += leaves
    previous_bottom: str | None = None
    previous_root: tuple[str, int] | None = None  # folding: a row's first root, its ranks
    for row in rows:
        deepest: tuple[int, str] | None = None
        row_root: tuple[str, int] | None = None
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
            first = f"n{builder.serial + 1}"
            planned = len(builder.plans)
            builder.draw_tree(t.root, holder, parent=None, path=(tree_id,))
            ranks = builder.plans[-1].height if len(builder.plans) > planned else 0
            if previous_root is not None:  # folding: rows stacked under the first tree's root
                tail, above = previous_root
                builder.edges.append(
                    (
                        tail,
                        first,
                        {
                            "style": "invis",
                            "minlen": str(above + 2),
                            "weight": "10" if row_root is None else "0",
                        },
                    )
                )
            elif previous_bottom is not None:  # hang this row under the previous one
                builder.edges.append((previous_bottom, first, {"style": "invis", "weight": "0"}))
            row_root = (row_root or (first, 0))[0], max(ranks, (row_root or ("", 0))[1])
            depth = sizes[tree_id][2]
            if deepest is None or depth > deepest[0]:
                deepest = (depth, builder.deepest)
        previous_bottom = deepest[1] if deepest is not None else previous_bottom
        if builder.folding:
            previous_root = row_root
    builder.capped = bool(left_out) and builder.folding
    if left_out and notes is not None:
        reason = "to fit 4096 x 4096 pixels" if builder.folding else f"at {cap} nodes"
        shown = ", ".join(left_out[:8]) + (
            f", ... (+{len(left_out) - 8})" if len(left_out) > 8 else ""
        )
        notes.append(
            f"picture capped {reason}: drew {len(order) - len(left_out)}"
            f" of {len(order)} trees ({drawn} of {total} nodes); left out: {shown}; "
            "draw one tree alone with tree=ID"
        )


@dataclasses.dataclass
class _Entry:
    """A node waiting to be drawn (``node`` ``None``: a wrapped row's junction point, or with
    ``box`` the box summing up the children cut from a very wide top node).

    ``parent`` is the node id (or junction key) it hangs from, ``gap`` the ranks between them
    (``minlen``), ``column`` / ``above`` the keys of its place in wrapped rows and of the node
    above it there."""

    node: BTNode | None
    parent: str | None
    holder: graphviz.Digraph
    trees: tuple[str, ...]
    where: str
    level: int
    gap: int = 1
    column: str | None = None
    above: str | None = None
    box: str | None = None  # with node None: the label of the box of cut children


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
        self.folding = False  # fold big trees (fsmbt.render.bt_fold)
        self.depth: int | None = None
        self.target = TARGET_INCHES  # the side (inches) a folded picture's estimate fits in
        self.plans: list[FoldPlan] = []  # of the trees drawn
        self.capped = False  # trees left out of a folded multi-tree picture
        self.planned: dict[tuple[tuple[str, ...], str], FoldPlan] = {}  # not drawn yet

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
        where: str = "",
    ) -> None:
        if top is None:
            self.deepest = self.next_id("n")
            graph.node(self.deepest, label="(empty tree)", shape="plaintext")
            return
        plan = self.plan_for(top, path, where)
        stack = [_Entry(top, parent, graph, path, where, 1)]
        deepest_level = 0
        drawn: dict[str, str] = {}  # junction / column key -> node id
        while stack:
            entry = stack.pop()
            tail = drawn.get(entry.parent, entry.parent) if entry.parent is not None else None
            edge = {"minlen": str(entry.gap)} if entry.gap > 1 else {}
            if entry.node is None and entry.box is not None:  # the cut children's box
                cut_id = self.next_id("f")
                entry.holder.node(cut_id, label=entry.box, **FOLD_STYLE)
                edge.update(style="dashed", color="gray45")
                self.edges.append((tail or "", cut_id, edge))
                if entry.column is not None:
                    drawn[entry.column] = cut_id
                continue
            if entry.node is None:  # a wrapped row's junction point
                junction = self.next_id("j")
                entry.holder.node(junction, shape="point", width="0.09", color="gray40")
                drawn[entry.where] = junction
                edge.update(style="dashed", arrowhead="none", color="gray40")
                self.edges.append((tail or "", junction, edge))
                continue
            node = entry.node
            self.count += 1
            if self.max_nodes is not None and self.count > self.max_nodes:
                raise TooLargeError(
                    f"too large to draw: more than {self.max_nodes} nodes (limit {self.max_nodes})",
                    hints=(Hint.MAX_NODES, Hint.NO_EXPANSION),
                )
            node_id = self.next_id("n")
            if entry.level > deepest_level:
                deepest_level, self.deepest = entry.level, node_id
            attrs = node_attrs(node, recursive=node.subtree_id in entry.trees)
            anchor = node_anchor(entry.where, None if self.expanding else entry.trees[0])
            self.by_anchor.setdefault(anchor, node_id)
            if self.anchors:
                attrs["id"] = anchor
            attrs.update(self.marks.get(anchor, {}))
            entry.holder.node(node_id, **attrs)
            if tail is not None:
                self.edges.append((tail, node_id, edge))
            if entry.column is not None:
                drawn[entry.column] = node_id
                above = drawn.get(entry.above or "")
                if above is not None:  # keep wrapped rows in columns under each other
                    self.edges.append(
                        (
                            above,
                            node_id,
                            {"style": "invis", "minlen": str(entry.gap), "weight": "3"},
                        )
                    )
            children = drawn_children(self.doc, node, entry.trees, entry.where, self.expanding)
            if plan is not None and entry.where in plan.folded:
                fold_anchor = FOLD_PREFIX + anchor.removeprefix("n@")
                self.draw_fold(
                    node_id, entry.holder, entry.where, plan.folded[entry.where], fold_anchor
                )
                children = []
            if children:
                stack.extend(reversed(self.child_entries(entry, node_id, children, plan)))

    def child_entries(
        self,
        entry: _Entry,
        node_id: str,
        children: list[tuple[BTNode, tuple[str, ...], str]],
        plan: FoldPlan | None,
    ) -> list[_Entry]:
        """What to draw under ``node_id``, in order: its children, in wrapped rows when the plan
        says so (each row after the first hangs from a junction point drawn after the previous
        row); an expanded SubTree's root in a dashed cluster named after its tree."""
        holder = entry.holder
        if len(children[0][1]) > len(entry.trees):  # an expanded SubTree: its own cluster
            ref = children[0][1][-1]
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
            child, inner, where = children[0]
            out = [_Entry(child, node_id, cluster, inner, where, entry.level + 1)]
            children = children[1:]  # (a SubTree reference has no children of its own)
            plan = None
        else:
            out = []
        listed: list[tuple[BTNode | None, tuple[str, ...], str]] = list(children)
        cut = plan.cut.get(entry.where) if plan is not None else None
        box: str | None = None
        if cut is not None:  # the children past the first ones: one box
            shown, rest, hidden = cut
            first, last = child_path(entry.where, shown), child_path(entry.where, shown + rest - 1)
            box = html_label(
                [f"[{rest} more children, {hidden} nodes]"], [f"focus {first} … {last}"]
            )
            listed = listed[:shown] + [(None, entry.trees, f"{node_id}#cut")]
        rows = plan.rows.get(entry.where) if plan is not None else None
        if rows is None or not listed:
            out.extend(
                _Entry(child, node_id, holder, inner, where, entry.level + 1, box=box)
                for child, inner, where in listed
            )
            return out
        gaps = plan.gaps[entry.where] if plan is not None else []
        start = 0
        row_parent = node_id
        for row, count in enumerate(rows):
            gap = gaps[row - 1] if row > 0 else 1
            if row > 0:
                key = f"{node_id}#{row}"
                junction_gap = 1 if row == 1 else gaps[row - 2]
                out.append(
                    _Entry(None, row_parent, holder, entry.trees, key, entry.level, junction_gap)
                )
                row_parent = key
            for column, (kid, kid_trees, kid_where) in enumerate(listed[start : start + count]):
                out.append(
                    _Entry(
                        kid,
                        row_parent,
                        holder,
                        kid_trees,
                        kid_where,
                        entry.level + 1,
                        gap,
                        column=f"{node_id}@{row}/{column}",
                        above=f"{node_id}@{row - 1}/{column}" if row > 0 else None,
                        box=box,
                    )
                )
            start += count
        return out

    def plan_for(self, top: BTNode, trees: tuple[str, ...], where: str) -> FoldPlan | None:
        """The fold plan of the tree under ``top`` (``None``: everything drawn)."""
        if not self.folding:
            return None
        plan = self.planned.pop((trees, where), None)
        if plan is None:
            plan = self.plan_only(top, trees, where)
        self.plans.append(plan)
        return plan

    def plan_only(self, top: BTNode, trees: tuple[str, ...], where: str) -> FoldPlan:
        """The fold plan of the tree under ``top``, kept for when it is drawn."""
        items = walk(
            self.doc, top, trees, where, expanding=self.expanding, max_nodes=self.max_nodes
        )
        plan = plan_folds(items, 0, measure, depth=self.depth, target=self.target)
        self.planned[(trees, where)] = plan
        return plan

    def draw_fold(
        self, node_id: str, holder: graphviz.Digraph, where: str, hidden: int, anchor: str
    ) -> None:
        """The ``[k nodes]`` box under the folded node ``node_id``; with anchors its SVG id is
        ``anchor`` (``fold@`` + the folded node's anchor path) and its class ``fold``, so a page
        can open it (draw with ``focus`` = the path after ``fold@``)."""
        box = self.next_id("f")
        word = "node" if hidden == 1 else "nodes"
        extra = {"id": anchor, "class": FOLD_CLASS} if self.anchors else {}
        holder.node(
            box,
            label=html_label([f"[{hidden} {word}]"], [f"focus {where or 'root'}"]),
            **FOLD_STYLE,
            **extra,
        )
        self.edges.append((node_id, box, {"style": "dashed", "color": "gray45"}))

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


def measure(node: BTNode) -> tuple[float, float]:
    """Estimated (width, height) in inches of ``node``'s shape, from its label's lines."""
    attrs = node_attrs(node)
    lines = [
        html.unescape(re.sub(r"<[^>]+>", "", line)) for line in attrs["label"][1:-1].split("<BR/>")
    ]
    width = max(len(line) for line in lines) * CHAR_INCHES + 0.35
    if attrs["shape"] in ("ellipse", "hexagon"):
        width *= 1.3
    return max(0.75, width), max(0.4, LINE_INCHES * len(lines) + 0.2)


def _shorten(value: str) -> str:
    value = " ".join(value.split())
    return value if len(value) <= MAX_VALUE_CHARS else value[: MAX_VALUE_CHARS - 1] + "…"
