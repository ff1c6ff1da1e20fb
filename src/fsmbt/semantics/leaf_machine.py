"""The leaf-execution machine of a behavior tree (docs/semantics.md, 'The leaf-execution machine'), and bounded exploration.

A state is the interpreter's full configuration at the moment it is about to tick an
environment leaf (node statuses, node memories, the explicit call stack, the pending wake-up):
a hashable ``Snapshot``. Inputs are that leaf's outcome (``success``/``failure``, and
``running`` for actions). ``step`` resumes the interpreter with the outcome and runs until the
next environment leaf is about to be ticked; outputs are what the environment observes on the
way: the root's result when a tick ends with one (``"SUCCESS"``/``"FAILURE"``, or
``"SKIPPED"`` when every child was skipped by RunOnce), then the label of the next leaf.

- A tick whose root returns RUNNING (a running leaf, KeepRunningUntilFailure...) is not
  observable: the next tick starts at once (that is also why ``tickOnce``'s immediate re-tick on
  a wake-up and ``tickExactlyOnce`` give the same leaf machine).
- ``mark_ticks=True`` makes that tick end observable: the output ``TICK_END`` where the root
  returned RUNNING, a wake-up's immediate re-tick included (``fsmbt.convert.bt_parallel``:
  where a Parallel's child yields the turn to its next sibling).
- ``loop=False``: a root result ends the run: the state becomes ``RootResult(result)``, status
  ``"final"``, outputs ``(result,)``. ``loop=True``: the root is ticked again; the outputs are
  ``(result, next leaf label)`` and the status stays ``"running"``.
- If the tree would run forever without ticking any environment leaf (every leaf internal,
  e.g. ``KeepRunningUntilFailure`` over ``AlwaysSuccess``), the state is
  ``RootResult("LIVELOCK")`` with output ``("LIVELOCK",)``: the real engine hangs there.

Fast path: a tree of only plain ``Sequence``/``Fallback`` nodes, transparent SubTrees and
environment leaves, widened with reactive nodes that hold no plain control below them and status
maps (``leaf_fast.is_static_tree``), runs on ``leaf_fast.PlainLeafTable`` instead:
a state is then the ``int`` id of the leaf about to be ticked, one step is O(1), and the outputs,
statuses and inputs are the interpreter's (tests/semantics/test_sem_leaf_fast.py checks them in
lockstep). ``generic=True`` forces the interpreter; ``fast`` says which path was taken.

Canonical states: a tree of the canonical class (``leaf_canonical.is_canonical_class``: the
Sequence/Fallback families - plain, reactive, WithMemory, Async -, Nav2's PipelineSequence,
RecoveryNode, RoundRobin and gated controllers, status maps, Repeat/Retry, SubTrees and leaves)
that is not plain runs on the interpreter, but every state is passed through
``leaf_canonical.Canonicalizer.canonical``: statuses and frame locals that are reset before they
are read are erased, so engine snapshots with the same future are one state (docs/semantics.md
§4a; tests/semantics/test_sem_leaf_canonical.py checks it in lockstep against the faithful
interpreter). ``canonical`` says whether it is used; ``generic=True`` is the faithful machine.

Complexity: ``step`` costs the nodes ticked between two leaves plus a snapshot
(O(k log k + depth)) on the interpreter, O(1) on the fast path; ``explore`` is O(S · I) steps for S reachable states and I ≤ 3 inputs.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Final, Generic, TypeVar, cast

if TYPE_CHECKING:
    import networkx as nx

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import LimitError
from fsmbt.semantics.bt_interpreter import (
    OUTCOME_TO_STATUS,
    BTInterpreter,
    BTLivelock,
    CompiledNode,
    CompiledTree,
    LeafRequest,
    Snapshot,
)
from fsmbt.semantics.leaf_canonical import Canonicalizer, is_canonical_class
from fsmbt.semantics.leaf_fast import ROOT_RESULT_NAMES, PlainLeafTable, is_static_tree
from fsmbt.semantics.machine import FINAL, Machine, Outputs
from fsmbt.semantics.machine import RUNNING as STATUS_RUNNING
from fsmbt.semantics.status import LeafOutcome, NodeStatus

LIVELOCK = "LIVELOCK"
#: Output of a ``mark_ticks`` machine when its root returned RUNNING (a tick ended) on the way.
TICK_END = "TICK_END"
#: The leaf outcomes a condition / an action may be given (``LeafOutcome`` values, plain str).
CONDITION_INPUTS: tuple[str, ...] = (LeafOutcome.SUCCESS.value, LeafOutcome.FAILURE.value)
ACTION_INPUTS: tuple[str, ...] = CONDITION_INPUTS + (LeafOutcome.RUNNING.value,)
_NODE_RUNNING: Final[int] = NodeStatus.RUNNING.value  # hot-loop alias
_OUTCOME_RUNNING: Final[str] = LeafOutcome.RUNNING.value


def leaf_label(node: BTNode | CompiledNode) -> str:
    """What a leaf is called in traces and in FSM state actions: its name, else its type.

    The FSM→BT and BT→FSM converters use this same function, so labels match by construction.
    """
    if isinstance(node, CompiledNode):
        return node.label
    return node.name or node.type


@dataclass(frozen=True)
class RootResult:
    """Terminal state: the root returned ``result`` (``loop=False``) or the tree livelocks."""

    result: str


#: Interpreter snapshot, terminal result, or (fast path) the id of the leaf about to be ticked.
LeafState = Snapshot | RootResult | int


class LeafMachine:
    """``Machine`` over leaf outcomes for a BT document (``fsmbt.semantics.machine``)."""

    def __init__(
        self,
        doc: BTDocument | CompiledTree,
        loop: bool = False,
        *,
        name: str | None = None,
        generic: bool = False,
        mark_ticks: bool = False,
    ) -> None:
        # marking ticks: a wake-up's immediate re-tick (``tickOnce``) is a tick end too
        self.interp = BTInterpreter(doc, exactly_once=mark_ticks)
        self.tree = self.interp.tree
        self.loop = loop
        #: output ``TICK_END`` where the root returns RUNNING (the fast path is not taken)
        self.mark_ticks = mark_ticks
        main = self.tree.doc.main
        self.name = name or main.id
        self.fast = not generic and not mark_ticks and is_static_tree(self.tree)
        self.table = PlainLeafTable(self.tree) if self.fast else None
        self.canonicalizer = (
            Canonicalizer(self.tree)
            if not generic and not self.fast and is_canonical_class(self.tree)
            else None
        )
        self.canonical = self.canonicalizer is not None

    # -- Machine protocol --------------------------------------------------------------------
    def start(self) -> tuple[LeafState, Outputs]:
        if self.table is not None:
            leaf = self.table.start_leaf
            return leaf, (self.table.labels[leaf],)
        outputs: list[str] = []
        snap = self.interp.begin_tick(self.interp.initial())
        state = self._run(snap, None, outputs)
        return state, tuple(outputs)

    def inputs(self, state: LeafState) -> Sequence[str]:
        if self.table is not None and type(state) is int:
            return CONDITION_INPUTS if self.table.is_condition[state] else ACTION_INPUTS
        node = self.leaf(state)
        if node is None:
            return ()
        return CONDITION_INPUTS if node.is_condition else ACTION_INPUTS

    def step(self, state: LeafState, symbol: str) -> tuple[LeafState, Outputs]:
        if isinstance(state, RootResult):
            raise ValueError(f"the tree has returned {state.result}; no input is expected")
        if self.table is not None:
            return self._fast_step(state, symbol)  # type: ignore[arg-type]
        outcome = OUTCOME_TO_STATUS.get(symbol)
        node = self.leaf(state)
        if outcome is None or node is None or (node.is_condition and outcome == _NODE_RUNNING):
            raise ValueError(f"input {symbol!r} is not allowed in state {self.describe(state)}")
        outputs: list[str] = []
        new_state = self._run(cast(Snapshot, state), outcome, outputs)
        return new_state, tuple(outputs)

    def status(self, state: LeafState) -> str:
        return FINAL if isinstance(state, RootResult) else STATUS_RUNNING

    def describe(self, state: LeafState) -> str:
        if isinstance(state, RootResult):
            return state.result
        node = self.leaf(state)
        assert node is not None
        return f"{node.label}@{node.path or 'root'}"

    # -- helpers -----------------------------------------------------------------------------
    def leaf(self, state: LeafState) -> CompiledNode | None:
        """The leaf the state is about to tick (``None`` for a terminal state)."""
        if isinstance(state, RootResult):
            return None
        if self.table is not None:
            return self.tree.nodes[state]  # type: ignore[index]
        request = self.interp.leaf_request(cast(Snapshot, state))
        return request.node if request is not None else None

    def _fast_step(self, leaf: int, symbol: str) -> tuple[LeafState, Outputs]:
        """``step`` on the fast path: O(1) table look-ups, the same loop rules as ``_run``."""
        table = self.table
        assert table is not None
        if (
            symbol == _OUTCOME_RUNNING
            and table.is_condition[leaf]
            or symbol not in OUTCOME_TO_STATUS
        ):
            raise ValueError(f"input {symbol!r} is not allowed in state {self.describe(leaf)}")
        target = table.after(leaf, symbol)
        if target >= 0:
            return target, (table.labels[target],)
        result = ROOT_RESULT_NAMES[target]
        if not self.loop:
            return RootResult(result), (result,)
        first = table.start_leaf
        return first, (result, table.labels[first])

    def _run(self, snap: Snapshot, outcome: int | None, outputs: list[str]) -> LeafState:
        """Advance to the next leaf request, ticking the root again as the rules say."""
        boundaries: set[Snapshot] = set()
        while True:
            try:
                snap, event = self.interp.advance(snap, outcome)
            except BTLivelock:
                outputs.append(LIVELOCK)
                return RootResult(LIVELOCK)
            outcome = None
            if self.canonicalizer is not None:
                snap = self.canonicalizer.canonical(snap)
            if isinstance(event, LeafRequest):
                outputs.append(event.node.label)
                return snap
            if event.status != _NODE_RUNNING:
                result = NodeStatus(event.status).name
                outputs.append(result)
                if not self.loop:
                    return RootResult(result)
            elif self.mark_ticks:
                outputs.append(TICK_END)
            if snap in boundaries:  # ticks repeat without any leaf: the engine would hang
                outputs.append(LIVELOCK)
                return RootResult(LIVELOCK)
            boundaries.add(snap)
            snap = self.interp.begin_tick(snap)


# -- exploration -----------------------------------------------------------------------------
S = TypeVar("S", bound=Hashable)


class StateLimitError(LimitError):
    """Exploration stopped: the machine has more reachable states than allowed."""


@dataclass
class ExploredMachine(Generic[S]):
    """Every reachable state of a machine, breadth first from the start."""

    start: S
    start_outputs: Outputs
    states: list[S] = field(default_factory=list)
    transitions: dict[S, dict[str, tuple[S, Outputs]]] = field(default_factory=dict)
    statuses: dict[S, str] = field(default_factory=dict)
    names: dict[S, str] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.states)

    def to_networkx(self) -> nx.MultiDiGraph[int]:
        """States as integers (BFS order) with ``status``/``name``; one edge per input, keyed
        by the input, carrying ``outputs``."""
        import networkx as nx  # only tests and reports need the graph object

        index = {s: i for i, s in enumerate(self.states)}
        graph: nx.MultiDiGraph[int] = nx.MultiDiGraph(
            start=index[self.start], start_outputs=self.start_outputs
        )
        for s, i in index.items():
            graph.add_node(i, status=self.statuses[s], name=self.names[s])
        for s, moves in self.transitions.items():
            for symbol, (target, outs) in moves.items():
                graph.add_edge(index[s], index[target], key=symbol, outputs=outs)
        return graph


def explore(machine: Machine[Any], max_states: int = 200_000) -> ExploredMachine[Any]:
    """Breadth-first exploration of every reachable state of ``machine``.

    Raises ``StateLimitError`` past ``max_states``. O(S · I) machine steps.
    """
    start, start_outputs = machine.start()
    result: ExploredMachine[Any] = ExploredMachine(start, start_outputs)
    seen = {start}
    queue = deque([start])
    while queue:
        state = queue.popleft()
        result.states.append(state)
        result.statuses[state] = machine.status(state)
        result.names[state] = machine.describe(state)
        moves: dict[str, tuple[Any, Outputs]] = {}
        for symbol in machine.inputs(state):
            target, outs = machine.step(state, symbol)
            moves[symbol] = (target, outs)
            if target not in seen:
                if len(seen) >= max_states:
                    raise StateLimitError(
                        f"the machine has more than {max_states} reachable states",
                        element=getattr(machine, "name", None),
                    )
                seen.add(target)
                queue.append(target)
        result.transitions[state] = moves
    return result
