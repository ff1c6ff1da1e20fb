"""The execution registry (fsmbt.semantics.execution): one answer to "how does this model run"."""

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.semantics.execution import (
    Flavour,
    check_engine,
    engines_for,
    event_machine,
    flavour_of,
    leaf_machine,
)
from fsmbt.verify.orient import (
    DISPATCH_RULE,
    LEAF_EXECUTION_RULE,
    LEBT_RULE,
    STATE_VARIABLE_RULE,
    orient,
)

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def models() -> dict[str, object]:
    fsm = api.load(EXAMPLES / "paper_fsm.xml").model
    return {
        "fsm": fsm,
        "lebt": api.convert_model(fsm, "rules", style="lebt").model,
        "dispatch": api.convert_model(fsm, "rules").model,  # auto, an event-driven machine
        "bsd": api.convert_model(fsm, "bsd").model,
        "plain": api.load(EXAMPLES / "robot_bt.xml").model,
    }


def test_each_model_has_one_flavour_and_the_verifier_pairs_by_it(models: dict) -> None:
    assert [flavour_of(models[k]) for k in ("fsm", "lebt", "dispatch", "bsd", "plain")] == [
        Flavour.FSM,
        Flavour.LEBT,
        Flavour.DISPATCH,
        Flavour.STATE_VARIABLE,
        Flavour.PLAIN,
    ]
    fsm = models["fsm"]
    assert orient(fsm, models["lebt"]).rule == LEBT_RULE
    assert orient(models["dispatch"], fsm).rule == DISPATCH_RULE
    assert orient(models["bsd"], fsm).rule == STATE_VARIABLE_RULE
    assert orient(fsm, models["plain"]).rule == LEAF_EXECUTION_RULE


def test_engines_per_flavour(models: dict) -> None:
    assert engines_for(models["fsm"]) == ("fsmbt", "python-statemachine")
    assert engines_for(models["bsd"]) == ("fsmbt",)
    assert engines_for(models["dispatch"]) == ("fsmbt",)
    assert engines_for(models["lebt"]) == ("fsmbt", "btcpp", "py_trees")
    with pytest.raises(InputError, match="unknown engine 'ros'"):
        check_engine(models["plain"], "ros")
    with pytest.raises(UnsupportedError, match="cannot run on btcpp"):
        check_engine(models["bsd"], "btcpp", "the BSD tree")


def test_machines_run_the_same_step_as_the_checker(models: dict) -> None:
    fsm = models["fsm"]
    alphabet = fsm.events()
    source = event_machine(fsm, alphabet)
    for kind in ("lebt", "dispatch"):
        converted = event_machine(models[kind], alphabet)
        state_a, out_a = source.start()
        state_b, out_b = converted.start()
        assert out_a == out_b
        for event in alphabet[:4]:
            state_a, out_a = source.step(state_a, event)
            state_b, out_b = converted.step(state_b, event)
            assert out_a == out_b, kind
    with pytest.raises(InputError, match="plain BT has no events"):
        event_machine(models["plain"], alphabet)
    leaf = leaf_machine(models["plain"])
    _state, first = leaf.start()
    assert first  # the first leaf ticked
