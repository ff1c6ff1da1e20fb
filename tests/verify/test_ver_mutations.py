"""The checker is not vacuous: single mutations of equivalent pairs (issue 3, item 6).

For every mutant: when an independent random simulation of both models finds a difference, the
checker must say "not equivalent"; whenever the checker says "not equivalent", every failing
property's counterexample must replay to a real difference; a mutant the checker calls
equivalent is never found different by simulation. Counts are printed (``pytest -s``).
"""

from __future__ import annotations

import copy
import random
from dataclasses import dataclass, field

import pytest

from fsmbt.verify import replay, verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.pairing import machines_for

# the families live in tests/support, shared with the NuSMV agreement test (tests/verify/nusmv)
from support.mutation_families import (
    bt_pairs,
    converted_bt_pairs,
    fsm_pairs,
    leaf_fsm_by_exploration,
    lebt_pairs,
    small_bt_and_leaf_fsm,
)
from support.ver_models import PAPER_EDGES, paper_fsm


# -- independent random simulation ----------------------------------------------------------------
def simulation_finds_difference(
    source_model, result_model, seed: int, runs: int = 150, length: int = 30
) -> bool:
    """Random input sequences (from the source's offered inputs, 80 % of the time among those
    the source reacts to) run step by step on fresh machines; any difference in outputs, status
    or offered inputs counts."""
    src, res, _mode = machines_for(source_model, result_model)
    follows = getattr(res, "follows_environment", False)
    rng = random.Random(seed)
    for _ in range(runs):
        s, o1 = src.start()
        r, o2 = res.start()
        if tuple(o1) != tuple(o2) or src.status(s) != res.status(r):
            return True
        for _ in range(length):
            offered = list(src.inputs(s))
            if not follows and set(offered) != set(res.inputs(r)):
                return True
            if not offered:
                break
            busy = [a for a in getattr(src, "active_inputs", lambda _x: ())(s) if a in offered]
            symbol = rng.choice(busy if busy and rng.random() < 0.8 else offered)
            s, o1 = src.step(s, symbol)
            r, o2 = res.step(r, symbol)
            if tuple(o1) != tuple(o2) or src.status(s) != res.status(r):
                return True
    return False


@dataclass
class Tally:
    generated: int = 0
    differ: int = 0  # the simulation found a difference
    caught: int = 0  # ... and the checker said "not equivalent"
    checker_only: int = 0  # checker: not equivalent, simulation found nothing (replay confirms)
    by_operator: dict[str, list[int]] = field(default_factory=dict)

    def line(self, family: str) -> str:
        return (
            f"{family}: {self.generated} mutants, {self.differ} differ by simulation, "
            f"{self.caught} caught, {self.checker_only} more found by the checker only"
        )


def judge(source_model, result_model, operator: str, tally: Tally, seed: int) -> None:
    report = verify(source_model, result_model)
    different = simulation_finds_difference(source_model, result_model, seed)
    tally.generated += 1
    counts = tally.by_operator.setdefault(operator, [0, 0])
    counts[0] += 1
    if not report.equivalent:
        counts[1] += 1
        src, res, _mode = machines_for(source_model, result_model)
        for prop in report.properties.values():
            if not prop.holds:
                inputs = [step.input for step in prop.counterexample[1:]]
                assert replay(src, res, inputs).differs, (operator, prop.name)
    if different:
        tally.differ += 1
        assert not report.equivalent, f"{operator}: simulation differs, checker says equivalent"
        tally.caught += 1
    elif not report.equivalent:
        tally.checker_only += 1


def run_family(pairs, mutate: str, family: str) -> Tally:
    """``mutate`` = "result" or "source": which side of each (equivalent) pair is mutated."""
    tally = Tally()
    for index, (source_model, result_model) in enumerate(pairs):
        assert verify(source_model, result_model).equivalent, (family, index)
        target = result_model if mutate == "result" else source_model
        for k, mutant in enumerate(mutants(target, seed=index, per_operator=4)):
            if mutate == "result":
                judge(source_model, mutant.model, mutant.operator, tally, seed=index * 1000 + k)
            else:
                judge(mutant.model, result_model, mutant.operator, tally, seed=index * 1000 + k)
    print("\n" + tally.line(family), {op: tuple(v) for op, v in sorted(tally.by_operator.items())})
    assert tally.differ > 0 and tally.caught == tally.differ
    return tally


# -- the families (tests/support/mutation_families.py) ----------------------------------------------
def test_fsm_vs_fsm_mutants_are_caught():
    tally = run_family(fsm_pairs(), "result", "FSM vs FSM")
    assert {"retarget_transition", "drop_transition", "change_action", "flip_final"} <= set(
        tally.by_operator
    )


def test_fsm_vs_lebt_mutants_are_caught():
    tally = run_family(lebt_pairs(), "result", "FSM vs LEBT")
    assert {
        "swap_children",
        "sequence_to_fallback",
        "invert_condition",
        "drop_leaf",
        "drop_guard_pair",
        "retarget_transition",
        "change_action",
        "flip_final",
    } <= set(tally.by_operator)


def test_lebt_active_inputs_are_sound_and_change_no_verdict():
    """Events left out by ``LEBTWithActiveInputs.active_inputs`` really are silent self-loops,
    and checking against the bare ``LEBTMachine`` (every event stepped) gives the same verdicts."""
    from fsmbt.semantics.lebt.machine import LEBTMachine
    from fsmbt.verify.native import check

    checked = 0
    for source, lebt in lebt_pairs()[:2]:
        for index, mutant in enumerate(mutants(lebt, seed=7, per_operator=3)):
            src, wrapped, _mode = machines_for(source, mutant.model)
            bare = LEBTMachine(mutant.model, wrapped.alphabet)
            assert check(src, wrapped).verdicts() == check(src, bare).verdicts(), mutant
            rng = random.Random(index)
            state, _ = wrapped.start()
            for _ in range(12):
                active = set(wrapped.active_inputs(state))
                for event in wrapped.alphabet:
                    if event not in active:
                        assert bare.step(state, event) == (state, ()), (mutant, event)
                        checked += 1
                state, _ = bare.step(state, rng.choice(wrapped.alphabet))
    assert checked > 0


def test_bt_source_mutants_are_caught():
    tally = run_family(bt_pairs(), "source", "mutated BT vs leaf FSM")
    assert {
        "swap_children",
        "sequence_to_fallback",
        "invert_condition",
        "drop_leaf",
        "change_action",
    } <= set(tally.by_operator)


def test_leaf_fsm_mutants_are_caught():
    tally = run_family(bt_pairs(), "result", "BT vs mutated leaf FSM")
    assert {"retarget_transition", "drop_transition", "change_action", "flip_final"} <= set(
        tally.by_operator
    )


def test_converted_hfsm_pairs_mutated_on_either_side_are_caught():
    run_family(converted_bt_pairs(), "source", "mutated BT vs converted HFSM")
    run_family(converted_bt_pairs(), "result", "BT vs mutated converted HFSM")


def test_the_hand_derived_leaf_fsm_matches_the_explored_one():
    doc, hand = small_bt_and_leaf_fsm()
    assert verify(doc, hand).equivalent
    assert verify(doc, leaf_fsm_by_exploration(doc)).equivalent
    assert verify(hand, leaf_fsm_by_exploration(doc)).equivalent  # state names are not observed


@pytest.mark.parametrize("operator", ["drop_transition", "retarget_transition"])
def test_a_known_mutant_is_reported_with_its_shortest_trace(operator):
    source = paper_fsm()
    result = copy.deepcopy(source)
    if operator == "drop_transition":
        del result.transitions[PAPER_EDGES.index("IJ")]
    else:
        result.transitions[PAPER_EDGES.index("IJ")].target = "A"
    report = verify(source, result)
    trace = report.properties["completeness"].counterexample
    assert [s.input for s in trace[1:]] == ["eventStartA", "eventAF", "eventFI", "eventIJ"]
