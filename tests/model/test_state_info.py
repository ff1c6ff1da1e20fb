"""The state metadata contract between readers and converters (model/state_info.py)."""

from fsmbt.model import state_info
from fsmbt.model.fsm import State


def test_encoded_fields_read_back() -> None:
    attrs = state_info.encode(
        outcomes=["done", "failed"],
        params={"text": "hello", "velocity": "0.5"},
        expression_params=["target"],
        inputs=["pose"],
        outputs=["result"],
        remap={"pose": "home"},
    )
    state = State("Log", action="LogState", attrs=attrs)
    assert state_info.declared_outcomes(state) == ["done", "failed"]
    assert state_info.parameters(state) == {"text": "hello", "velocity": "0.5"}
    assert state_info.expression_parameters(state) == ["target"]
    assert state_info.input_keys(state) == ["pose"]
    assert state_info.output_keys(state) == ["result"]
    assert state_info.remapping(state) == {"pose": "home"}
    assert state_info.state_class(state) == "LogState"


def test_unknown_fields_have_empty_answers() -> None:
    state = State("A", action=None, attrs={state_info.OUTCOMES: "not json"})
    assert state_info.declared_outcomes(state) is None
    assert state_info.parameters(state) == {}
    assert state_info.remapping(state) == {}
    assert state_info.ros_interface(state) is None
    assert state_info.state_class(state) is None
