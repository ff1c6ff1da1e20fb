"""Which nodes of a big behavior tree a picture shows: folds, wrapped rows, a focus.

A picture of a behavior tree is read at 100 % when it fits 4 096 x 4 096 pixels (42.6 inches at
96 dpi) with no side more than four times the other (issue 29). Big trees are drawn the way Groot2
users read them:

- **Folding**: a node whose children are not drawn is *folded*: one dashed box under it says how
  many nodes it hides (``[k nodes]``) and the path to draw it alone with (``focus``).
- **Wrapped rows**: the children of a composite whose row would be too wide are laid out in rows,
  each row hanging below the previous one (``rows``).
- **Cut**: the drawn top node (the root, or the ``focus``) cannot be folded; past
  ``TOP_CHILDREN`` children, its first ones are shown and one box sums up the others (``cut``).

``plan_folds`` chooses both. Without a ``depth``, nodes are opened breadth first (every node of a
level before the next level, so siblings are treated alike) while the estimated picture stays
within ``TARGET_INCHES`` on both sides and ``NODE_BUDGET`` drawn nodes; a node whose children do
not fit stays folded and later, smaller nodes may still open. This is tried for a few row widths
(``ROW_WIDTHS``, widest first); among the plans with an estimated aspect within
``TARGET_ASPECT``, the one with the widest rows that shows at least ``KEEP_SHOWN`` of the most
nodes any of them shows wins (fewer wrapped rows read more easily). With a ``depth``, exactly the nodes more than ``depth`` levels below the
top are folded, whatever the size (the caller scales the picture down if it must).

Sizes are estimates from the label text (``measure``); Graphviz's real layout differs a little,
which is why the targets keep a margin below 42.6 inches and the picture is still capped with
Graphviz's ``size`` as a last resort. Costs: one walk of the drawn tree (explicit stack, refused
past ``max_nodes`` nodes), then per row width one estimate update per node tried, each over
the tried node's ancestors only (``_Profiles``: O(depth x children)), and one whole estimate.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import Hint, InputError
from fsmbt.render.anchor_ids import child_path
from fsmbt.render.dot import TooLargeError

#: Most nodes (fold boxes included) a picture shows before subtrees are folded.
NODE_BUDGET = 160
#: The estimated picture stays within this many inches on each side (42.6 in = 4 096 px).
TARGET_INCHES = 36.0
#: The estimated long side stays within this many times the short one (the rule is 4).
TARGET_ASPECT = 3.5
#: Row widths (inches) tried for wrapping the children of a wide composite; ``None``: no wrap.
ROW_WIDTHS: tuple[float | None, ...] = (None, 24.0, 16.0, 10.0, 6.0)
#: A plan with wider rows (fewer wraps) is preferred while it shows this share of the nodes the
#: best plan shows.
KEEP_SHOWN = 0.85
#: Layout spacing the estimate assumes (the picture's ``nodesep`` / ``ranksep``, inches).
NODE_GAP = 0.25
RANK_GAP = 0.45
#: Most children of the drawn top node shown; the rest are summed up in one box ("cut").
TOP_CHILDREN = 100
#: Size of a fold box (inches).
FOLD_BOX = (1.3, 0.55)


@dataclasses.dataclass
class Item:
    """One node as the picture draws it.

    Attributes:
        node: the node.
        trees: the trees being expanded around it (the first is the tree drawn).
        where: its child-index path from the drawn root (``""`` for the root).
        level: 0 for the drawn root.
        children: indices of its drawn children in the walk's list.
        size: how many nodes its subtree holds, itself included.
    """

    node: BTNode
    trees: tuple[str, ...]
    where: str
    level: int
    children: list[int] = dataclasses.field(default_factory=list)
    size: int = 1


@dataclasses.dataclass
class FoldPlan:
    """What a picture of one tree shows.

    Attributes:
        folded: path -> how many nodes are hidden under that node (its descendants).
        rows: path -> how many children each row holds, for composites drawn in wrapped rows.
        gaps: path -> for each wrapped row after the first, how many ranks below the previous
            row it starts (one more than the previous row's deepest shown subtree).
        cut: path -> (children shown, children left out, nodes left out) for a top node with
            more than ``TOP_CHILDREN`` children: the others are summed up in one box drawn
            last in its rows (counted in ``rows``).
        shown: nodes drawn (fold boxes not counted); total: nodes of the tree.
        height: ranks the picture spans below its top (fold boxes and wrapped rows included).
    """

    folded: dict[str, int] = dataclasses.field(default_factory=dict)
    rows: dict[str, list[int]] = dataclasses.field(default_factory=dict)
    gaps: dict[str, list[int]] = dataclasses.field(default_factory=dict)
    cut: dict[str, tuple[int, int, int]] = dataclasses.field(default_factory=dict)
    shown: int = 0
    total: int = 0
    height: int = 0


def drawn_children(
    doc: BTDocument, node: BTNode, trees: tuple[str, ...], where: str, expanding: bool
) -> list[tuple[BTNode, tuple[str, ...], str]]:
    """The children a picture draws under ``node``: with ``expanding``, a SubTree reference to a
    tree not already being expanded gets that tree's root as child 0 (the interpreter's path,
    docs/semantics.md 'Leaf execution'); then the node's own children."""
    out: list[tuple[BTNode, tuple[str, ...], str]] = []
    ref = node.subtree_id
    if expanding and ref is not None and ref in doc.trees and ref not in trees:
        sub_root = doc.trees[ref].root
        if sub_root is not None:
            out.append((sub_root, (*trees, ref), child_path(where, 0)))
    out.extend(
        (child, trees, child_path(where, index)) for index, child in enumerate(node.children)
    )
    return out


def walk(
    doc: BTDocument,
    top: BTNode,
    trees: tuple[str, ...],
    where: str,
    *,
    expanding: bool,
    max_nodes: int | None,
) -> list[Item]:
    """Every node drawn under ``top`` (itself first), breadth first, with subtree sizes."""
    items = [Item(top, trees, where, 0)]
    head = 0
    while head < len(items):
        item = items[head]
        for node, inner, path in drawn_children(doc, item.node, item.trees, item.where, expanding):
            item.children.append(len(items))
            items.append(Item(node, inner, path, item.level + 1))
            if max_nodes is not None and len(items) > max_nodes:
                raise TooLargeError(
                    f"too large to draw: more than {max_nodes} nodes (limit {max_nodes})",
                    hints=(Hint.MAX_NODES, Hint.NO_EXPANSION),
                )
        head += 1
    for item in reversed(items):  # children come after their parent
        item.size = 1 + sum(items[c].size for c in item.children)
    return items


def find_focus(items: list[Item], focus: str) -> int:
    """The index of the node ``focus`` names: a child-index path (``0/2/1``, ``root``) or the
    name / label of exactly one node."""
    wanted = "" if focus in ("root", "/") else focus.strip("/")
    for index, item in enumerate(items):
        if item.where == wanted:
            return index
    named = [i for i, item in enumerate(items) if focus in (item.node.name, item.node.label)]
    if len(named) == 1:
        return named[0]
    if named:
        paths = ", ".join(items[i].where or "root" for i in named[:8])
        raise InputError(
            f"{len(named)} nodes are named '{focus}'; focus on one by its path ({paths})",
            element=focus,
        )
    raise InputError(
        f"no node '{focus}' in the tree drawn (give a node name or a child-index path like 0/2/1)",
        element=focus,
    )


Measure = Callable[[BTNode], tuple[float, float]]


Profile = tuple[list[float], list[float]]  # per rank below a node: (widths, heights)


def _merge(left: Profile | None, right: Profile) -> Profile:
    """Two subtrees side by side: rank by rank, widths add up (with a gap), heights max."""
    if left is None:
        return list(right[0]), list(right[1])
    widths, heights = list(left[0]), list(left[1])
    for rank, (width, height) in enumerate(zip(*right, strict=True)):
        if rank < len(widths):
            widths[rank] += NODE_GAP + width
            heights[rank] = max(heights[rank], height)
        else:
            widths.append(width)
            heights.append(height)
    return widths, heights


class _Estimate:
    """The estimated extent (inches) of a plan's picture. dot lays a tree out rank by rank and
    lets subtrees of different depths interleave, so a subtree is summed up by its *profile*:
    the width and height of each rank below its top; siblings' profiles add up rank by rank, and
    the rows of a wrapped composite stack (each row starts below the previous row's deepest
    rank). The picture is as wide as its widest rank and as tall as its ranks."""

    def __init__(self, items: list[Item], sizes: list[tuple[float, float]], row: float | None):
        self.items = items
        self.sizes = sizes
        self.row = row
        self.limit: dict[int, int] = {}  # node -> children shown (the rest cut)

    def kids(self, index: int) -> list[int]:
        """The children of ``items[index]`` that are drawn when it is open."""
        kids = self.items[index].children
        return kids[: self.limit[index]] if index in self.limit else kids

    def rows_of(self, profiles: list[Profile]) -> tuple[list[int], list[Profile]]:
        """How many children each row holds, and each row's profile: children join a row while
        its widest rank stays within the row width (at least one child per row)."""
        counts: list[int] = []
        merged: list[Profile] = []
        for profile in profiles:
            if merged:
                candidate = _merge(merged[-1], profile)
                if self.row is None or max(candidate[0]) <= self.row:
                    merged[-1] = candidate
                    counts[-1] += 1
                    continue
            merged.append(_merge(None, profile))
            counts.append(1)
        return counts, merged

    def extent(self, top: int, opened: set[int]) -> tuple[float, float, dict[int, list[int]]]:
        """(width, height, rows per wrapped node) of the picture rooted at ``top``."""
        order: list[int] = []
        stack = [top]
        while stack:
            index = stack.pop()
            order.append(index)
            if index in opened:
                stack.extend(self.kids(index))
        profiles: dict[int, Profile] = {}
        wrapped: dict[int, list[int]] = {}
        for index in reversed(order):
            width, height = self.sizes[index]
            kids = self.items[index].children
            if not kids:
                profiles[index] = ([width], [height])
            elif index not in opened:
                profiles[index] = ([width, FOLD_BOX[0]], [height, FOLD_BOX[1]])
            else:
                shown = [profiles.pop(c) for c in self.kids(index)]
                if index in self.limit:  # the box summing up the cut children
                    shown.append(([FOLD_BOX[0]], [FOLD_BOX[1]]))
                counts, rows = self.rows_of(shown)
                if len(counts) > 1:
                    wrapped[index] = counts
                widths, heights = [width], [height]
                for row_widths, row_heights in rows:
                    widths += row_widths
                    heights += row_heights
                profiles[index] = (widths, heights)
        widths, heights = profiles[top]
        return max(widths), sum(heights) + RANK_GAP * (len(heights) - 1), wrapped


class _Profiles:
    """``_Estimate.extent`` kept up to date while ``_open`` opens nodes one at a time: every
        node's profile as ``extent`` would compute it (a leaf: its own size; a closed node with
        children: itself and its fold box; an open node: its kids' profiles in rows), so opening a
        node recomputes only its own profile and its ancestors', in the same order and with the
        same arithmetic as ``extent`` (the same figures, bit for bit). ``_open`` asks for the
        extent once per node it tries: O(depth x kids) each instead of a walk of the whole open
        tree (a 30-state FSM's 314-node dispatch tree is planned for up to five sizes per picture,
    ``fsmbt.render.picture_dot``)."""

    def __init__(self, estimate: _Estimate, top: int):
        self.estimate = estimate
        items = estimate.items
        self.parent: dict[int, int] = {}
        self.profiles: dict[int, Profile] = {}
        stack = [top]
        while stack:
            index = stack.pop()
            width, height = estimate.sizes[index]
            if items[index].children:
                self.profiles[index] = ([width, FOLD_BOX[0]], [height, FOLD_BOX[1]])
            else:
                self.profiles[index] = ([width], [height])
            for child in estimate.kids(index):
                self.parent[child] = index
                stack.append(child)

    def _opened_profile(self, index: int, changed: dict[int, Profile]) -> Profile:
        estimate = self.estimate
        width, height = estimate.sizes[index]
        shown = [changed.get(c, self.profiles[c]) for c in estimate.kids(index)]
        if index in estimate.limit:
            shown.append(([FOLD_BOX[0]], [FOLD_BOX[1]]))
        _counts, rows = estimate.rows_of(shown)
        widths, heights = [width], [height]
        for row_widths, row_heights in rows:
            widths += row_widths
            heights += row_heights
        return widths, heights

    def try_open(self, index: int, top: int) -> tuple[float, float, dict[int, Profile]]:
        """(width, height) of the picture with ``index`` opened too (its ancestors are), and
        the profiles that changed, for ``keep``."""
        changed: dict[int, Profile] = {index: self._opened_profile(index, {})}
        node = index
        while node != top:
            node = self.parent[node]
            changed[node] = self._opened_profile(node, changed)
        widths, heights = changed[top]
        return max(widths), sum(heights) + RANK_GAP * (len(heights) - 1), changed

    def keep(self, changed: dict[int, Profile]) -> None:
        self.profiles.update(changed)


def plan_folds(
    items: list[Item],
    top: int,
    measure: Measure,
    *,
    depth: int | None = None,
    target: float = TARGET_INCHES,
) -> FoldPlan:
    """What to show of the tree under ``items[top]`` (see the module docstring); ``target``:
    the side (inches) the estimated picture stays within."""
    sizes = [measure(item.node) for item in items]
    tried: list[tuple[bool, float, FoldPlan]] = []
    for row in ROW_WIDTHS:
        estimate = _Estimate(items, sizes, row)
        opened = _open(items, top, estimate, depth, target)
        width, height, wrapped = estimate.extent(top, opened)
        aspect = max(width, height) / max(0.1, min(width, height))
        plan = _plan(items, top, opened, wrapped, estimate)
        tried.append((aspect <= TARGET_ASPECT, aspect, plan))
        if aspect <= TARGET_ASPECT and plan.shown == items[top].size:
            break  # everything drawn, in shape: no narrower rows needed
    in_shape = [plan for ok, _, plan in tried if ok]
    if not in_shape:
        return min(tried, key=lambda t: t[1])[2]
    most = max(plan.shown for plan in in_shape)
    # the widest rows (fewest wraps) that show nearly as many nodes as the best
    return next(plan for plan in in_shape if plan.shown >= KEEP_SHOWN * most)


def _open(
    items: list[Item], top: int, estimate: _Estimate, depth: int | None, target: float
) -> set[int]:
    """The nodes whose children are drawn (breadth first, see the module docstring)."""
    opened: set[int] = set()
    base = items[top].level
    if depth is not None:
        stack = [top]
        while stack:
            index = stack.pop()
            if items[index].children and items[index].level - base < depth:
                opened.add(index)
                stack.extend(items[index].children)
        return opened
    if len(items[top].children) > TOP_CHILDREN:
        estimate.limit[top] = TOP_CHILDREN
    shown = 1
    queue = [top]
    head = 0
    profiles = _Profiles(estimate, top)
    while head < len(queue):
        index = queue[head]
        head += 1
        kids = estimate.kids(index)
        if not kids:
            continue
        # children shown, fold boxes of the children that have children of their own, and
        # this node's own fold box gone
        cost = len(kids) + sum(1 for c in kids if items[c].children) - (1 if index != top else 0)
        if index != top and shown + cost > NODE_BUDGET:
            continue
        # the extent with ``index`` opened too (estimate.extent(top, opened | {index}))
        width, height, changed = profiles.try_open(index, top)
        if index != top and (width > target or height > target):
            continue
        opened.add(index)
        profiles.keep(changed)
        shown += cost
        queue.extend(kids)
    return opened


def _plan(
    items: list[Item],
    top: int,
    opened: set[int],
    wrapped: dict[int, list[int]],
    estimate: _Estimate,
) -> FoldPlan:
    plan = FoldPlan(total=items[top].size)
    order: list[int] = []
    stack = [top]
    while stack:
        index = stack.pop()
        order.append(index)
        item = items[index]
        plan.shown += 1
        if index in opened:
            stack.extend(estimate.kids(index))
            if index in wrapped:
                plan.rows[item.where] = wrapped[index]
            if index in estimate.limit:
                rest = item.children[estimate.limit[index] :]
                plan.cut[item.where] = (
                    estimate.limit[index],
                    len(rest),
                    sum(items[c].size for c in rest),
                )
        elif item.children:
            plan.folded[item.where] = item.size - 1
    ranks: dict[int, int] = {-1: 0}  # ranks a shown subtree spans below its top (-1: a cut box)
    for index in reversed(order):
        kids = estimate.kids(index) + ([-1] if index in estimate.limit else [])
        if not kids:
            ranks[index] = 0
        elif index not in opened:
            ranks[index] = 1  # the fold box
        else:
            counts = wrapped.get(index, [len(kids)])
            deepest: list[int] = []
            start = 0
            for count in counts:
                deepest.append(max(ranks[c] for c in kids[start : start + count]))
                start += count
            gaps = [1 + d for d in deepest[:-1]]
            if len(counts) > 1:
                plan.gaps[items[index].where] = gaps
            ranks[index] = 1 + sum(gaps) + deepest[-1]
    plan.height = ranks[top]
    return plan
