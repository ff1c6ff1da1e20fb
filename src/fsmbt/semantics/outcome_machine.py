"""An outcome-driven FSM as a leaf-execution machine over its states' outcomes
(docs/semantics.md, "11. Outcome-driven machines", "The outcome pairing").

A state is the atomic state about to run (its path) or the root's result. ``start`` enters the
initial state, descending into containers; the output is the state's label (the leaf the BT
ticks). An input is one of that state's outcomes (``OutcomeView``: halting ``preempted``
outcomes removed) or ``running`` (the state goes on: its label is output again, as a BT leaf
ticked again). An outcome follows its transition; reaching a container's final state takes the
container's completion transition for that outcome, up as many levels as it takes; reaching a
top-level final state ends the run with ``SUCCESS``/``FAILURE`` (``OutcomeView.root_result``).

A Concurrence read in rounds (``Region.parallel``; docs/semantics.md §11, "Concurrences:
Parallel or product") is a ``Round`` state: each child's outcome so far, the child about to
run and where each container child is. Entering it runs its first child; a container child's
outcome that leads to another of its states keeps its turn (its SubTree goes on in the same
tick), unless it goes round a loop (``Region.round_trips``: its tree returns RUNNING there);
when a child ends the source decision (``Concurrence.decide``) is taken, and a decided outcome
leaves the container like the product's final state of that name; else, and after ``running``,
the next child still running runs (``outcome_parallel.next_child``; docs/semantics.md §11,
"Container children").

Cost: O(nesting depth) per step; states are strings and result tuples.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from fsmbt.semantics.machine import FINAL, RUNNING, Outputs
from fsmbt.semantics.outcome_parallel import Done, next_child
from fsmbt.semantics.outcome_rules import OutcomeError
from fsmbt.semantics.outcome_view import RUNNING_INPUT, OutcomeView, Unit


@dataclass(frozen=True, order=True)
class Round:
    """Inside a Concurrence read in rounds: its region, each child's outcome so far (None
    while it runs), the index of the child about to run, and where each container child is
    (the path of its atomic state about to run; "" for a leaf child or one that has ended)."""

    region: str
    done: Done
    index: int
    inner: tuple[str, ...] = ()


@dataclass(frozen=True)
class _Ended:
    """A container child of a concurrence reached its final state ``outcome``."""

    outcome: str


#: A state: an atomic state's path, a ``Round``, or ``(result,)`` once the machine has ended.
OutcomeState = str | tuple[str] | Round


class OutcomeFSMMachine:
    """``Machine`` over outcomes for an ``OutcomeView`` (see the module docstring)."""

    follows_environment = False

    def __init__(self, view: OutcomeView) -> None:
        self.view = view
        self.name = view.fsm.name
        self.units = {u.path: u for r in view.regions.values() for u in r.units.values()}
        self.region_of = {
            u.path: path for path, r in view.regions.items() for u in r.units.values()
        }
        self.round_trips = frozenset(t for r in view.regions.values() for t in r.round_trips)
        #: Whether the last ``_enter`` took a round trip (a loop of a container child going
        #: round: its SubTree returns RUNNING, the turn passes on).
        self._went_round = False

    def start(self) -> tuple[OutcomeState, Outputs]:
        top = self.view.top
        if top.parallel:
            first = self._round_start("")
            return first, (self.units[self._child(first)].label,)
        return self._settled(self._enter("", top.initial))

    def _child_path(self, region: str, index: int) -> str:
        concurrence = self.view.regions[region].concurrence
        assert concurrence is not None
        label = concurrence.labels[index]
        return f"{region}/{label}" if region else label

    def _child(self, state: Round) -> str:
        """The path of the atomic state about to run in a Round."""
        if state.inner and state.inner[state.index]:
            return state.inner[state.index]
        return self._child_path(state.region, state.index)

    def _round_start(self, region: str) -> Round:
        """Entering a Concurrence: no child has ended, each container child at its first
        state (it runs one before it ends: ``outcome_view``), the first child about to run."""
        concurrence = self.view.regions[region].concurrence
        assert concurrence is not None
        inner: list[str] = []
        for index in range(len(concurrence.labels)):
            unit = self.units[self._child_path(region, index)]
            if not unit.container:
                inner.append("")
                continue
            entered = self._enter(unit.path, self.view.regions[unit.path].initial)
            assert isinstance(entered, str), "a container child runs a state before it ends"
            inner.append(entered)
        return Round(region, tuple(None for _ in inner), 0, tuple(inner))

    def _settled(self, entered: OutcomeState | _Ended) -> tuple[OutcomeState, Outputs]:
        """A state reached outside any concurrence child, with its output."""
        assert not isinstance(entered, _Ended)
        if isinstance(entered, tuple):
            return entered, entered
        return entered, (self.describe(entered),)

    def unit_of(self, state: str | Round) -> Unit:
        """The unit about to run in a state that has not ended."""
        return self.units[self._child(state) if isinstance(state, Round) else state]

    def inputs(self, state: OutcomeState) -> Sequence[str]:
        if isinstance(state, tuple):
            return ()
        return (*self.unit_of(state).outcomes, RUNNING_INPUT)

    def step(self, state: OutcomeState, symbol: str) -> tuple[OutcomeState, Outputs]:
        if isinstance(state, tuple):
            return state, ()
        if isinstance(state, Round):
            return self._round_step(state, symbol)
        unit = self.units[state]
        if symbol == RUNNING_INPUT:
            return state, (unit.label,)
        return self._settled(self._enter(self.region_of[state], unit.targets[symbol]))

    def status(self, state: OutcomeState) -> str:
        return FINAL if isinstance(state, tuple) else RUNNING

    def describe(self, state: OutcomeState) -> str:
        if isinstance(state, Round):
            return self.units[self._child(state)].label
        return state[0] if isinstance(state, tuple) else self.units[state].label

    def _round_step(self, state: Round, symbol: str) -> tuple[OutcomeState, Outputs]:
        """One answer inside a Round: a container child's outcome that leads to another of its
        states keeps it running (its SubTree goes on in the same tick); a child that ends
        records its outcome and the source decision is taken; a leaf that runs on, or a child
        that ended without a decision, passes the turn to the next child still running."""
        done, inner = state.done, state.inner
        index = state.index
        if symbol != RUNNING_INPUT:
            ended: str | None = symbol
            if inner and inner[index]:
                here = inner[index]
                self._went_round = (here, symbol) in self.round_trips
                entered = self._enter(self.region_of[here], self.units[here].targets[symbol])
                if not isinstance(entered, _Ended):
                    assert isinstance(entered, str), "a container child holds no concurrence"
                    inner = _put(inner, index, entered)
                    if self._went_round:  # its tree returned RUNNING: the next child's turn
                        after = Round(state.region, done, next_child(done, index), inner)
                        return after, (self.units[self._child(after)].label,)
                    after = Round(state.region, done, index, inner)
                    return after, (self.units[entered].label,)
                ended = entered.outcome
                inner = _put(inner, index, "")
            done = done[:index] + (ended,) + done[index + 1 :]
            concurrence = self.view.regions[state.region].concurrence
            assert concurrence is not None
            outcome = concurrence.decide(done)
            if outcome is not None and concurrence.callback_state is not None:
                outcome = concurrence.callback_state  # its outcome_cb runs, as a leaf
            if outcome is not None:
                return self._settled(self._enter(state.region, outcome))
        after = Round(state.region, done, next_child(done, index), inner)
        return after, (self.units[self._child(after)].label,)

    def _enter(self, region_path: str, target: str) -> OutcomeState | _Ended:
        """The state reached by going to ``target`` in a region: up through the containers
        it ends (``_Ended`` at a concurrence child's end), down into the ones it enters."""
        seen: set[tuple[str, str]] = set()
        while True:
            if (region_path, target) in seen:
                raise OutcomeError(
                    "containers enter and leave each other forever without running a state",
                    element=f"state '{target}'",
                )
            seen.add((region_path, target))
            region = self.view.regions[region_path]
            state = region.machine.states[target]
            if state.final:
                owner = region.owner
                if owner is None:
                    return (self.view.root_result(target),)
                region_path = self.region_of[owner.path]
                if self.view.regions[region_path].parallel:
                    return _Ended(target)
                if (owner.path, target) in self.round_trips:
                    self._went_round = True
                onward = owner.targets.get(target)
                if onward is None:  # SMACH raises on an outcome its container does not map
                    raise OutcomeError(
                        f"the container ends with outcome '{target}', which its parent "
                        "state machine does not map to a transition",
                        element=f"state '{owner.path}'",
                    )
                target = onward
                continue
            unit = region.units[target]
            if unit.container and self.view.regions[unit.path].parallel:
                return self._round_start(unit.path)
            if unit.container:
                region_path = unit.path
                target = self.view.regions[unit.path].initial
                continue
            return unit.path


def _put(inner: tuple[str, ...], index: int, value: str) -> tuple[str, ...]:
    return inner[:index] + (value,) + inner[index + 1 :]
