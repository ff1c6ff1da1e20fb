"""The outcome pairing of a source machine and the BT -> FSM conversion of its structured tree
(docs/semantics.md §11, "The outcome pairing"): the round trip FSM -> structured BT -> FSM is
proven equivalent to the source by the same machines as the structured tree itself, the
converted FSM read as a leaf-execution machine (``FSMLeafMachine``) whose leaves are fed the
source states' outcomes through the outcome rules.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.convert.structured.schedule import read_structured_view
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import FINAL, FSMLeafMachine, Outputs
from fsmbt.semantics.outcome_machine import OutcomeFSMMachine
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.semantics.outcome_view import RUNNING_INPUT, OutcomeView, Unit
from fsmbt.verify.outcome_pairing import OUTCOME_EXECUTION


class OutcomeFSMLeafMachine:
    """A BT -> FSM conversion of a structured tree (an FSM over leaf statuses, read as a
    leaf-execution machine, ``FSMLeafMachine``) fed the source states' outcomes: in a state
    about to run leaf ``L``, the inputs are the outcomes of the source unit labelled ``L``,
    each given to the FSM as the status the outcome rules map it to. Only for trees without a
    dispatch (the rules engine's BT -> FSM refuses ``Switch``)."""

    follows_environment = False

    def __init__(self, leaf_fsm: FSM, view: OutcomeView) -> None:
        self.inner = FSMLeafMachine(leaf_fsm)
        self.view = view
        self.name = self.inner.name

    def _unit(self, state: str) -> Unit | None:
        action = self.inner.fsm.states[state].action
        return self.view.by_label.get(action) if action is not None else None

    def start(self) -> tuple[str, Outputs]:
        return self.inner.start()

    def inputs(self, state: str) -> Sequence[str]:
        unit = self._unit(state)
        if self.inner.status(state) == FINAL or unit is None:
            return self.inner.inputs(state)
        return (*unit.outcomes, RUNNING_INPUT)

    def step(self, state: str, symbol: str) -> tuple[str, Outputs]:
        unit = self._unit(state)
        if unit is None or symbol == RUNNING_INPUT or symbol not in unit.status:
            return self.inner.step(state, symbol)
        return self.inner.step(state, unit.status[symbol] or "success")

    def status(self, state: str) -> str:
        return self.inner.status(state)

    def describe(self, state: str) -> str:
        return self.inner.describe(state)


def leaf_fsm_machines(
    source: FSM, leaf_fsm: FSM, rules: OutcomeRules | None = None
) -> tuple[OutcomeFSMMachine, OutcomeFSMLeafMachine, str]:
    """The outcome pairing of a source machine and the BT -> FSM conversion of its structured
    tree (``OutcomeFSMLeafMachine``)."""
    view = read_structured_view(source, rules)
    return OutcomeFSMMachine(view), OutcomeFSMLeafMachine(leaf_fsm, view), OUTCOME_EXECUTION
