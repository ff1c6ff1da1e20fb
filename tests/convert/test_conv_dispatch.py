"""The dispatch style (docs/semantics.md section 12): built, proven, logarithmic, bad input."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.generate import random_fsm
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_runtime import DispatchMachine
from fsmbt.verify import verify


@pytest.mark.parametrize("shape", ["tree", "chain"])
@pytest.mark.parametrize("n", [1, 2, 7, 40])
@pytest.mark.parametrize("start_event", [False, True])
def test_dispatch_is_proven_equivalent(shape: str, n: int, start_event: bool) -> None:
    extra = {"extra_edges": 0} if shape == "chain" else {}
    fsm = random_fsm(f"d{n}", n, start_event=start_event, shape=shape, **extra)  # type: ignore[arg-type]
    result = convert(fsm, style="dispatch")
    assert result.stats["style"] == "dispatch"
    doc = loads(dumps(result.model, "btcpp"), "btcpp")  # what BehaviorTree.CPP reads
    assert verify(fsm, doc).equivalent


def test_a_wrong_target_is_caught() -> None:
    fsm = random_fsm("wrong", 12, start_event=False, shape="tree")
    text = dumps(convert(fsm, style="dispatch").model, "btcpp")
    # a transition writes only the digits it changes: take the second one writing d0
    scripts = [line for line in text.splitlines() if "fsm_d0:='" in line]
    first = scripts[1]
    assert "fsm_d0:='" in first
    digit = first.split("fsm_d0:='")[1][0]
    other = "b" if digit != "b" else "c"
    mutated = text.replace(first, first.replace(f"fsm_d0:='{digit}'", f"fsm_d0:='{other}'"), 1)
    report = verify(fsm, loads(mutated, "btcpp"))
    assert not report.equivalent
    trace = report.properties["completeness"].counterexample or []
    assert trace and all(step.result_state in fsm.states for step in trace)  # named, not digits


def test_macro_steps_follow_the_fsm() -> None:
    fsm = FSM("door")
    fsm.add_state("Closed", action="lock")
    fsm.add_state("Open", action="beep")
    fsm.add_state("Gone", final=True)
    fsm.initial = "Closed"
    fsm.add_transition("Closed", "push", "Open")
    fsm.add_transition("Open", "push", "Closed")
    fsm.add_transition("Open", "leave", "Gone")
    machine = DispatchMachine(convert(fsm, style="dispatch").model, ["push", "leave"])
    state, out = machine.start()
    assert out == ("lock",) and machine.status(state) == "running"
    state, out = machine.step(state, "leave")  # ignored in Closed
    assert out == ()
    state, out = machine.step(state, "push")
    assert out == ("beep",)
    state, out = machine.step(state, "leave")
    assert machine.status(state) == "final"


def test_depth_is_logarithmic() -> None:
    depths = {}
    for n in (100, 5000):
        fsm = random_fsm(f"c{n}", n, start_event=False, shape="chain", extra_edges=0)
        depths[n] = int(convert(fsm, style="dispatch").stats["depth"])
    # log7 levels of index Switches (+ the root's seventh digit) + an event Switch + the
    # transition (KeepRunningUntilFailure, Sequence, Script): 3 + 1 + 3, 5 + 1 + 1 + 3
    assert depths[100] <= 8
    assert depths[5000] <= 10


def test_numeric_event_is_refused() -> None:
    fsm = FSM("num")
    fsm.add_state("A")
    fsm.add_state("B")
    fsm.initial = "A"
    fsm.add_transition("A", "42", "B")
    with pytest.raises(UnsupportedError, match="state 'A'"):
        convert(fsm, style="dispatch")


def test_auto_gives_an_event_driven_machine_the_dispatch_form() -> None:
    fsm = random_fsm("auto", 30, start_event=True, shape="tree")
    result = convert(fsm)  # style auto
    assert result.stats["style"] == "dispatch" and result.warnings == []
    assert verify(fsm, result.model).equivalent
    assert convert(fsm, style="lebt").stats["style"] == "lebt"  # the paper's shape, asked for


def test_auto_writes_the_lebt_where_a_switch_cannot_compare_an_event() -> None:
    fsm = FSM("num")
    fsm.add_state("A")
    fsm.add_state("B")
    fsm.initial = "A"
    fsm.add_transition("A", "42", "B")
    result = convert(fsm)
    assert result.stats["style"] == "lebt"
    (warning,) = [w for w in result.warnings if "dispatch form cannot be written" in w]
    assert "state 'A'" in warning and "'42'" in warning
    assert verify(fsm, result.model).equivalent


def test_auto_keeps_the_dispatch_form_when_nusmv_checks_the_result(tmp_path: Path) -> None:
    from fsmbt import api

    source = tmp_path / "fsm.json"
    api.write(random_fsm("nusmv", 6, start_event=False, shape="tree"), source)
    native = api.convert_file(source)
    assert native.conversion.stats["style"] == "dispatch"
    checked = api.convert_file(source, verify_engine="nusmv")  # NuSMV encodes the form
    assert checked.conversion.stats["style"] == "dispatch" and checked.equivalent
    assert not any("NuSMV" in w for w in checked.warnings)
    both = api.convert_file(source, style="dispatch", verify_engine="both")
    assert both.equivalent and both.report is not None
    assert both.report.engine == "native+nusmv"


def test_post_conditions_other_than_literal_on_success_on_an_entry_are_refused() -> None:
    fsm = random_fsm("post", 5, start_event=False, shape="chain", extra_edges=0)
    text = dumps(convert(fsm, style="dispatch").model, "btcpp")
    assert "_onSuccess=" in text  # the transitions write their digits after the leaf
    line = next(x for x in text.splitlines() if "_onSuccess=" in x)
    bad_code = line.replace('_onSuccess="', '_onSuccess="fsm_d0:=fsm_d1; ', 1)
    on_switch = text.replace("<Switch2 ", "<Switch2 _onSuccess=\"fsm_d0:='a'\" ", 1)
    on_failure = text.replace(line, line.replace("_onSuccess=", "_onFailure="), 1)
    for bad in (text.replace(line, bad_code, 1), on_switch, on_failure):
        assert bad != text
        with pytest.raises(UnsupportedError, match="_on") as caught:
            DispatchMachine(loads(bad, "btcpp"), ["x"])
        assert caught.value.location is not None
