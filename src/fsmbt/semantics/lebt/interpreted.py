"""The LEBT runtime on the generic BT interpreter: runs any tree of LEBT leaves.

The tick function (``InterpretedTick``) is one interpreter ``tickOnce`` whose environment
leaves answer with the shared leaf behaviours (``fsmbt.semantics.lebt.leaves``): a guard with
``guard_outcome``, a state leaf with ``state_on_start`` on its first tick (status IDLE) and
``state_on_running`` after. Macro step, start and termination are
``fsmbt.semantics.lebt.driver.MacroStepDriver``'s; the memory between ticks is the
interpreter's hashable snapshot.

Costs: a tick is the interpreter's, O(nodes ticked); an LEBT's root Sequence tries every
root-level guard, so a macro step is O(root-level guards) — the fast path
(``fsmbt.semantics.lebt.fast``) is O(1) on the strict grammar.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import NamedTuple

from fsmbt.model.bt import BTDocument
from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledTree, LeafRequest, Snapshot
from fsmbt.semantics.lebt.driver import MacroStepDriver
from fsmbt.semantics.lebt.leaves import (
    LebtBlackboard,
    LebtLeaves,
    guard_outcome,
    state_on_running,
    state_on_start,
)
from fsmbt.semantics.status import LeafOutcome, NodeStatus

_IDLE = NodeStatus.IDLE
_RUNNING = NodeStatus.RUNNING
#: lookups instead of ``outcome.status`` / ``NodeStatus(i)`` calls: this is the inner loop
_STATUS_OF_OUTCOME = {outcome: outcome.status for outcome in LeafOutcome}
_NODE_STATUS = tuple(NodeStatus)


class InterpretedLebtState(NamedTuple):
    """Everything between two macro steps: interpreter memory, ``state``, last root result."""

    snapshot: Snapshot
    bb_state: str
    last_result: NodeStatus | None  # the root's status after the last tick; None before any


class InterpretedTick:
    """The tick function of the interpreted runtime: one interpreter tick of the tree."""

    def __init__(self, interp: BTInterpreter, leaves: LebtLeaves) -> None:
        self.interp = interp
        self.leaves = leaves

    def tick(
        self, snap: Snapshot, bb: LebtBlackboard, actions: list[str]
    ) -> tuple[Snapshot, NodeStatus]:
        interp = self.interp
        snap = interp.begin_tick(snap)
        snap, event = interp.advance(snap)
        while isinstance(event, LeafRequest):
            outcome = self.leaf_outcome(event, bb, actions)
            snap, event = interp.advance(snap, _STATUS_OF_OUTCOME[outcome])
        return snap, _NODE_STATUS[event.status]

    def leaf_outcome(
        self, request: LeafRequest, bb: LebtBlackboard, actions: list[str]
    ) -> LeafOutcome:
        """The answer of the leaf the interpreter is about to tick.

        Args:
            request: the interpreter's request (the leaf and its status before the tick).
            bb: the blackboard.
            actions: the step's actions so far (a starting state leaf appends its action).

        Returns:
            The leaf's outcome.
        """
        node_id = request.node.id
        guard = self.leaves.guards.get(node_id)
        if guard is not None:
            return guard_outcome(guard, bb)
        spec = self.leaves.states[node_id]
        if request.prev == _IDLE:
            return state_on_start(spec, bb, actions)
        assert request.prev == _RUNNING, "a state leaf ticked again after it completed"
        return state_on_running(spec, bb)


class LEBTRuntime(MacroStepDriver[Snapshot, InterpretedLebtState]):
    """Runs a loop-execution BT in the interpreter, macro step by macro step.

    Args:
        doc: the tree (compiled or not).
        start: the start pseudo-state; ``None`` infers it (``LebtLeaves.of``).
    """

    def __init__(self, doc: BTDocument | CompiledTree, *, start: str | None = None) -> None:
        self.interp = BTInterpreter(doc)
        self.tree = self.interp.tree
        leaves = LebtLeaves.of(self.tree, start)
        self.ticker = InterpretedTick(self.interp, leaves)
        super().__init__(leaves, self.ticker.tick, self.interp.initial(), InterpretedLebtState)

    def running_leaves(self, state: InterpretedLebtState) -> Iterator[int]:
        """The compiled ids of the state leaves RUNNING in ``state``.

        Args:
            state: a state of this runtime.

        Returns:
            The ids, in the snapshot's order.
        """
        states = self.leaves.states
        return (nid for nid, status in state.snapshot[0] if status == _RUNNING and nid in states)
