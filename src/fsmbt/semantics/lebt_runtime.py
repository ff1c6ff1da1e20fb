"""The LEBT protocol (docs/semantics.md, 'The LEBT protocol') as a library: leaf behaviours, macro steps, a Machine.

The two leaf types (written as ``fsmbt.semantics.lebt_spec`` says) behave like this, against a
blackboard with ``state`` and ``event`` (``""`` = no event pending):

- guard (``LebtGuard``, a condition): FAILURE when (``state``, ``event``) is one of its pairs —
  the transition fires and the Fallback runs the body — else SUCCESS.
- state leaf (``LebtState``, a stateful action) for state ``s``:
  ``onStart``: run ``s``'s action, set ``state = s``, clear ``event``; RUNNING (SUCCESS if ``s``
  is final). ``onRunning``: if an event is pending and ``s`` has a transition on it, SUCCESS
  without clearing it; if one is pending without a transition, clear it and stay RUNNING;
  with none pending, RUNNING.

One macro step = set ``event``, tick the root; if the root returns SUCCESS with the event still
pending, tick once more; an event still pending after that is dropped (ignored). Start: the
blackboard's ``state`` is the start pseudo-state; when an entry guard holds the initialisation
pair ``(start, "")`` (an FSM without initial event), ``start()`` ticks the root once with no
event pending so the initial state's leaf runs; otherwise ``start()`` ticks nothing.

The same leaf functions (``guard_outcome``, ``state_on_start``, ``state_on_running``) are
registered in BehaviorTree.CPP and py_trees by ``fsmbt.semantics.engines``; only the control
flow around them differs between the interpreter and the engines, which is what the
differential tests compare. ``LEBTMachine`` runs a tree of the strict LEBT grammar on
``fsmbt.semantics.lebt_fast`` (same leaf behaviours and macro step, no interpreter) and any
other tree on the interpreter (``LEBTRuntime``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.semantics.bt_interpreter import (
    FAILURE, IDLE, OUTCOME_FAILURE, OUTCOME_RUNNING, OUTCOME_SUCCESS, OUTCOME_TO_STATUS,
    STATUS_NAMES, SUCCESS, BTInterpreter, CompiledNode, CompiledTree, LeafRequest, Snapshot,
)
from fsmbt.semantics.lebt_spec import (
    DEFAULT_START, GUARD_TYPE, NO_EVENT, STATE_TYPE, GuardSpec, StateSpec,
)
from fsmbt.semantics.machine import FINAL, RUNNING, Outputs

if TYPE_CHECKING:
    from fsmbt.semantics.lebt_fast import FastLEBTRuntime


class LebtBlackboard(Protocol):
    """What the leaves read and write; a dataclass here, the engine's blackboard elsewhere."""

    state: str
    event: str


@dataclass
class PlainBlackboard:
    state: str
    event: str = NO_EVENT


# -- leaf behaviours (shared with the engine adapters) ---------------------------------------
def guard_outcome(spec: GuardSpec, bb: LebtBlackboard) -> str:
    """FAILURE when the guard's transition fires (the paper's "event negated")."""
    return OUTCOME_FAILURE if spec.matches(bb.state, bb.event) else OUTCOME_SUCCESS


def state_on_start(spec: StateSpec, bb: LebtBlackboard, actions: list[str]) -> str:
    """First tick: enter the state (its action runs once, here)."""
    if spec.action is not None:
        actions.append(spec.action)
    bb.state = spec.state
    bb.event = NO_EVENT
    return OUTCOME_SUCCESS if spec.final else OUTCOME_RUNNING


def state_on_running(spec: StateSpec, bb: LebtBlackboard) -> str:
    """Later ticks: leave on an event with a transition, drop an event without one."""
    if bb.event != NO_EVENT:
        if bb.event in spec.exits:
            return OUTCOME_SUCCESS
        bb.event = NO_EVENT
    return OUTCOME_RUNNING


@dataclass(frozen=True)
class LebtLeaves:
    """The parsed LEBT leaves of a compiled tree, by compiled node id, and the start name."""

    guards: dict[int, GuardSpec]
    states: dict[int, StateSpec]
    start: str
    init_on_start: bool  # an entry guard holds the pair (start, "")

    @classmethod
    def of(cls, tree: CompiledTree, start: str | None = None) -> LebtLeaves:
        guards: dict[int, GuardSpec] = {}
        states: dict[int, StateSpec] = {}
        for node in tree.nodes:
            if not node.is_env_leaf:
                continue
            where = {"location": node.source.location, "element": f"<{node.type}> '{node.label}'"}
            if node.type == GUARD_TYPE:
                if node.kind is not NodeKind.CONDITION:
                    raise InputError("an LEBT guard must be a Condition", **where)
                try:
                    guards[node.id] = GuardSpec.from_attrs(node.source.attrs)
                except ValueError as exc:
                    raise InputError(str(exc), **where) from None
            elif node.type == STATE_TYPE:
                if node.kind is not NodeKind.ACTION:
                    raise InputError("an LEBT state leaf must be an Action", **where)
                states[node.id] = StateSpec.from_attrs(node.source.attrs)
            else:
                raise InputError(f"a loop-execution BT only has {GUARD_TYPE} and {STATE_TYPE} "
                                 "leaves", **where)
        if start is None:
            start = cls._infer_start(guards, states)
        init = any((start, NO_EVENT) in g.pairs for g in guards.values())
        return cls(guards, states, start, init)

    @staticmethod
    def _infer_start(guards: dict[int, GuardSpec], states: dict[int, StateSpec]) -> str:
        """The start pseudo-state: the one guard source that is no state, else the default."""
        names = {s.state for s in states.values()}
        sources = {src for g in guards.values() for src, _ in g.pairs if src not in names}
        return sources.pop() if len(sources) == 1 else DEFAULT_START


def drive_macro_step(tick: Callable[[], str], bb: LebtBlackboard, event: str) -> str:
    """The LEBT macro step (docs/semantics.md, 'The LEBT protocol') around any engine's root tick; returns the last root result.
    An event still pending after the second tick is dropped."""
    bb.event = event
    result = tick()
    if result == "SUCCESS" and bb.event != NO_EVENT:
        result = tick()
    bb.event = NO_EVENT
    return result


class EngineLebtRun:
    """The macro-step driver shared by the real-engine adapters (BehaviorTree.CPP, py_trees):
    a subclass sets ``leaves`` and ``bb`` and implements ``_tick`` (one root tick, returning
    the root's status name); actions run by state leaves are collected in ``actions``."""

    leaves: LebtLeaves
    bb: LebtBlackboard

    def __init__(self) -> None:
        self.actions: list[str] = []
        self.last_result: str | None = None

    def _tick(self) -> str:
        raise NotImplementedError

    def initial(self) -> tuple[str, ...]:
        """What runs before any event: the initial state's action when no initial event."""
        self.actions = []
        if self.leaves.init_on_start:
            self._tick()
        return tuple(self.actions)

    def macro_step(self, event: str) -> tuple[str, ...]:
        self.actions = []
        drive_macro_step(self._tick, self.bb, event)
        return tuple(self.actions)

    @property
    def terminated(self) -> bool:
        return self.last_result == "SUCCESS" and self.bb.state != self.leaves.start


# -- the runtime -------------------------------------------------------------------------------
@dataclass(frozen=True)
class LebtState:
    """Everything between two macro steps: interpreter memory, ``state``, last root result."""

    snapshot: Snapshot
    bb_state: str
    last_result: str | None  # "SUCCESS"/"RUNNING"/... of the last tick; None before any


class LEBTRuntime:
    """Runs a loop-execution BT in the interpreter, macro step by macro step."""

    def __init__(self, doc: BTDocument | CompiledTree, *, start: str | None = None) -> None:
        self.interp = BTInterpreter(doc)
        self.tree = self.interp.tree
        self.leaves = LebtLeaves.of(self.tree, start)

    def initial(self) -> tuple[LebtState, Outputs]:
        state = LebtState(self.interp.initial(), self.leaves.start, None)
        if not self.leaves.init_on_start:
            return state, ()
        bb = PlainBlackboard(state.bb_state)
        actions: list[str] = []
        snap, result = self._tick(state.snapshot, bb, actions)
        return LebtState(snap, bb.state, result), tuple(actions)

    def macro_step(self, state: LebtState, event: str) -> tuple[LebtState, Outputs]:
        """Set ``event``, tick; tick again if the root succeeded with the event pending."""
        bb = PlainBlackboard(state.bb_state, event)
        actions: list[str] = []
        snap, result = self._tick(state.snapshot, bb, actions)
        if result == "SUCCESS" and bb.event != NO_EVENT:
            snap, result = self._tick(snap, bb, actions)
        return LebtState(snap, bb.state, result), tuple(actions)

    def _tick(self, snap: Snapshot, bb: PlainBlackboard, actions: list[str]) -> tuple[
            Snapshot, str]:
        snap = self.interp.begin_tick(snap)
        snap, event = self.interp.advance(snap)
        while isinstance(event, LeafRequest):
            outcome = self.leaf_outcome(event, bb, actions)
            snap, event = self.interp.advance(snap, OUTCOME_TO_STATUS[outcome])
        return snap, STATUS_NAMES[event.status]

    def leaf_outcome(self, request: LeafRequest, bb: LebtBlackboard, actions: list[str]) -> str:
        node: CompiledNode = request.node
        guard = self.leaves.guards.get(node.id)
        if guard is not None:
            return guard_outcome(guard, bb)
        spec = self.leaves.states[node.id]
        if request.prev == IDLE:
            return state_on_start(spec, bb, actions)
        assert request.prev not in (SUCCESS, FAILURE)
        return state_on_running(spec, bb)

    def terminated(self, state: LebtState) -> bool:
        """Root SUCCESS and nothing running: the FSM is in a final state. Before the start
        pseudo-state is left (an initial event not seen yet) a SUCCESS only says that no guard
        fired, so it does not count (docs/semantics.md)."""
        return state.last_result == "SUCCESS" and state.bb_state != self.leaves.start


class LEBTMachine:
    """``Machine`` of an LEBT's macro steps: inputs are events, outputs the actions run.

    A tree of the strict LEBT grammar (``lebt_fast.strict_lebt_sels``) runs on
    ``lebt_fast.FastLEBTRuntime`` (O(1) per macro step for a deterministic LEBT instead of the
    interpreter's O(root-level guards)); any other tree, or ``generic=True``, on the BT
    interpreter (``LEBTRuntime``). ``fast`` says which one was taken.
    """

    def __init__(self, doc: BTDocument | CompiledTree, alphabet: Sequence[str], *,
                 start: str | None = None, name: str | None = None,
                 generic: bool = False) -> None:
        from fsmbt.semantics.lebt_fast import FastLEBTRuntime, strict_lebt_sels

        tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        body_state = None if generic else strict_lebt_sels(tree)
        self.runtime: LEBTRuntime | FastLEBTRuntime
        if body_state is None:
            self.runtime = LEBTRuntime(tree, start=start)
        else:
            self.runtime = FastLEBTRuntime(tree, body_state, LebtLeaves.of(tree, start))
        self.fast = body_state is not None
        self.alphabet = tuple(alphabet)
        self.name = name or self.runtime.tree.doc.main.id

    def start(self) -> tuple[Any, Outputs]:
        return self.runtime.initial()

    def inputs(self, state: Any) -> Sequence[str]:
        return self.alphabet

    def step(self, state: Any, symbol: str) -> tuple[Any, Outputs]:
        return self.runtime.macro_step(state, symbol)

    def status(self, state: Any) -> str:
        return FINAL if self.runtime.terminated(state) else RUNNING

    def describe(self, state: Any) -> str:
        return state.bb_state
