"""The structural edit script between two versions of a model: what was added, removed, moved,
re-typed, renamed or re-parameterised (docs/diff.md, 'The edit script').

Behaviour is decided elsewhere (``fsmbt.diff.behaviour``); this module only says how the
*files* differ, so that a reviewer sees both the effect and the edit that caused it.

Behavior trees — a matching in the manner of GumTree (top-down by name, then bottom-up by
children), over every tree of both documents, nodes identified by ``(tree id, child-index
path)``:

1. *anchors*: nodes with a name of their own (leaves, SubTrees, named controls) are matched by
   ``(tree, label)``; among equal keys, the same path first, then in pre-order order;
2. *bottom-up*: an unmatched inner node of NEW is matched with the unmatched OLD node (same
   tree, the parent of a match of one of its descendants) that shares the largest share of
   matched descendants with it (Dice coefficient, at least ``MIN_DICE``), first among nodes
   of the same type, then among any (a re-typed node);
3. *same place*: what is still unmatched is matched with the unmatched node at the same path.

Then each matched pair is classified: ``retyped`` (the type changed, e.g. Sequence ->
Fallback), ``renamed``, ``updated`` (ports/attributes), ``moved`` (to another parent, or out of
order among its siblings: the children not on a longest increasing subsequence of the old
order, so swapping two children moves one). Unmatched NEW nodes are ``added``, unmatched OLD
nodes ``removed`` (a removed or added subtree is one operation, with its size).

State machines — states by path (``Parent/child``), transitions by ``(source, event, guard)``:
states ``added``/``removed``/``updated`` (action, final), transitions ``added``/``removed``/
``retargeted``, the initial state ``updated``.

Costs: O(n log n) for n nodes or states and transitions; explicit stacks, no recursion.
"""

from __future__ import annotations

import bisect
from collections import Counter
from dataclasses import dataclass

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind, canonical_type
from fsmbt.model.fsm import FSM

ADDED = "added"
REMOVED = "removed"
MOVED = "moved"
RETYPED = "retyped"
RENAMED = "renamed"
UPDATED = "updated"
RETARGETED = "retargeted"
#: The least share of common descendants for two inner nodes to be matched bottom-up.
MIN_DICE = 0.5
#: Every operation kind, in the order a script lists them.
OPERATIONS = (REMOVED, ADDED, RETYPED, RENAMED, MOVED, UPDATED, RETARGETED)


@dataclass(frozen=True)
class EditOp:
    """One edit from OLD to NEW.

    Attributes:
        op: one of ``OPERATIONS``.
        what: ``"node"``, ``"state"``, ``"transition"`` or ``"initial"``.
        old: where it was in OLD (``tree:path`` for a BT node, a state path, a transition), or
            ``None`` (added).
        new: where it is in NEW, or ``None`` (removed).
        label: what a person calls it (the node's label, the state's name).
        detail: a short sentence (``Sequence -> Fallback``, ``5 nodes``, ``position 0 -> 1``).
        parent: for a removed BT node, where its old parent is in NEW (``None``: nowhere).
    """

    op: str
    what: str
    old: str | None
    new: str | None
    label: str
    detail: str = ""
    parent: str | None = None

    def text(self) -> str:
        """One line: ``moved node Dock (Main:2/1 -> Main:2/0): position 1 -> 0``."""
        if self.old is not None and self.new is not None and self.old != self.new:
            place = f"{self.old} -> {self.new}"
        else:
            place = self.new or self.old or ""
        tail = f": {self.detail}" if self.detail else ""
        return f"{self.op} {self.what} {self.label} ({place}){tail}"


@dataclass
class _Entry:
    tree: str
    path: str
    node: BTNode
    parent: int  # index of the parent entry, -1 for a root
    index: int  # place among the parent's children
    size: int = 1  # nodes in the subtree

    @property
    def place(self) -> str:
        return f"{self.tree}:{self.path or 'root'}"


def _entries(doc: BTDocument) -> list[_Entry]:
    """Every node of every tree in pre-order, with its path; subtree sizes filled in."""
    out: list[_Entry] = []
    for tree_id, tree in doc.trees.items():
        if tree.root is None:
            continue
        stack: list[tuple[BTNode, str, int, int]] = [(tree.root, "", -1, 0)]
        while stack:
            node, path, parent, index = stack.pop()
            me = len(out)
            out.append(_Entry(tree_id, path, node, parent, index))
            for i in range(len(node.children) - 1, -1, -1):
                child_path = f"{path}/{i}" if path else str(i)
                stack.append((node.children[i], child_path, me, i))
    for i in range(len(out) - 1, -1, -1):  # children come after their parent
        parent = out[i].parent
        if parent >= 0:
            out[parent].size += out[i].size
    return out


def _anchor_key(node: BTNode) -> str | None:
    if node.name is not None or node.kind is not NodeKind.CONTROL:
        if node.kind is NodeKind.DECORATOR and node.name is None:
            return None  # an unnamed decorator is matched by its child, like a control
        return node.subtree_id or node.label
    return None


def _match_bt(old: list[_Entry], new: list[_Entry]) -> dict[int, int]:
    """new entry index -> old entry index."""
    match: dict[int, int] = {}
    taken: set[int] = set()
    # 1. anchors by (tree, label): same path first, then pre-order
    groups_old: dict[tuple[str, str], list[int]] = {}
    for i, e in enumerate(old):
        key = _anchor_key(e.node)
        if key is not None:
            groups_old.setdefault((e.tree, key), []).append(i)
    groups_new: dict[tuple[str, str], list[int]] = {}
    for j, e in enumerate(new):
        key = _anchor_key(e.node)
        if key is not None:
            groups_new.setdefault((e.tree, key), []).append(j)
    for group, js in groups_new.items():
        candidates = groups_old.get(group, [])
        if not candidates:
            continue
        by_path = {old[i].path: i for i in candidates}
        rest: list[int] = []
        for j in js:
            found = by_path.get(new[j].path)
            if found is not None and found not in taken:
                match[j] = found
                taken.add(found)
            else:
                rest.append(j)
        free = [i for i in candidates if i not in taken]
        for j, i in zip(rest, free, strict=False):
            match[j] = i
            taken.add(i)
    # 2. bottom-up: children before parents (reverse pre-order); a candidate is an unmatched
    # OLD node holding matches of this node's descendants, accepted when the share of common
    # descendants (Dice) is at least MIN_DICE
    for same_type in (True, False):  # same type first: a re-typed node only when none fits
        for j in range(len(new) - 1, -1, -1):
            e = new[j]
            if j in match or e.size == 1:
                continue
            kind = canonical_type(e.node.type)
            inside = [match[d] for d in range(j + 1, j + e.size) if d in match]
            votes: Counter[int] = Counter()
            for i in inside:
                parent = old[i].parent
                if parent >= 0 and parent not in taken and old[parent].tree == e.tree:
                    if not same_type or canonical_type(old[parent].node.type) == kind:
                        votes[parent] += 1
            best, best_dice = -1, MIN_DICE
            for candidate in sorted(votes):
                low, high = candidate, candidate + old[candidate].size
                common = sum(1 for i in inside if low < i < high)
                dice = 2 * common / (e.size - 1 + old[candidate].size - 1)
                if dice > best_dice or (dice == best_dice and best < 0):
                    best, best_dice = candidate, dice
            if best >= 0:
                match[j] = best
                taken.add(best)
    # 3. the roots of one tree, then the same place
    by_place = {(e.tree, e.path): i for i, e in enumerate(old)}
    for j, e in enumerate(new):
        root = by_place.get((e.tree, ""))
        if e.parent < 0 and j not in match and root is not None and root not in taken:
            match[j] = root
            taken.add(root)
    for j, e in enumerate(new):
        if j in match:
            continue
        same = by_place.get((e.tree, e.path))
        if same is not None and same not in taken:
            match[j] = same
            taken.add(same)
    return match


def _out_of_order(pairs: list[tuple[int, int]]) -> set[int]:
    """Of ``(new index, old position)`` pairs in new order, the new indices not on a longest
    increasing subsequence of old positions (patience sorting, O(k log k))."""
    tails: list[int] = []  # old positions
    tail_at: list[int] = []  # index into pairs
    back: list[int] = [-1] * len(pairs)
    for k, (_j, pos) in enumerate(pairs):
        at = bisect.bisect_left(tails, pos)
        if at == len(tails):
            tails.append(pos)
            tail_at.append(k)
        else:
            tails[at] = pos
            tail_at[at] = k
        back[k] = tail_at[at - 1] if at > 0 else -1
    keep: set[int] = set()
    k = tail_at[-1] if tail_at else -1
    while k >= 0:
        keep.add(pairs[k][0])
        k = back[k]
    return {j for j, _pos in pairs if j not in keep}


def bt_edit_script(old: BTDocument, new: BTDocument) -> list[EditOp]:
    """The edit script from ``old`` to ``new`` (see the module docstring)."""
    olds, news = _entries(old), _entries(new)
    match = _match_bt(olds, news)
    matched_old = {i: j for j, i in match.items()}
    ops: list[EditOp] = []
    for i, e in enumerate(olds):
        if i in matched_old or (e.parent >= 0 and e.parent not in matched_old):
            continue  # reported with its removed ancestor
        at = matched_old.get(e.parent) if e.parent >= 0 else None
        parent = news[at].place if at is not None else None
        gone = sum(1 for d in range(i, i + e.size) if d not in matched_old)
        ops.append(EditOp(REMOVED, "node", e.place, None, e.node.label, _count(gone), parent))
    for j, e in enumerate(news):
        if j in match or (e.parent >= 0 and e.parent not in match):
            continue
        new_nodes = sum(1 for d in range(j, j + e.size) if d not in match)
        ops.append(EditOp(ADDED, "node", None, e.place, e.node.label, _count(new_nodes)))
    # children of each matched parent, in new order, with their old position
    siblings: dict[int, list[tuple[int, int]]] = {}
    for j, e in enumerate(news):
        at = match.get(j)
        if at is None:
            continue
        o = olds[at]
        n_node, o_node = e.node, o.node
        if canonical_type(n_node.type) != canonical_type(o_node.type):
            ops.append(
                EditOp(
                    RETYPED,
                    "node",
                    o.place,
                    e.place,
                    n_node.label,
                    f"{o_node.type} -> {n_node.type}",
                )
            )
        elif n_node.name != o_node.name:
            ops.append(
                EditOp(
                    RENAMED,
                    "node",
                    o.place,
                    e.place,
                    n_node.label,
                    f"{o_node.label} -> {n_node.label}",
                )
            )
        if n_node.attrs != o_node.attrs and canonical_type(n_node.type) == canonical_type(
            o_node.type
        ):
            changed = sorted(
                k
                for k in set(n_node.attrs) | set(o_node.attrs)
                if n_node.attrs.get(k) != o_node.attrs.get(k)
            )
            ops.append(EditOp(UPDATED, "node", o.place, e.place, n_node.label, ", ".join(changed)))
        same_parent = (e.parent < 0 and o.parent < 0) or (
            e.parent >= 0 and match.get(e.parent) == o.parent and o.parent >= 0
        )
        if not same_parent:
            ops.append(EditOp(MOVED, "node", o.place, e.place, n_node.label, "to another parent"))
        elif e.parent >= 0:
            siblings.setdefault(e.parent, []).append((j, o.index))
    for pairs in siblings.values():
        for j in sorted(_out_of_order(pairs)):
            e = news[j]
            o = olds[match[j]]
            ops.append(
                EditOp(
                    MOVED,
                    "node",
                    o.place,
                    e.place,
                    e.node.label,
                    f"position {o.index} -> {e.index}",
                )
            )
    return _ordered(ops)


def _count(nodes: int) -> str:
    return f"{nodes} nodes" if nodes > 1 else ""


def _ordered(ops: list[EditOp]) -> list[EditOp]:
    rank = {op: k for k, op in enumerate(OPERATIONS)}
    return sorted(ops, key=lambda op: (rank[op.op], op.new or op.old or ""))


def _fsm_states(fsm: FSM) -> dict[str, tuple[str | None, bool]]:
    return {path: (state.action, state.final) for path, _machine, state in fsm.walk()}


def fsm_transitions(fsm: FSM) -> dict[tuple[str, str, str], str]:
    """(source path, event, guard) -> target, over every (sub-)machine; the first of
    duplicates wins (a nondeterministic choice is reported as the file lists it)."""
    out: dict[tuple[str, str, str], str] = {}
    machines: list[tuple[str, FSM]] = [("", fsm)]
    while machines:
        prefix, machine = machines.pop()
        for t in machine.transitions:
            key = (prefix + t.source, t.event or "", t.attrs.get("cond", ""))
            out.setdefault(key, prefix + t.target)
        for state in machine.states.values():
            for index, region in enumerate(state.regions):
                inner = f"{prefix}{state.name}/" + (f"{index}:" if state.is_parallel else "")
                machines.append((inner, region))
    return out


def fsm_edit_script(old: FSM, new: FSM) -> list[EditOp]:
    """The edit script from ``old`` to ``new`` (see the module docstring)."""
    ops: list[EditOp] = []
    s_old, s_new = _fsm_states(old), _fsm_states(new)
    for path in s_old:
        if path not in s_new:
            ops.append(EditOp(REMOVED, "state", path, None, path))
    for path, (action, final) in s_new.items():
        if path not in s_old:
            ops.append(EditOp(ADDED, "state", None, path, path))
            continue
        old_action, old_final = s_old[path]
        changes = []
        if action != old_action:
            changes.append(f"action {old_action} -> {action}")
        if final != old_final:
            changes.append("now final" if final else "no longer final")
        if changes:
            ops.append(EditOp(UPDATED, "state", path, path, path, "; ".join(changes)))
    if old.initial != new.initial:
        ops.append(EditOp(UPDATED, "initial", old.initial, new.initial, "initial state", ""))
    t_old, t_new = fsm_transitions(old), fsm_transitions(new)
    for key, target in t_old.items():
        if key not in t_new:
            ops.append(EditOp(REMOVED, "transition", _tname(key, target), None, key[1] or "(none)"))
    for key, target in t_new.items():
        before = t_old.get(key)
        if before is None:
            ops.append(EditOp(ADDED, "transition", None, _tname(key, target), key[1] or "(none)"))
        elif before != target:
            ops.append(
                EditOp(
                    RETARGETED,
                    "transition",
                    _tname(key, before),
                    _tname(key, target),
                    key[1] or "(none)",
                    f"target {before} -> {target}",
                )
            )
    return _ordered(ops)


def _tname(key: tuple[str, str, str], target: str) -> str:
    source, event, guard = key
    guarded = f" [{guard}]" if guard else ""
    return f"{source} --{event}{guarded}--> {target}"


def edit_script(old: FSM | BTDocument, new: FSM | BTDocument) -> list[EditOp] | None:
    """The edit script, or ``None`` for models of two kinds (no structure in common)."""
    if isinstance(old, BTDocument) and isinstance(new, BTDocument):
        return bt_edit_script(old, new)
    if isinstance(old, FSM) and isinstance(new, FSM):
        return fsm_edit_script(old, new)
    return None
