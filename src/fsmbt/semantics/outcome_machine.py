"""An outcome-driven FSM as a leaf-execution machine over its states' outcomes
(docs/semantics.md, "11. Outcome-driven machines", "The outcome pairing").

A state is the atomic state about to run (its path) or the root's result. ``start`` enters the
initial state, descending into containers; the output is the state's label (the leaf the BT
ticks). An input is one of that state's outcomes (``OutcomeView``: halting ``preempted``
outcomes removed) or ``running`` (the state goes on: its label is output again, as a BT leaf
ticked again). An outcome follows its transition; reaching a container's final state takes the
container's completion transition for that outcome, up as many levels as it takes; reaching a
top-level final state ends the run with ``SUCCESS``/``FAILURE`` (``OutcomeView.root_result``).

Cost: O(nesting depth) per step; states are strings and result tuples.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.semantics.machine import FINAL, RUNNING, Outputs
from fsmbt.semantics.outcome_rules import OutcomeError
from fsmbt.semantics.outcome_view import RUNNING_INPUT, OutcomeView

#: A state: an atomic state's path, or ``(result,)`` once the machine has ended.
OutcomeState = str | tuple[str]


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
        return self._enter("", self.view.top.initial)

    def inputs(self, state: OutcomeState) -> Sequence[str]:
        if isinstance(state, tuple):
            return ()
        return (*self.units[state].outcomes, RUNNING_INPUT)

    def step(self, state: OutcomeState, symbol: str) -> tuple[OutcomeState, Outputs]:
        if isinstance(state, tuple):
            return state, ()
        unit = self.units[state]
        if symbol == RUNNING_INPUT:
            return state, (unit.label,)
        return self._enter(self.region_of[state], unit.targets[symbol])

    def status(self, state: OutcomeState) -> str:
        return FINAL if isinstance(state, tuple) else RUNNING

    def describe(self, state: OutcomeState) -> str:
        return state[0] if isinstance(state, tuple) else self.units[state].label

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
            if unit.container:
                region_path = unit.path
                target = self.view.regions[unit.path].initial
                continue
            return unit.path, (unit.label,)
