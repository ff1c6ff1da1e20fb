"""SCXML documents read by running the W3C algorithm (fsmbt.formats.scxml.w3c): history, guarded
inputs, the internal and external queues, descriptors, refusals with lines, bounds. Expected
configurations are worked out by hand from the W3C SCXML 1.0 algorithm (appendix D); the
agreement with a W3C engine written by others is tests/runtime/test_rt_scxml_reader_oracle.py.
"""

from __future__ import annotations

import pytest

from fsmbt import api
from fsmbt.formats import dumps, loads
from fsmbt.formats.registry import ReadContext
from fsmbt.formats.scxml.structural import read_scxml
from fsmbt.formats.scxml.w3c import MAX_GUARDS_PER_EVENT, representative_event
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.semantics.machine import FINAL, FSMMachine
from fsmbt.verify.nusmv.binary import find_nusmv

NS = 'xmlns="http://www.w3.org/2005/07/scxml"'


def doc(body: str) -> str:
    return f'<scxml {NS} version="1.0">\n{body}\n</scxml>'


def walk(model: FSM, events: list[str]) -> list[str]:
    machine = FSMMachine(model)
    state, _ = machine.start()
    seen = [state]
    for event in events:
        state, _ = machine.step(state, event)
        seen.append(state)
    return seen


HISTORY = """
  <state id="a" initial="a1"><history id="h" type="{kind}"><transition target="a1"/></history>
    <state id="a1"><transition event="n" target="a2"/></state>
    <state id="a2" initial="x"><state id="x"><transition event="n" target="y"/></state>
      <state id="y"/></state>
    <transition event="out" target="b"/></state>
  <state id="b"><transition event="back" target="h"/></state>"""


@pytest.mark.parametrize("kind, restored", [("shallow", "a/a2/x"), ("deep", "a/a2/y")])
def test_history_restores_the_child_or_the_leaves(kind: str, restored: str) -> None:
    model = loads(doc(HISTORY.format(kind=kind)), "scxml")
    seen = walk(model, ["back", "n", "n", "out", "back"])
    assert seen[0] == "a/a1"  # no history recorded: the transition leaves b alone
    assert seen[1] == "a/a1"  # 'back' is not an event of a/a1
    assert seen[3] == "a/a2/y"
    assert seen[4].startswith("b#h=")
    assert seen[5].split("#")[0] == restored


def test_history_default_transition_before_anything_is_recorded() -> None:
    body = """
  <state id="b"><transition event="go" target="h"/></state>
  <state id="a" initial="a1"><history id="h"><transition target="a2"/></history>
    <state id="a1"/><state id="a2"/></state>"""
    assert walk(loads(doc(body), "scxml"), ["go"])[-1].split("#")[0] == "a/a2"


def test_internal_events_run_before_events_sent_to_the_external_queue() -> None:
    body = """
  <state id="s"><transition event="go" target="t"><send event="ext"/><raise event="int"/>
    </transition></state>
  <state id="t"><transition event="int" target="u"/><transition event="ext" target="w"/></state>
  <state id="u"><transition event="ext" target="v"/><transition event="int" target="w"/></state>
  <state id="v"/><state id="w"/>"""
    # go: s -> t; the macro step takes 'int' (t -> u); then the external 'ext' (u -> v)
    assert walk(loads(doc(body), "scxml"), ["go"]) == ["s", "v"]


def test_done_state_of_a_compound_is_raised_and_taken_in_the_macro_step() -> None:
    body = """
  <state id="c" initial="c1"><state id="c1"><transition event="n" target="cf"/></state>
    <final id="cf"/><transition event="done.state.c" target="end"/></state>
  <final id="end"/>"""
    model = loads(doc(body), "scxml")
    seen = walk(model, ["n"])
    assert seen == ["c/c1", "end"] and FSMMachine(model).status("end") == FINAL


def test_guarded_input_is_one_symbol_per_event_and_guard_values() -> None:
    body = """
  <state id="s"><transition event="e" cond="x &gt; 1" target="t"/>
    <transition event="e" target="u"/></state>
  <state id="t"><transition event="back" target="s"/></state>
  <state id="u"><transition event="back" cond="ready" target="s"/></state>"""
    warnings: list[str] = []
    model = read_scxml(doc(body), ReadContext(warnings=warnings))
    assert sorted(model.events()) == ["back[!g2]", "back[g2]", "e[!g1]", "e[g1]"]
    assert model.attrs["{https://fsmbt.dev/ns/scxml}guard.g1"] == "x > 1"
    assert any("g2 is an input of the environment: ready" in w for w in warnings)
    assert walk(model, ["e[g1]", "back[!g2]", "back[g2]"]) == ["s", "t", "s", "s"]
    assert walk(model, ["e[!g1]", "back[!g2]", "back[g2]"]) == ["s", "u", "u", "s"]


def test_fsm_to_bt_of_a_guarded_machine_verifies() -> None:
    body = """
  <state id="s"><transition event="e" cond="x &gt; 1" target="t"/>
    <transition event="e" target="u"><raise event="r"/></transition></state>
  <state id="t"><transition event="back" target="s"/></state>
  <state id="u"><transition event="r" cond="ok" target="t"/>
    <transition event="back" target="s"/></state>"""
    model = loads(doc(body), "scxml")
    result = api.convert_model(model, style="lebt")  # the LEBT: NuSMV checks it too
    assert api.verify_models(model, result.model, "native").equivalent
    if find_nusmv() is not None:
        assert api.verify_models(model, result.model, "nusmv").equivalent


def test_if_branches_are_guarded_and_an_effectless_if_is_dropped() -> None:
    body = """
  <state id="s"><transition event="go" target="t">
    <if cond="a"><raise event="yes"/><elseif cond="b"/><raise event="maybe"/><else/>
      <raise event="no"/></if>
    <if cond="c"><assign location="v" expr="1"/></if></transition></state>
  <state id="t"><transition event="yes" target="y"/><transition event="maybe" target="m"/>
    <transition event="no" target="n"/></state>
  <state id="y"/><state id="m"/><state id="n"/>"""
    warnings: list[str] = []
    model = read_scxml(doc(body), ReadContext(warnings=warnings))
    targets = {t.event: t.target for t in model.transitions if t.source == "s"}
    assert targets["go[g1,g2]"] == targets["go[g1,!g2]"] == "y"
    assert targets["go[!g1,g2]"] == "m" and targets["go[!g1,!g2]"] == "n"
    assert any("<if> ignored" in w for w in warnings)


def test_wildcard_and_prefix_descriptors() -> None:
    body = """
  <state id="s"><transition event="a.b" target="t"/><transition event="a.*" target="u"/>
    <transition event="*" target="w"/></state>
  <state id="t"/><state id="u"/><state id="w"/>"""
    model = loads(doc(body), "scxml")
    assert sorted(model.events()) == ["a", "a.b"]
    assert walk(model, ["a.b"])[-1] == "t" and walk(model, ["a"])[-1] == "u"
    assert representative_event("a.b.c", ["a", "a.b"]) == "a.b"
    assert representative_event("a.x", ["a", "a.b"]) == "a"
    assert representative_event("ab", ["a", "a.b"]) is None


def test_prefix_events_are_written_so_a_w3c_engine_reads_the_same_machine() -> None:
    """Transitions on ``a.b`` come before those on ``a`` in each state, so the writer may write
    both names and the file reads back equal (a W3C engine takes the first match)."""
    body = """
  <state id="s"><transition event="a.b" target="t"/><transition event="a" target="u"/></state>
  <state id="t"><transition event="a" target="s"/></state><state id="u"/>"""
    model = loads(doc(body), "scxml")
    again = loads(dumps(model, "scxml"), "scxml")
    assert again == model
    assert walk(model, ["a.b", "a.b", "a"]) == ["s", "t", "s", "u"]  # a.b in t: via 'a'
    first = loads(
        doc(
            body.replace(
                'event="a.b" target="t"/><transition event="a" target="u"',
                'event="a" target="u"/><transition event="a.b" target="t"',
            )
        ),
        "scxml",
    )
    assert walk(first, ["a.b"]) == ["s", "u"]  # W3C: the first match in document order


def test_hierarchical_prefix_events_are_still_refused_by_the_writer() -> None:
    inner = FSM(name="c")
    inner.add_state("x")
    inner.add_transition("x", "a", "x")
    top = FSM()
    top.add_state(State("c", regions=[inner]))
    top.add_state("y")
    top.add_transition("c", "a.b", "y")
    with pytest.raises(UnsupportedError, match="prefix matching"):
        dumps(top, "scxml")


def test_targetless_transition_runs_its_content_and_stays() -> None:
    body = """
  <state id="c" initial="c1"><state id="c1"><transition event="n" target="c2"/></state>
    <state id="c2"/><transition event="poke"><raise event="n"/></transition></state>"""
    assert walk(loads(doc(body), "scxml"), ["poke"]) == ["c/c1", "c/c2"]


@pytest.mark.parametrize(
    "body, message",
    [
        (
            '<state id="s"><onentry><raise event="x"/></onentry><transition event="x" target="s"/>'
            "</state>",
            "macro step does not end",
        ),
        (
            '<state id="s"><transition target="t"/><transition event="*" target="s"/></state>'
            '<state id="t"><transition target="s"/></state>',
            "macro step does not end",
        ),
    ],
)
def test_cycles_within_a_macro_step_are_errors_not_hangs(body: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        loads(doc(body), "scxml")


def test_guard_read_before_the_first_event_is_refused() -> None:
    with pytest.raises(UnsupportedError, match="before the first event"):
        loads(
            doc('<state id="s"><transition cond="x" target="t"/></state><state id="t"/>'), "scxml"
        )


def test_too_many_guards_on_one_event_are_refused() -> None:
    transitions = "".join(
        f'<transition event="e" cond="v{i}" target="s"/>' for i in range(MAX_GUARDS_PER_EVENT + 1)
    )
    with pytest.raises(UnsupportedError, match="guards read on event 'e'"):
        loads(doc(f'<state id="s">{transitions}</state>'), "scxml")


def test_assign_to_an_unread_variable_is_warned_and_one_read_by_a_guard_refused() -> None:
    warnings: list[str] = []
    read_scxml(
        doc(
            '<state id="s"><transition event="e" cond="x" target="s">'
            '<assign location="y" expr="1"/></transition></state>'
        ),
        ReadContext(warnings=warnings),
    )
    assert any("<assign> to 'y' ignored" in w for w in warnings)
    with pytest.raises(UnsupportedError, match="line 3") as info:
        loads(
            doc(
                '<state id="s"><transition event="e" cond="x" target="s">\n'
                '<assign location="x" expr="1"/></transition></state>'
            ),
            "scxml",
        )
    assert "which a guard reads" in str(info.value)


TIMER = """
  <state id="s"><onentry><send event="tick" delay="1s"/></onentry>
    <transition event="tick" target="t"/></state>
  <state id="t"><onentry><cancel sendid="x"/></onentry><transition event="back" target="s"/>
  </state>"""


def test_delayed_send_is_refused_naming_the_abstraction_option() -> None:
    with pytest.raises(UnsupportedError, match="abstract=time") as info:
        loads(doc(TIMER), "scxml")
    assert "line 3" in str(info.value)


def test_delayed_send_under_the_time_abstraction_is_an_environment_input() -> None:
    warnings: list[str] = []
    model = read_scxml(doc(TIMER), ReadContext(options={"abstract": "time"}, warnings=warnings))
    assert any("verified under the abstraction 'time'" in w and "tick" in w for w in warnings)
    assert any("<cancel> ignored" in w for w in warnings)
    assert walk(model, ["tick", "back"]) == ["s", "t", "s"]  # the timer fires when it likes
    result = api.convert_model(model)
    assert api.verify_models(model, result.model, "native").equivalent


COUNTER = """
  <datamodel><data id="n" expr="0"/></datamodel>
  <state id="s"><transition event="tick" cond="n &lt; 2" target="s">
    <assign location="n" expr="n + 1"/></transition>
    <transition event="tick" target="done"/></state>
  <final id="done"/>"""


def test_data_is_read_exactly_by_default_and_guards_are_computed() -> None:
    model = loads(doc(COUNTER), "scxml")
    assert walk(model, ["tick", "tick", "tick"]) == ["s#n=0", "s#n=1", "s#n=2", "done#n=2"]
    assert sorted(model.events()) == ["tick"]  # no guard is an input any more
    constant = doc(COUNTER.replace('<assign location="n" expr="n + 1"/>', ""))
    assert walk(loads(constant, "scxml"), ["tick", "tick"]) == ["s", "s", "s"]  # n constant
    guarded = read_scxml(constant, ReadContext(options={"data": "inputs"}))
    assert sorted(guarded.events()) == ["tick[!g1]", "tick[g1]"]  # the old reading, opt-in


@pytest.mark.parametrize(
    "text, value",
    [
        ("1 + 2 * 3", 7),
        ("(1 + 2) * 3", 9),
        ("!true || false", False),
        ("x ge 2 and x lt 5", True),
        ("'a' + 1", "a1"),
        ("x === 3", True),
        ("x === '3'", False),
        ("-x + 1", -2),
        ("empty(y)", True),
        ("In('s')", True),
    ],
)
def test_expression_language(text: str, value: object) -> None:
    from fsmbt.formats.scxml.expr import evaluate, parse

    assert evaluate(parse(text), {"x": 3, "y": ""}, lambda state: state == "s") == value


@pytest.mark.parametrize("text", ["a.b", "f(1, 2)", "1 +", "(1", "1)", "_event.data"])
def test_expressions_outside_the_language_do_not_parse(text: str) -> None:
    from fsmbt.formats.scxml.expr import ExpressionError, parse

    with pytest.raises(ExpressionError):
        parse(text)


#: Also run by python-statemachine in tests/runtime/test_rt_scxml_reader_oracle.py.
INVALID_TARGET = """
  <state id="s"><transition event="go" target="t"/></state>
  <state id="t">
    <onentry><send target="_internal" event="sent"/><raise event="after"/></onentry>
    <transition event="sent" target="got_it"/><transition event="after" target="went_on"/>
    <transition event="error.execution" target="failed"/></state>
  <state id="got_it"/><state id="went_on"/><state id="failed"/>"""


def test_an_invalid_send_target_raises_error_execution_and_ends_its_block() -> None:
    """W3C 6.2.4: a target that is neither special (``#_...``) nor a URI places
    error.execution on the internal queue; the send sends nothing and the rest of the
    ``<onentry>`` is skipped (so neither 'sent' nor 'after' happens)."""
    ctx = ReadContext()
    model = read_scxml(doc(INVALID_TARGET), ctx)
    assert walk(model, ["go"]) == ["s", "failed"]
    assert any("not a valid target" in w for w in ctx.warnings)


@pytest.mark.parametrize(
    "body, named",
    [
        (  # an initial that names an ancestor (the fuzzer's hang: entry re-entered it forever)
            '<state id="b" initial="h"><history id="h" type="deep"><transition target="b1"/>'
            '</history><state id="b1" initial="b"><state id="x"/></state>'
            '<transition event="go" target="b"/></state>',
            "state 'b1': its initial 'b'",
        ),
        (  # a history whose default transition leaves its parent
            '<state id="a"><transition event="go" target="h"/></state>'
            '<state id="p" initial="p1"><history id="h"><transition target="a"/></history>'
            '<state id="p1"/></state>',
            "history 'h': its default transition target 'a'",
        ),
    ],
)
def test_default_targets_outside_their_state_are_errors_not_hangs(body: str, named: str) -> None:
    with pytest.raises(InputError, match=named) as info:
        loads(doc(body), "scxml")
    assert "not a descendant" in str(info.value) and info.value.location is not None
