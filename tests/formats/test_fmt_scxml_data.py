"""SCXML's finite data model read exactly (docs/formats/scxml.md, "Data read exactly"):
tracked variables in each state, computed guards, ``<send eventexpr>``, ``<script>`` that
cannot affect control flow, the state limit on unbounded variables, the dialects."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api, limits
from fsmbt.formats import loads
from fsmbt.formats.registry import ReadContext
from fsmbt.formats.scxml.datamodel import StateLimitError, literal_prefix, may_match_prefix
from fsmbt.formats.scxml.expr import (
    ECMASCRIPT,
    JEXL,
    PYTHON,
    UNDEFINED,
    ExecutionError,
    OutsideSubset,
    evaluate,
    parse,
)
from fsmbt.formats.scxml.structural import read_scxml
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import FSMMachine
from support.corpus import CORPUS

REPO = Path(__file__).resolve().parents[2]
NS = 'xmlns="http://www.w3.org/2005/07/scxml"'


def doc(body: str, datamodel: str = "ecmascript") -> str:
    return f'<scxml {NS} version="1.0" datamodel="{datamodel}">{body}\n</scxml>'


def walk(model: FSM, events: list[str]) -> list[str]:
    machine = FSMMachine(model)
    state, _ = machine.start()
    seen = [state]
    for event in events:
        state, _ = machine.step(state, event)
        seen.append(state)
    return seen


def read(text: str) -> tuple[FSM, list[str]]:
    warnings: list[str] = []
    return read_scxml(text, ReadContext(warnings=warnings)), warnings


# -- the data in each state ----------------------------------------------------------------------
MICROWAVE = """
  <datamodel><data id="cook" expr="2"/><data id="t" expr="0"/><data id="closed" expr="true"/>
  </datamodel>
  <state id="off"><transition event="on" target="on"/></state>
  <state id="on" initial="idle">
    <transition event="off" target="off"/><transition cond="t &gt;= cook" target="off"/>
    <state id="idle"><transition cond="closed" target="cooking"/>
      <transition event="close" target="cooking"><assign location="closed" expr="true"/>
      </transition></state>
    <state id="cooking"><transition event="open" target="idle">
      <assign location="closed" expr="false"/></transition>
      <transition event="time"><assign location="t" expr="t + 1"/></transition></state>
  </state>"""


def test_variables_that_change_are_part_of_each_state_and_guards_are_computed() -> None:
    model, warnings = read(doc(MICROWAVE))
    assert walk(model, ["on", "time", "open", "close", "time"]) == [
        "off#t=0;closed=true",
        "on/cooking#t=0;closed=true",  # the eventless guard 'closed' is computed: true
        "on/cooking#t=1;closed=true",
        "on/idle#t=1;closed=false",
        "on/cooking#t=1;closed=true",
        "off#t=2;closed=true",  # t >= cook: the eventless transition of 'on'
    ]
    assert sorted(model.events()) == ["close", "off", "on", "open", "time"]  # no guard input
    assert any("values of t, closed are part of each state" in w for w in warnings)
    assert any("cook never change(s)" in w for w in warnings)


def test_a_data_machine_converts_and_verifies() -> None:
    model, _ = read(doc(MICROWAVE))
    result = api.convert_model(model)
    assert api.verify_models(model, result.model, "native").equivalent


def test_assignments_no_guard_reads_are_ignored_and_stay_out_of_the_state() -> None:
    body = MICROWAVE.replace(
        '<transition event="time">', '<transition event="time"><assign location="n" expr="n + 1"/>'
    ).replace('<data id="t" expr="0"/>', '<data id="t" expr="0"/><data id="n" expr="0"/>')
    model, warnings = read(doc(body))
    assert walk(model, ["on", "time"])[-1] == "on/cooking#t=1;closed=true"
    assert any("<assign> to 'n' ignored (no cond reads it)" in w for w in warnings)


def test_an_unbounded_variable_ends_in_the_state_limit_naming_it() -> None:
    body = """
  <datamodel><data id="n" expr="0"/></datamodel>
  <state id="s"><transition event="tick" target="s"><assign location="n" expr="n + 1"/>
    </transition><transition event="stop" cond="n == 3" target="end"/></state>
  <final id="end"/>"""
    with limits.changed(conversion_max_states=50):
        with pytest.raises(StateLimitError, match=r"the variable 'n' took \d+ distinct values"):
            loads(doc(body), "scxml")


def test_an_unbounded_variable_stops_at_its_value_limit_before_the_state_limit() -> None:
    """``max_data_values`` (fsmbt.limits) ends an unbounded counter long before
    ``conversion_max_states`` would (the fuzzer found inputs that took 16 s to get there)."""
    body = """
  <datamodel><data id="n" expr="0"/></datamodel>
  <state id="s"><transition event="tick" target="s"><assign location="n" expr="n + 1"/>
    </transition><transition event="stop" cond="n == 3" target="end"/></state>
  <final id="end"/>"""
    with limits.changed(max_data_values=40):
        with pytest.raises(StateLimitError, match=r"'n' took more than 40 distinct values") as info:
            loads(doc(body), "scxml")
        assert "FSMBT_MAX_DATA_VALUES" in str(info.value)


def test_assign_of_an_expression_outside_the_subset_to_a_guard_variable_is_refused() -> None:
    body = """
  <datamodel><data id="n" expr="0"/></datamodel>
  <state id="s"><transition event="tick" target="s">
    <assign location="n" expr="Math.max(n, 1)"/></transition>
    <transition event="stop" cond="n == 1" target="s"/></state>"""
    with pytest.raises(UnsupportedError, match="outside fsmbt's subset") as info:
        loads(doc(body), "scxml")
    assert "line 4" in str(info.value) and "'n'" in str(info.value)


def test_an_operation_the_subset_does_not_model_is_refused_with_its_line() -> None:
    body = """
  <datamodel><data id="s" expr="'a'"/></datamodel>
  <state id="p"><transition event="go" target="p">
    <assign location="s" expr="s * 2"/></transition>
    <transition event="stop" cond="s == 'b'" target="p"/></state>"""
    with pytest.raises(UnsupportedError, match="line 4"):
        loads(doc(body), "scxml")


def test_internal_transition_keeps_the_data_an_external_one_exits_and_enters() -> None:
    body = """
  <datamodel><data id="x" expr="0"/></datamodel>
  <state id="a" initial="a1"><onentry><assign location="x" expr="x + 1"/></onentry>
    <onexit><assign location="x" expr="x + 1"/></onexit>
    <state id="a1"/><state id="a2"/>
    <transition event="in" type="internal" target="a2"/>
    <transition event="out" cond="x &lt; 4" target="a"/></state>"""
    model, _ = read(doc(body))
    assert walk(model, ["in", "out", "out", "out"]) == [
        "a/a1#x=1",  # entry: x + 1
        "a/a2#x=1",  # internal: 'a' is neither exited nor entered
        "a/a1#x=3",  # external: exit and entry, one each
        "a/a1#x=5",
        "a/a1#x=5",  # 5 < 4 is false: the transition is not taken
    ]


def test_commons_var_declares_and_assigns_in_jexl() -> None:
    body = """
  <state id="off"><transition event="on" target="on"/></state>
  <state id="on" xmlns:cs="http://commons.apache.org/scxml">
    <onentry><if cond="empty(limit)"><cs:var name="limit" expr="2"/></if>
      <cs:var name="n" expr="0"/></onentry>
    <transition cond="n ge limit" target="off"/>
    <transition event="tick"><assign location="n" expr="n + 1"/></transition></state>"""
    model, _ = read(doc(body, "jexl"))
    assert walk(model, ["on", "tick", "tick"]) == [
        "off#limit=null;n=null",
        "on#limit=2;n=0",
        "on#limit=2;n=1",
        "off#limit=2;n=2",
    ]


# -- <send eventexpr> ----------------------------------------------------------------------------
def test_eventexpr_of_literals_and_event_name_is_computed() -> None:
    body = """
  <state id="s"><transition event="go stop" target="t">
    <send eventexpr="'did.' + _event.name"/></transition></state>
  <state id="t"><transition event="did.go" target="u"/><transition event="did.stop" target="v"/>
  </state><state id="u"/><state id="v"/>"""
    model, _ = read(doc(body))
    assert walk(model, ["go"])[-1] == "u"
    assert walk(model, ["stop"])[-1] == "v"


def test_eventexpr_before_any_event_raises_error_execution() -> None:
    body = """
  <state id="s"><onentry><send eventexpr="'x.' + _event.name"/><raise event="after"/>
    </onentry><transition event="error.execution" target="failed"/>
    <transition event="after" target="ran"/></state>
  <state id="failed"/><state id="ran"/>"""
    model, _ = read(doc(body))
    assert walk(model, [])[0] == "failed"  # _event is unbound: error.execution, raise skipped


def test_eventexpr_no_descriptor_can_match_is_dropped_with_a_warning() -> None:
    body = """
  <state id="s"><transition event="go" target="s">
    <send eventexpr="'Out.' + _event.data.replace('a', '')"/></transition></state>"""
    model, warnings = read(doc(body))
    assert walk(model, ["go"]) == ["s", "s"]
    assert any("dropped: no event descriptor can match" in w and ":3:" in w for w in warnings)


@pytest.mark.parametrize(
    "descriptor", ["Out", "Out.x", "*", "error.execution", "error"], ids=lambda d: d
)
def test_eventexpr_a_descriptor_may_match_is_refused(descriptor: str) -> None:
    body = f"""
  <state id="s"><transition event="go" target="s">
    <send eventexpr="'Out.' + f(x)"/></transition>
    <transition event="{descriptor}" target="s"/></state>"""
    with pytest.raises(UnsupportedError, match="eventexpr") as info:
        loads(doc(body), "scxml")
    assert "line 3" in str(info.value)


def test_literal_prefix_and_descriptor_matching() -> None:
    assert literal_prefix('"a." + _event.name.replace(\'x\', "")') == "a."
    assert literal_prefix("'a' + b.c(1)[0] + 'd'") == "a"
    assert literal_prefix("'a' + b - c") is None  # ('a' + b) - c is a number
    assert literal_prefix("'a' + (b ? c : d)") is None
    assert literal_prefix("b + 'a'") is None
    assert may_match_prefix(["submit"], "submit.x") and may_match_prefix(["a.b.c"], "a.b")
    assert not may_match_prefix(["sub", "x.submit"], "submit.")


# -- <script> ------------------------------------------------------------------------------------
def test_script_that_cannot_affect_control_flow_is_ignored_with_its_line() -> None:
    body = """
  <state id="s"><onentry><send event="out"/>
    <script>anything(); at = all</script></onentry>
    <transition event="go" cond="In('s')" target="t"/></state>
  <state id="t"><transition event="back" target="s"/></state>"""
    model, warnings = read(doc(body))
    assert walk(model, ["go", "back"]) == ["s", "t", "s"]
    assert any("<script> ignored" in w and ":3:" in w for w in warnings)


@pytest.mark.parametrize(
    "extra, reason",
    [
        ('<transition event="go" cond="ready" target="t"/>', "reads the data model"),
        ('<transition event="error.execution" target="t"/>', "error.execution"),
        ('<transition event="*" target="t"/>', "error.execution"),
    ],
)
def test_script_that_may_matter_is_refused_with_its_line(extra: str, reason: str) -> None:
    body = f"""
  <state id="s"><onentry>
    <script>ready = true</script></onentry>
    {extra}</state><state id="t"/>"""
    with pytest.raises(UnsupportedError, match="<script>") as info:
        loads(doc(body), "scxml")
    assert reason in str(info.value) and "line 3" in str(info.value)


def test_script_whose_failure_would_skip_a_raise_is_refused() -> None:
    body = """
  <state id="s"><transition event="go">
    <script>may(fail)</script><raise event="next"/></transition>
    <transition event="next" target="t"/></state><state id="t"/>"""
    with pytest.raises(UnsupportedError, match="may fail") as info:
        loads(doc(body), "scxml")
    assert "line 3" in str(info.value)
    inert = body.replace('<transition event="next" target="t"/>', "")  # nothing takes 'next'
    assert walk(read(doc(inert))[0], ["go"]) == ["s", "s"]


# -- the expression subset and its dialects ------------------------------------------------------
@pytest.mark.parametrize(
    "dialect, text, value",
    [
        (ECMASCRIPT, "-7 % 3", -1),  # the dividend's sign
        (PYTHON, "-7 % 3", 2),  # the divisor's sign
        (JEXL, "-7 % 3", -1),
        (ECMASCRIPT, "7 / 2", 3.5),
        (ECMASCRIPT, "1 === 1.0", True),
        (ECMASCRIPT, "true === 1", False),
        (ECMASCRIPT, "true == 1", True),
        (ECMASCRIPT, "null == undefined", True),
        (ECMASCRIPT, "null === undefined", False),
        (ECMASCRIPT, "null == 0", False),
        (ECMASCRIPT, "'a' + 1 + 2", "a12"),
        (ECMASCRIPT, "1 + 2 + 'a'", "3a"),
        (ECMASCRIPT, "0 || 'x'", "x"),
        (ECMASCRIPT, "'b' > 'a' && 2 >= 2", True),
        (ECMASCRIPT, "'x' + u", "xundefined"),
        (JEXL, "empty(missing) and x ge 3", True),  # jexl: an undeclared name is null
        (JEXL, "6 / 3", 2),
        (PYTHON, "x == 3 and not False", True),
    ],
)
def test_dialects(dialect: object, text: str, value: object) -> None:
    data = {"x": 3, "u": UNDEFINED}
    got = evaluate(parse(text, dialect), data, lambda _s: False)  # type: ignore[arg-type]
    assert got == value and type(got) is type(value)


@pytest.mark.parametrize(
    "dialect, text, error",
    [
        (ECMASCRIPT, "'5' * 2", OutsideSubset),
        (ECMASCRIPT, "1 / 0", OutsideSubset),
        (ECMASCRIPT, "u + 1", OutsideSubset),
        (ECMASCRIPT, "'1' == 1", OutsideSubset),
        (ECMASCRIPT, "'a' < 1", OutsideSubset),
        (ECMASCRIPT, "9007199254740992 * 4", OutsideSubset),
        (PYTHON, "'a' + 1", OutsideSubset),
        (JEXL, "7 / 2", OutsideSubset),
        (ECMASCRIPT, "missing + 1", ExecutionError),
        (PYTHON, "missing", ExecutionError),
        (ECMASCRIPT, "_event.name", ExecutionError),
    ],
)
def test_values_the_subset_does_not_model_are_errors(
    dialect: object, text: str, error: type[Exception]
) -> None:
    with pytest.raises(error):
        evaluate(parse(text, dialect), {"u": UNDEFINED}, lambda _s: False)  # type: ignore[arg-type]


# -- the corpus files this reading opens ---------------------------------------------------------
OPENED = [
    "w3c_scxml_examples/microwave-01.scxml",
    "w3c_scxml_examples/microwave-02.scxml",
    "commons_scxml/microwave-01-jexl.scxml",
    "scion_tests/internal-transitions__test0.scxml",
    "scion_tests/targetless-transition__test0.scxml",
    "qt_scxml_examples/ftpclient.scxml",
    "scxml_tutorial/virtualSetup.scxml",
]


@pytest.mark.parametrize("name", OPENED)
def test_corpus_file_is_read_converted_and_verified(name: str) -> None:
    path = CORPUS / "fsm" / name
    if not path.exists():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    outcome = api.convert_file(path, to="btcpp")
    assert outcome.report is not None and outcome.report.equivalent


def test_microwave_cooks_until_the_timer_reaches_the_cook_time() -> None:
    path = CORPUS / "fsm" / "w3c_scxml_examples" / "microwave-01.scxml"
    if not path.exists():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    model = api.load(path).model
    seen = walk(model, ["turn.on", "time", "time", "time", "time", "time"])
    assert seen[1] == "on/cooking#door_closed=true;timer=0"
    assert seen[-1] == "off#door_closed=true;timer=5"  # timer >= cook_time (5): off
    assert walk(model, ["turn.on", "door.open", "time"])[-1] == "on/idle#door_closed=false;timer=0"


def test_assign_to_a_member_of_a_guard_variable_is_refused() -> None:
    body = """
  <datamodel><data id="x" expr="0"/></datamodel>
  <state id="s"><transition event="e" target="s"><assign location="x.y" expr="1"/>
    </transition><transition event="f" cond="x.y == 1" target="s"/></state>"""
    with pytest.raises(UnsupportedError, match="member location 'x.y'") as info:
        loads(doc(body), "scxml")
    assert "line 3" in str(info.value)


def test_send_data_reading_event_before_any_event_fails_and_skips_the_send() -> None:
    body = """
  <state id="s"><onentry><send event="go"><param name="p" expr="_event.data"/></send>
    </onentry><transition event="go" target="sent"/>
    <transition event="error.execution" target="failed"/></state>
  <state id="failed"/><state id="sent"><transition event="again" target="s2"/></state>
  <state id="s2"><onentry><send event="go"><param name="p" expr="_event.data"/></send>
    </onentry><transition event="go" target="sent"/></state>"""
    model, _ = read(doc(body))
    assert walk(model, [])[0] == "failed"  # W3C: _event is unbound, the send is not performed


def test_send_data_that_may_fail_before_an_event_that_matters_is_refused() -> None:
    body = """
  <state id="s"><transition event="e" target="s">
    <send event="go"><param name="p" expr="compute(1)"/></send></transition>
    <transition event="go" target="t"/></state><state id="t"/>"""
    with pytest.raises(UnsupportedError, match="<param>/<content> of <send>") as info:
        loads(doc(body), "scxml")
    assert "line 3" in str(info.value)
    unread = body.replace('<transition event="go" target="t"/>', "")  # nothing takes 'go'
    assert walk(read(doc(unread))[0], ["e"]) == ["s", "s"]


def test_an_inert_wildcard_transition_does_not_make_a_script_matter() -> None:
    body = """
  <state id="s"><onentry><script>log.everything()</script></onentry>
    <transition event="go" target="t"/>
    <transition event="*"><log expr="'seen'"/></transition></state><state id="t"/>"""
    model, warnings = read(doc(body))  # the '*' transition is targetless and has no effect
    assert walk(model, ["go"]) == ["s", "t"]
    assert any("<script> ignored" in w for w in warnings)
    live = body.replace("<log expr=\"'seen'\"/>", '<raise event="go"/>')
    with pytest.raises(UnsupportedError, match="error.execution"):
        loads(doc(live), "scxml")
