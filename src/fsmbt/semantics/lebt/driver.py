"""The LEBT macro step, written once, over a tick function that each runtime plugs in.

Rules (docs/semantics.md §5, "The LEBT protocol"):

- one macro step = post the event (``event`` on the blackboard), tick the root; if the root
  returned SUCCESS with the event still pending, tick once more (the second-tick rule: the
  first tick only finished the state that the event leaves); an event still pending after
  that is dropped, i.e. ignored, as the FSM ignores an event it has no transition on;
- start: the blackboard's ``state`` is the start pseudo-state; when an entry guard holds the
  initialisation pair ``(start, "")`` (an FSM without initial event) the root is ticked once
  with no event pending so the initial state's leaf runs; otherwise nothing is ticked;
- termination: the last tick returned SUCCESS and ``state`` is no longer the start
  pseudo-state (before the start is left a SUCCESS only says that no guard fired).

A *tick function* ``tick(memory, bb, actions) -> (memory', status)`` runs one root tick: it reads
and writes the blackboard through the shared leaf behaviours (``fsmbt.semantics.lebt.leaves``),
appends the actions run to ``actions`` and returns the root's ``NodeStatus``. ``memory`` is
whatever the runtime keeps between ticks: the interpreter's snapshot
(``fsmbt.semantics.lebt.interpreted``), the running state leaf of a strict-grammar tree
(``fsmbt.semantics.lebt.fast``), nothing for a real engine that keeps its own state
(``EngineLebtRun`` below, used by ``fsmbt.semantics.engines``). The runtimes differ only in that
function; ``MacroStepDriver`` is the only place the rules above are written.

States between macro steps are 3-tuples ``(memory, bb_state, last_result)`` (a ``NamedTuple``
per runtime, so they are hashable and cheap to hash for the checker).

Costs: a macro step is at most two ticks plus O(1); the driver allocates one blackboard, one
action list and one state per step.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from typing import Any, Generic, NamedTuple, TypeVar

from fsmbt.semantics.lebt.leaves import LebtBlackboard, LebtLeaves, PlainBlackboard
from fsmbt.semantics.lebt.spec import NO_EVENT
from fsmbt.semantics.machine import Outputs
from fsmbt.semantics.status import NodeStatus

M = TypeVar("M")
S = TypeVar("S", bound=tuple[Any, str, NodeStatus | None])

#: One root tick: (memory before, blackboard, actions run so far) -> (memory after, root status).
TickFunction = Callable[[M, LebtBlackboard, list[str]], tuple[M, NodeStatus]]
#: Builds a runtime's state from (memory, ``state`` on the blackboard, last root status).
StateFactory = Callable[[M, str, NodeStatus | None], S]

_SUCCESS = NodeStatus.SUCCESS  # tick functions return NodeStatus members: compared with `is`


class MacroStepDriver(Generic[M, S]):
    """The macro step, start and termination rules around a runtime's tick function.

    Args:
        leaves: the tree's parsed LEBT leaves (start pseudo-state, initialisation pair).
        tick: the runtime's tick function.
        idle: the memory before the first tick.
        make_state: the runtime's state type (a ``NamedTuple`` of three fields).
        blackboard: gives the blackboard a step runs on, from (``state``, ``event``); a fresh
            ``PlainBlackboard`` by default, the engine's own for a real engine.
    """

    def __init__(
        self,
        leaves: LebtLeaves,
        tick: TickFunction[M],
        idle: M,
        make_state: StateFactory[M, S],
        blackboard: Callable[[str, str], LebtBlackboard] = PlainBlackboard,
    ) -> None:
        self.leaves = leaves
        self._tick = tick
        self._idle = idle
        self._make_state = make_state
        self._blackboard = blackboard

    def initial(self) -> tuple[S, Outputs]:
        """The state before any event and the actions run to reach it.

        Returns:
            The start state; the initial state's action when the FSM has no initial event.
        """
        start = self.leaves.start
        if not self.leaves.init_on_start:
            return self._make_state(self._idle, start, None), ()
        bb = self._blackboard(start, NO_EVENT)
        actions: list[str] = []
        memory, result = self._tick(self._idle, bb, actions)
        return self._make_state(memory, bb.state, result), tuple(actions)

    def macro_step(self, state: S, event: str) -> tuple[S, Outputs]:
        """Post ``event``, tick; tick again if the root succeeded with it pending; drop it.

        Args:
            state: the state after the previous macro step (or ``initial``).
            event: the event posted.

        Returns:
            The next state and the actions run during the step, in order.
        """
        memory, bb_state, _last = state
        bb = self._blackboard(bb_state, event)
        actions: list[str] = []
        tick = self._tick
        memory, result = tick(memory, bb, actions)
        if result is _SUCCESS and bb.event != NO_EVENT:
            memory, result = tick(memory, bb, actions)
        bb.event = NO_EVENT  # an event still pending is dropped
        return self._make_state(memory, bb.state, result), tuple(actions)

    def terminated(self, state: S) -> bool:
        """Root SUCCESS and nothing running: the FSM is in a final state. Before the start
        pseudo-state is left (an initial event not seen yet) a SUCCESS only says that no guard
        fired, so it does not count (docs/semantics.md)."""
        _memory, bb_state, last = state
        return last is _SUCCESS and bb_state != self.leaves.start


class EngineLebtState(NamedTuple):
    """An engine runtime's state: the engine holds its own memory, so there is none here."""

    memory: None
    bb_state: str
    last_result: NodeStatus | None


class EngineLebtRun:
    """The macro-step driver for a real engine (BehaviorTree.CPP, py_trees), which keeps its
    own tree memory and blackboard, so it is run in place, one step after the other.

    A subclass sets ``leaves`` and ``bb`` (the engine's blackboard) and implements
    ``_tick_engine`` (one root tick of the engine, returning the root's ``NodeStatus``); its
    state leaves append the actions they run to ``actions``.
    """

    leaves: LebtLeaves
    bb: LebtBlackboard

    def __init__(self) -> None:
        self.actions: list[str] = []
        self.last_result: NodeStatus | None = None

    def _tick_engine(self) -> NodeStatus:
        raise NotImplementedError

    def _engine_tick(
        self, memory: None, bb: LebtBlackboard, actions: list[str]
    ) -> tuple[None, NodeStatus]:
        """The tick function: the engine's leaves write into ``bb`` (the engine's) and
        ``self.actions``."""
        self.actions = actions
        self.last_result = self._tick_engine()
        return None, self.last_result

    def _engine_blackboard(self, state: str, event: str) -> LebtBlackboard:
        self.bb.state = state
        self.bb.event = event
        return self.bb

    @cached_property
    def driver(self) -> MacroStepDriver[None, EngineLebtState]:
        """The one macro-step driver, over this engine's tick function and blackboard."""
        return MacroStepDriver(
            self.leaves, self._engine_tick, None, EngineLebtState, self._engine_blackboard
        )

    @property
    def state(self) -> EngineLebtState:
        """The engine's state between macro steps (``state`` is its blackboard's)."""
        return EngineLebtState(None, self.bb.state, self.last_result)

    def initial(self) -> tuple[str, ...]:
        """What runs before any event: the initial state's action when no initial event."""
        return self.driver.initial()[1]

    def macro_step(self, event: str) -> tuple[str, ...]:
        """One macro step on the engine (``MacroStepDriver.macro_step``); the actions run."""
        return self.driver.macro_step(self.state, event)[1]

    @property
    def terminated(self) -> bool:
        """``MacroStepDriver.terminated`` of the engine's current state."""
        return self.driver.terminated(self.state)
