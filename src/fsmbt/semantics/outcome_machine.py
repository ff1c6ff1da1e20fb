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
Parallel or product") is a ``Round`` state: each child's outcome so far and the child about to
run. Entering it runs its first child; after each answer the source decision
(``Concurrence.decide``) is taken, and a decided outcome leaves the container like the
product's final state of that name; else the next child still running runs
(``outcome_parallel.next_child``).

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
    while it runs), and the index of the child about to run."""

    region: str
    done: Done
    index: int


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

    def start(self) -> tuple[OutcomeState, Outputs]:
        top = self.view.top
        if top.parallel and top.concurrence is not None:
            first = Round("", tuple(None for _ in top.concurrence.labels), 0)
            return first, (self.units[self._child(first)].label,)
        return self._enter("", top.initial)

    def _child(self, state: Round) -> str:
        region = self.view.regions[state.region]
        concurrence = region.concurrence
        assert concurrence is not None
        return f"{state.region}/{concurrence.labels[state.index]}" if state.region else (
            concurrence.labels[state.index])  # fmt: skip

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
        return self._enter(self.region_of[state], unit.targets[symbol])

    def status(self, state: OutcomeState) -> str:
        return FINAL if isinstance(state, tuple) else RUNNING

    def describe(self, state: OutcomeState) -> str:
        if isinstance(state, Round):
            return self.units[self._child(state)].label
        return state[0] if isinstance(state, tuple) else self.units[state].label

    def _round_step(self, state: Round, symbol: str) -> tuple[OutcomeState, Outputs]:
        done = state.done
        if symbol != RUNNING_INPUT:
            done = done[: state.index] + (symbol,) + done[state.index + 1 :]
            concurrence = self.view.regions[state.region].concurrence
            assert concurrence is not None
            outcome = concurrence.decide(done)
            if outcome is not None:
                return self._enter(state.region, outcome)
        after = Round(state.region, done, next_child(done, state.index))
        return after, (self.units[self._child(after)].label,)

    def _enter(self, region_path: str, target: str) -> tuple[OutcomeState, Outputs]:
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
                    result = self.view.root_result(target)
                    return (result,), (result,)
                region_path = self.region_of[owner.path]
                target = owner.targets[target]
                continue
            unit = region.units[target]
            if unit.container and self.view.regions[unit.path].parallel:
                inner = self.view.regions[unit.path].concurrence
                assert inner is not None
                first = Round(unit.path, tuple(None for _ in inner.labels), 0)
                return first, (self.units[self._child(first)].label,)
            if unit.container:
                region_path = unit.path
                target = self.view.regions[unit.path].initial
                continue
            return unit.path, (unit.label,)
