"""An outcome-driven machine whose container ends with an outcome its parent does not map
(docs/semantics.md §11): stepping into it is a located ``OutcomeError``, never a ``KeyError``
(found by a corpus mutant retargeted to a ``preempted`` final; SMACH raises there too)."""

from __future__ import annotations

import pytest

from fsmbt.semantics.outcome_machine import OutcomeFSMMachine
from fsmbt.semantics.outcome_rules import OutcomeError
from support.structured_btcpp import read_structured_view
from support.structured_machines import container, machine


def test_an_unmapped_container_outcome_is_a_located_error() -> None:
    inner = machine(
        {"A": {"succeeded": "succeeded", "aborted": "preempted"}},
        finals=("succeeded", "aborted", "preempted"),
        name="inner",
    )
    outer = machine({"B": {"succeeded": "succeeded", "aborted": "aborted"}}, name="outer")
    container(outer, "C", inner, {"succeeded": "B", "aborted": "aborted"}, first=True)
    runner = OutcomeFSMMachine(read_structured_view(outer))
    state, _outputs = runner.start()
    assert runner.step(state, "succeeded")[0] != state  # a mapped outcome goes on
    with pytest.raises(OutcomeError, match="'preempted'") as raised:
        runner.step(state, "aborted")
    assert "C" in str(raised.value)  # the container is named
