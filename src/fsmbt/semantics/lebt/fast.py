"""A direct runner for LEBTs of the strict shape, without the generic BT interpreter.

Why: the generic interpreter ticks past every root-level guard in each macro step, so checking
an n-state FSM against its LEBT costs O(n^2) (1 000 states: ~100 s). For trees of the strict
LEBT grammar (docs/semantics.md §5, "The LEBT protocol") ::

    Root := Sequence(Sel+)      Sel := Fallback(Guard, Body)      Body := State | Sequence(State, Sel*)

(Guard = an ``LebtGuard`` Condition, State = an ``LebtState`` Action, nodes of the compiled
tree, so a ``SubTree`` node or any other node type is outside the grammar) nothing but a guard
ever returns FAILURE, so nothing is ever halted and the whole run-time memory between two ticks
is the running state leaf (or none): the indices of BehaviorTree.CPP's non-reactive
Sequence/Fallback ancestors and the SUCCESS/FAILURE statuses before it follow from its position.
A tick then is (derived from ``sequence_node.cpp``/``fallback_node.cpp`` and the leaf
behaviours of ``fsmbt.semantics.lebt.leaves``):

- running leaf ``X``: ``state_on_running(X)``; RUNNING ends the tick; SUCCESS continues
  "after X";
- nothing running: the first root-level Sel whose guard holds (``state``, ``event``) runs its
  body (its State leaf starts: RUNNING ends the tick, SUCCESS - a final state - continues
  "after" it); none holds: the root returns SUCCESS. Nested guards are never reached first.
- "after Y": the later siblings of each Sequence ancestor of ``Y``, innermost first (the
  pre-order after ``Y``), are Sels whose guards are tried; the first that holds runs its body as
  above; none: the root returns SUCCESS (every Sequence completes).

Finding that first Sel: an index ``(source, event) -> Sels whose guard holds the pair`` in
pre-order, and an O(1) test "the Sel's parent Sequence is an ancestor of ``Y`` (pre-order
interval) and the Sel comes after ``Y``". One tick costs O(c log c + k) for c Sels sharing the
pair and k leaves started (one per final state passed); a deterministic LEBT has c <= 1.
Building the index is O(N + P) for N nodes and P guard pairs.

That tick is ``StrictTick``; macro step, start and termination are
``fsmbt.semantics.lebt.driver.MacroStepDriver``'s, the same as the interpreted runtime's.
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Iterator
from typing import NamedTuple

from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.bt_interpreter import CompiledTree, Snapshot
from fsmbt.semantics.lebt.driver import MacroStepDriver
from fsmbt.semantics.lebt.leaves import LebtBlackboard, LebtLeaves, state_on_start
from fsmbt.semantics.lebt.spec import GUARD_TYPE, NO_EVENT, STATE_TYPE
from fsmbt.semantics.status import LeafOutcome, NodeStatus

ROOT = 0  # the compiled root's id (ids are pre-order indices)
_IDLE_SNAPSHOT: Snapshot = ((), (), (), False)
_RUNNING = NodeStatus.RUNNING
_SUCCESS = NodeStatus.SUCCESS
_LEAF_RUNNING = LeafOutcome.RUNNING


class FastLebtState(NamedTuple):
    """Everything between two macro steps on the fast path (hashable, cheap to hash)."""

    running: int | None  # compiled id of the running LebtState leaf, None when nothing runs
    bb_state: str
    last_result: NodeStatus | None  # the root's status after the last tick; None before any

    @property
    def snapshot(self) -> Snapshot:
        """The interpreter-shaped view of the memory: only the running leaf is listed."""
        if self.running is None:
            return _IDLE_SNAPSHOT
        return (((self.running, int(_RUNNING)),), (), (), False)


def strict_lebt_sels(tree: CompiledTree) -> dict[int, int] | None:
    """``{Sel id: its body's State leaf id}`` when ``tree`` has the strict LEBT shape, else
    ``None``. O(N), iterative (checks every node once)."""
    nodes = tree.nodes

    def is_(nid: int, kind: NodeKind, type_: str) -> bool:
        node = nodes[nid]
        return node.kind is kind and node.type == type_ and node.internal_status is None

    root = nodes[ROOT]
    if not (is_(ROOT, NodeKind.CONTROL, "Sequence") and root.children):
        return None
    body_state: dict[int, int] = {}
    stack = list(root.children)
    visited = 1
    while stack:
        sel = stack.pop()
        node = nodes[sel]
        if not is_(sel, NodeKind.CONTROL, "Fallback") or len(node.children) != 2:
            return None
        guard, body = node.children
        if not is_(guard, NodeKind.CONDITION, GUARD_TYPE):
            return None
        visited += 3
        if is_(body, NodeKind.ACTION, STATE_TYPE):
            body_state[sel] = body
            continue
        kids = nodes[body].children
        if not (
            is_(body, NodeKind.CONTROL, "Sequence")
            and kids
            and is_(kids[0], NodeKind.ACTION, STATE_TYPE)
        ):
            return None
        body_state[sel] = kids[0]
        visited += 1
        stack.extend(kids[1:])
    return body_state if visited == len(nodes) else None


class StrictTick:
    """The tick function of the fast path: one root tick of a strict-grammar LEBT, computed
    from the running leaf alone (module docstring), with an index of guard pairs.

    Args:
        tree: the compiled tree.
        body_state: ``strict_lebt_sels(tree)``.
        leaves: the tree's parsed leaves.
    """

    def __init__(self, tree: CompiledTree, body_state: dict[int, int], leaves: LebtLeaves) -> None:
        nodes = tree.nodes
        self.leaves = leaves
        self.body_state = body_state
        self.parent: dict[int, int] = {sel: nodes[sel].parent for sel in body_state}  # type: ignore[misc]
        # last[n]: the largest pre-order id in n's subtree (children have larger ids)
        last = list(range(len(nodes)))
        for node in reversed(nodes):
            if node.children:
                last[node.id] = last[node.children[-1]]
        self.last = last
        self.exits = {nid: frozenset(spec.exits) for nid, spec in leaves.states.items()}
        index: dict[tuple[str, str], set[int]] = {}
        for sel in body_state:
            guard = nodes[sel].children[0]
            for pair in leaves.guards[guard].pairs:
                index.setdefault(pair, set()).add(sel)
        self.index: dict[tuple[str, str], list[int]] = {
            pair: sorted(sels) for pair, sels in index.items()
        }

    def _next_sel(self, after: int | None, state: str, event: str) -> int | None:
        """The first Sel (pre-order) tried after ``after`` (None: a fresh tick) whose guard
        holds (``state``, ``event``)."""
        candidates = self.index.get((state, event))
        if not candidates:
            return None
        parent = self.parent
        if after is None:
            return next((sel for sel in candidates if parent[sel] == ROOT), None)
        last = self.last
        for k in range(bisect_right(candidates, after), len(candidates)):
            sel = candidates[k]
            p = parent[sel]
            if p <= after <= last[p]:
                return sel
        return None

    def tick(
        self, running: int | None, bb: LebtBlackboard, actions: list[str]
    ) -> tuple[int | None, NodeStatus]:
        """One root tick: the running leaf afterwards and the root's status."""
        if running is not None:
            if bb.event == NO_EVENT:
                return running, _RUNNING
            if bb.event not in self.exits[running]:
                bb.event = NO_EVENT
                return running, _RUNNING
        after = running
        states = self.leaves.states
        while True:
            sel = self._next_sel(after, bb.state, bb.event)
            if sel is None:
                return None, _SUCCESS
            leaf = self.body_state[sel]
            if state_on_start(states[leaf], bb, actions) is _LEAF_RUNNING:
                return leaf, _RUNNING
            after = leaf


class FastLEBTRuntime(MacroStepDriver["int | None", FastLebtState]):
    """``LEBTRuntime``'s interface (``initial``, ``macro_step``, ``terminated``,
    ``running_leaves``, ``tree``, ``leaves``) for a strict-shape LEBT (``body_state`` from
    ``strict_lebt_sels``): the same driver over ``StrictTick``, so the two runtimes are
    interchangeable.

    Args:
        tree: the compiled tree.
        body_state: ``strict_lebt_sels(tree)``.
        leaves: the tree's parsed leaves.
    """

    def __init__(self, tree: CompiledTree, body_state: dict[int, int], leaves: LebtLeaves) -> None:
        self.tree = tree
        self.ticker = StrictTick(tree, body_state, leaves)
        super().__init__(leaves, self.ticker.tick, None, FastLebtState)

    def running_leaves(self, state: FastLebtState) -> Iterator[int]:
        """The compiled id of the state leaf RUNNING in ``state`` (none or one).

        Args:
            state: a state of this runtime.

        Returns:
            The ids.
        """
        if state.running is not None:
            yield state.running
