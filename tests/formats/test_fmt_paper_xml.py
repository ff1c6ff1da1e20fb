"""The reference paper's FSM XML: start pseudo-state, final-state rule, round trip, errors."""

from __future__ import annotations

import pytest

from fsmbt.formats import dumps, loads
from fsmbt.model import FSM, State
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.semantics.machine import FSMMachine

PAPER = """<FSM>
  <InitialState name="Start"/>
  <States>
    <State name="A" type="normal"/>
    <State name="B" type="normal"/>
    <State name="C" type="final"/>
  </States>
  <Transitions>
    <Transition from="Start" to="A" event="eventSA"/>
    <Transition from="A" to="B" event="eventAB"/>
    <Transition from="B" to="A" event="eventBA"/>
    <Transition from="B" to="C" event="eventBC"/>
  </Transitions>
</FSM>
"""


def test_start_pseudo_state_becomes_initial_event() -> None:
    fsm = loads(PAPER, "paper-xml")
    assert (fsm.start_name, fsm.initial, fsm.initial_event) == ("Start", "A", "eventSA")
    assert "Start" not in fsm.states
    assert all(t.source != "Start" for t in fsm.transitions)
    assert [s.name for s in fsm.states.values() if s.final] == ["C"]
    assert fsm.states["A"].action == "A"
    assert fsm.transitions[0].location is not None and fsm.transitions[0].location.line == 10
    machine = FSMMachine(fsm)
    state, out = machine.start()
    assert out == ()
    state, out = machine.step(state, "eventSA")
    assert (state, out) == ("A", ("A",))


def test_round_trip_restores_the_pseudo_state() -> None:
    fsm = loads(PAPER, "paper-xml")
    text = dumps(fsm, "paper-xml")
    assert '<Transition from="Start" to="A" event="eventSA"/>' in text
    assert loads(text, "paper-xml") == fsm


def test_initial_state_naming_a_real_state_and_text_form() -> None:
    fsm = loads(
        "<FSM><InitialState>B</InitialState><States><State name='A'/><State name='B'/>"
        "</States><Transitions><Transition from='B' to='A' event='e'/></Transitions></FSM>",
        "paper-xml",
    )
    assert (fsm.initial, fsm.start_name, fsm.initial_event) == ("B", None, None)
    # no state is marked final: a state with no way out is final (docs/semantics.md, 'Models')
    assert fsm.states["A"].final and not fsm.states["B"].final
    assert loads(dumps(fsm, "paper-xml"), "paper-xml") == fsm


def test_unmarked_model_without_finals_round_trips() -> None:
    fsm = FSM()
    fsm.add_state("A")
    fsm.add_state("B", action="beep")
    fsm.add_transition("A", "go", "B")
    text = dumps(fsm, "paper-xml")
    assert 'finals="marked"' in text and 'action="beep"' in text
    assert loads(text, "paper-xml") == fsm


def test_duplicate_state_names_its_line() -> None:
    with pytest.raises(InputError, match="duplicate state 'A'") as info:
        loads("<FSM>\n<States>\n<State name='A'/>\n<State name='A'/>\n</States></FSM>", "paper-xml")
    assert info.value.location.line == 4


def test_unknown_target_is_kept_for_validation() -> None:
    fsm = loads(
        "<FSM><InitialState name='A'/><States><State name='A'/></States><Transitions>"
        "<Transition from='A' to='Z' event='e'/></Transitions></FSM>",
        "paper-xml",
    )
    assert fsm.transitions[0].target == "Z" and "Z" not in fsm.states


@pytest.mark.parametrize(
    "text, match",
    [
        ("<FSM><States><State/></States></FSM>", "without name"),
        ("<FSM><States><State name='A' type='weird'/></States></FSM>", "unknown state type"),
        ("<FSM><InitialState name='S'/><States><State name='A'/></States></FSM>", "exactly one"),
        ("<FSM><Bogus/></FSM>", "unexpected element"),
        ("<FSM><Transitions><Transition from='A'/></Transitions></FSM>", "'from' and 'to'"),
    ],
)
def test_errors(text: str, match: str) -> None:
    with pytest.raises(InputError, match=match):
        loads(text, "paper-xml")


def test_hierarchical_fsm_cannot_be_written() -> None:
    inner = FSM(name="C")
    inner.add_state("x")
    fsm = FSM()
    fsm.add_state(State("C", regions=[inner]))
    with pytest.raises(UnsupportedError):
        dumps(fsm, "paper-xml")


def test_detected_by_root_element_in_xml_file(tmp_path) -> None:
    from fsmbt import api

    path = tmp_path / "machine.xml"
    path.write_text(PAPER)
    assert isinstance(api.load(path).model, FSM)
