"""The native checker on FSM pairs and hand-written machines: verdicts, per-property
counterexamples that replay to real differences, and shortest counterexamples (checked against a
brute-force search over input sequences)."""

from __future__ import annotations

import copy
import itertools
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fsmbt.model import FSM, InputError, State, flatten
from fsmbt.semantics.machine import FINAL, RUNNING
from fsmbt.verify import replay
from fsmbt.verify.native import check
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import (
    COMPLETENESS,
    DEADLOCK_ABSENCE,
    NO_ADDITIONAL_BEHAVIOR,
    PROPERTIES,
    REACHABILITY,
    TERMINATION_CONSISTENCY,
)
from support.ver_models import PAPER_EDGES, paper_fsm


def pair(source: FSM, result: FSM):
    src, res, _mode = machines_for(source, result)
    return src, res


def assert_counterexamples_real(source, result, report) -> None:
    for name, prop in report.properties.items():
        if not prop.holds:
            assert prop.counterexample, name
            inputs = [s.input for s in prop.counterexample[1:]]
            assert replay(source, result, inputs).differs, name


# -- verdicts -------------------------------------------------------------------------------------
def test_identical_copies_are_equivalent_and_replay_agrees():
    src, res = pair(paper_fsm(), paper_fsm())
    report = check(src, res)
    assert report.equivalent
    assert set(report.properties) == set(PROPERTIES)
    assert report.stats["product_states"] == report.stats["source_states"] == 11
    assert not replay(src, res, ["eventStartA", "eventAB", "eventBD", "eventDE"]).differs


def test_renamed_and_reordered_copy_is_equivalent():
    source = paper_fsm()
    result = FSM(name="renamed")
    for name in reversed("ABCDEFGHIJ"):  # other order, other names, same actions
        result.add_state(State(f"s_{name}", action=name, final=name in "HJ"))
    result.start_name, result.initial_event, result.initial = "Init", "eventStartA", "s_A"
    for a, b in reversed(PAPER_EDGES):
        result.add_transition(f"s_{a}", f"event{a}{b}", f"s_{b}")
    assert check(*pair(source, result)).equivalent


def test_hierarchical_fsm_equals_its_flattening():
    inner = FSM(name="inner")
    inner.add_state("x")
    inner.add_state("y", final=True)
    inner.add_transition("x", "go", "y")
    outer = FSM(name="outer")
    outer.add_state(State("C", action=None, regions=[inner]))
    outer.add_state("D", final=True)
    outer.add_transition("C", None, "D")
    outer.add_transition("C", "abort", "D")
    assert check(*pair(outer, flatten(outer))).equivalent


def test_retargeted_transition_fails_with_a_shortest_real_counterexample():
    source, result = paper_fsm(), paper_fsm()
    result.transitions[PAPER_EDGES.index("BC")].target = "D"
    src, res = pair(source, result)
    report = check(src, res)
    assert not report.equivalent
    completeness = report.properties[COMPLETENESS]
    assert not completeness.holds
    assert [s.input for s in completeness.counterexample[1:]] == [
        "eventStartA",
        "eventAB",
        "eventBC",
    ]
    assert completeness.counterexample[-1].source_outputs == ["C"]
    assert completeness.counterexample[-1].result_outputs == ["D"]
    assert_counterexamples_real(src, res, report)


def test_dropped_transition_is_incomplete_but_adds_nothing():
    source, result = paper_fsm(), paper_fsm()
    del result.transitions[PAPER_EDGES.index("AF")]
    src, res = pair(source, result)
    report = check(src, res)
    verdicts = report.verdicts()
    assert not verdicts[COMPLETENESS]
    assert verdicts[NO_ADDITIONAL_BEHAVIOR]
    assert not verdicts[REACHABILITY]  # F, I, J are never reached with matching behaviour
    assert "F" in report.properties[REACHABILITY].detail
    assert_counterexamples_real(src, res, report)


def test_extra_transition_is_additional_behaviour_only():
    source, result = paper_fsm(), paper_fsm()
    result.add_transition("B", "eventBJ", "J")
    src, res = pair(source, result)
    report = check(src, res)
    verdicts = report.verdicts()
    assert not verdicts[NO_ADDITIONAL_BEHAVIOR]
    assert verdicts[COMPLETENESS]
    assert not verdicts[TERMINATION_CONSISTENCY]  # J is final
    assert_counterexamples_real(src, res, report)


def test_flipped_final_flag_is_a_termination_difference():
    source, result = paper_fsm(), paper_fsm()
    result.states["E"].final = True
    src, res = pair(source, result)
    report = check(src, res)
    assert not report.properties[TERMINATION_CONSISTENCY].holds
    trace = report.properties[TERMINATION_CONSISTENCY].counterexample
    assert trace[-1].source_status == RUNNING and trace[-1].result_status == FINAL
    assert_counterexamples_real(src, res, report)


def test_non_final_sink_in_result_is_a_deadlock():
    source, result = paper_fsm(), paper_fsm()
    result.transitions = [t for t in result.transitions if t.source != "G"]  # G never reaches H
    src, res = pair(source, result)
    report = check(src, res)
    deadlock = report.properties[DEADLOCK_ABSENCE]
    assert not deadlock.holds
    assert deadlock.counterexample[-1].input == "eventGH"  # extended to the source's next act
    assert_counterexamples_real(src, res, report)


def test_deadlock_shared_by_both_sides_is_not_a_failure():
    source = paper_fsm()
    source.transitions = [t for t in source.transitions if t.source != "G"]
    assert check(*pair(source, copy.deepcopy(source))).equivalent


def test_changed_action_label_is_caught_at_the_start():
    source = FSM(name="s")
    source.add_state("a")
    source.add_state("b", final=True)
    source.add_transition("a", "e", "b")
    result = copy.deepcopy(source)
    result.states["a"].action = "other"
    src, res = pair(source, result)
    report = check(src, res)
    trace = report.properties[COMPLETENESS].counterexample
    assert len(trace) == 1 and trace[0].input is None
    assert_counterexamples_real(src, res, report)


# -- hand-written machines ------------------------------------------------------------------------
class Counter:
    """A machine with state 0..limit-1 (or unbounded); input 'inc' outputs the new value."""

    def __init__(self, name, limit=None, offered=("inc",), stuck_at=None, final_at=None):
        self.name, self.limit, self.offered = name, limit, offered
        self.stuck_at, self.final_at = stuck_at, final_at

    def start(self):
        return 0, ()

    def inputs(self, state):
        return self.offered

    def step(self, state, symbol):
        if symbol != "inc" or state == self.stuck_at or state == self.final_at:
            return state, ()
        nxt = state + 1 if self.limit is None else (state + 1) % self.limit
        return nxt, (str(nxt),)

    def status(self, state):
        return FINAL if state == self.final_at else RUNNING

    def describe(self, state):
        return f"n={state}"


def test_counter_pairs():
    assert check(Counter("a", 6), Counter("b", 6)).equivalent
    report = check(Counter("a", 6), Counter("b", 3))
    assert report.properties[COMPLETENESS].counterexample[-1].input == "inc"
    assert len(report.properties[COMPLETENESS].counterexample) == 4  # start + 3 incs: 3 vs 0


def test_result_refusing_an_input_is_incomplete_and_extra_input_is_additional():
    report = check(Counter("a", 4, offered=("inc", "nop")), Counter("b", 4))
    assert not report.properties[COMPLETENESS].holds
    assert report.properties[NO_ADDITIONAL_BEHAVIOR].holds
    assert "does not accept input 'nop'" in report.properties[COMPLETENESS].detail
    report = check(Counter("a", 4), Counter("b", 4, offered=("inc", "nop")))
    assert not report.properties[NO_ADDITIONAL_BEHAVIOR].holds
    assert report.properties[COMPLETENESS].holds


def test_stuck_result_is_a_deadlock_with_a_real_counterexample():
    source, result = Counter("a", 5), Counter("b", 5, stuck_at=2)
    report = check(source, result)
    assert not report.properties[DEADLOCK_ABSENCE].holds
    inputs = [s.input for s in report.properties[DEADLOCK_ABSENCE].counterexample[1:]]
    assert inputs == ["inc", "inc", "inc"]
    assert replay(source, result, inputs).differs


def test_state_space_limit_is_a_clear_error():
    with pytest.raises(InputError, match="more than 50 reachable states"):
        check(Counter("a"), Counter("b"), max_states=50)


# -- shortest counterexamples against brute force -------------------------------------------------
def random_fsm(rng: random.Random, n: int, events: list[str], name: str) -> FSM:
    fsm = FSM(name=name)
    actions = ["p", "q", "r"]
    for i in range(n):
        fsm.add_state(State(f"s{i}", action=rng.choice(actions), final=rng.random() < 0.2))
    for i in range(n):
        for event in events:
            if rng.random() < 0.5:
                fsm.add_transition(f"s{i}", event, f"s{rng.randrange(n)}")
    return fsm


def shortest_difference(src, res, alphabet, bound):
    for length in range(bound + 1):
        for inputs in itertools.product(alphabet, repeat=length):
            if replay(src, res, list(inputs)).differs:
                return length
    return None


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.integers(0, 10**9), st.integers(2, 4), st.integers(2, 4))
def test_verdict_and_shortest_counterexample_match_brute_force(seed, n1, n2):
    rng = random.Random(seed)
    events = ["a", "b"]
    source = random_fsm(rng, n1, events, "src")
    result = random_fsm(rng, n2, events, "res") if rng.random() < 0.6 else copy.deepcopy(source)
    src, res = pair(source, result)
    report = check(src, res)
    bound = 7
    alphabet = list(src.alphabet)
    brute = shortest_difference(src, res, alphabet, bound)
    trace_lengths = [
        len(p.counterexample) - 1
        for p in report.properties.values()
        if not p.holds and p.name in (COMPLETENESS, NO_ADDITIONAL_BEHAVIOR, TERMINATION_CONSISTENCY)
    ]
    if report.equivalent:
        assert brute is None
        rng2 = random.Random(seed + 1)
        for _ in range(30 if alphabet else 0):
            assert not replay(src, res, rng2.choices(alphabet, k=12)).differs
    else:
        assert_counterexamples_real(src, res, report)
        # n1*n2 <= 16 product states: a difference, if any, is within 16 steps
        shortest = min(trace_lengths)
        if shortest <= bound:
            assert brute == shortest
        else:
            assert brute is None
