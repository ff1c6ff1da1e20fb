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

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.generate.generator import random_bt, random_fsm
from fsmbt.model import FSM, BTDocument, BTNode, NodeKind, State
from fsmbt.semantics.leaf_machine import LeafMachine
from fsmbt.semantics.random_trees import lebt_from_structure
from fsmbt.verify import replay, verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.pairing import machines_for

from ver_models import PAPER_EDGES, paper_fsm, renamed_copy  # noqa: E402 (sibling test module)

PAPER_STRUCTURE = [("A", [("B", []), ("F", [("I", [("J", [])])])]), ("C", []),
                   ("D", [("E", [("G", [("H", [])])])])]


def leaf(name: str, kind: NodeKind = NodeKind.ACTION) -> BTNode:
    return BTNode("Act" if kind is NodeKind.ACTION else "Check", kind, name=name)


def small_bt_and_leaf_fsm() -> tuple[BTDocument, FSM]:
    """Sequence(c1?, Fallback(a1, a2)) and its leaf FSM, derived by hand."""
    root = BTNode("Sequence", NodeKind.CONTROL, children=[
        leaf("c1", NodeKind.CONDITION),
        BTNode("Fallback", NodeKind.CONTROL, children=[leaf("a1"), leaf("a2")])])
    fsm = FSM(name="leaf_fsm")
    for name in ("c1", "a1", "a2"):
        fsm.add_state(name)
    fsm.add_state(State("S", action="SUCCESS", final=True))
    fsm.add_state(State("F", action="FAILURE", final=True))
    for a, e, b in [("c1", "success", "a1"), ("c1", "failure", "F"), ("a1", "success", "S"),
                    ("a1", "failure", "a2"), ("a1", "running", "a1"), ("a2", "success", "S"),
                    ("a2", "failure", "F"), ("a2", "running", "a2")]:
        fsm.add_transition(a, e, b)
    return BTDocument.single(root), fsm


def leaf_fsm_by_exploration(doc: BTDocument) -> FSM:
    """The BT's leaf-execution machine written out as an FSM (one state per machine state)."""
    machine = LeafMachine(doc)
    start, outputs = machine.start()
    names: dict[object, str] = {}
    fsm = FSM(name="explored")
    queue = [(start, outputs)]
    names[start] = "q0"
    fsm.add_state(State("q0", action=outputs[-1], final=machine.status(start) != "running"))
    while queue:
        state, _ = queue.pop(0)
        for symbol in machine.inputs(state):
            nxt, outs = machine.step(state, symbol)
            if nxt not in names:
                names[nxt] = f"q{len(names)}"
                fsm.add_state(State(names[nxt], action=outs[-1],
                                    final=machine.status(nxt) != "running"))
                queue.append((nxt, outs))
            fsm.add_transition(names[state], symbol, names[nxt])
    return fsm


# -- independent random simulation ----------------------------------------------------------------
def simulation_finds_difference(source_model, result_model, seed: int, runs: int = 150,
                                length: int = 30) -> bool:
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
        return (f"{family}: {self.generated} mutants, {self.differ} differ by simulation, "
                f"{self.caught} caught, {self.checker_only} more found by the checker only")


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


# -- the families ---------------------------------------------------------------------------------
def fsm_pairs() -> list[tuple[FSM, FSM]]:
    pairs = [(paper_fsm(), renamed_copy(paper_fsm()))]
    for seed in range(4):
        fsm = random_fsm(f"mut:{seed}", min_states=4, max_states=9)
        pairs.append((fsm, renamed_copy(fsm)))
    return pairs


def test_fsm_vs_fsm_mutants_are_caught():
    tally = run_family(fsm_pairs(), "result", "FSM vs FSM")
    assert {"retarget_transition", "drop_transition", "change_action", "flip_final"} <= set(
        tally.by_operator)


def lebt_pairs() -> list[tuple[FSM, BTDocument]]:
    pairs = [(paper_fsm(), lebt_from_structure(paper_fsm(), PAPER_STRUCTURE))]
    for seed in range(3):
        fsm = random_fsm(f"lebt:{seed}", min_states=4, max_states=8)
        pairs.append((fsm, fsm_to_lebt(fsm).model))
    return pairs


def test_fsm_vs_lebt_mutants_are_caught():
    tally = run_family(lebt_pairs(), "result", "FSM vs LEBT")
    assert {"swap_children", "sequence_to_fallback", "invert_condition", "drop_leaf",
            "drop_guard_pair", "retarget_transition", "change_action", "flip_final"} <= set(
        tally.by_operator)


def test_lebt_active_inputs_are_sound_and_change_no_verdict():
    """Events left out by ``LEBTWithActiveInputs.active_inputs`` really are silent self-loops,
    and checking against the bare ``LEBTMachine`` (every event stepped) gives the same verdicts."""
    from fsmbt.semantics.lebt_runtime import LEBTMachine
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


def bt_pairs() -> list[tuple[BTDocument, FSM]]:
    pairs = [small_bt_and_leaf_fsm()]
    for seed in range(4):
        doc = random_bt(f"mutbt:{seed}", depth=3, breadth=3, max_nodes=14)
        pairs.append((doc, leaf_fsm_by_exploration(doc)))
    return pairs


def test_bt_source_mutants_are_caught():
    tally = run_family(bt_pairs(), "source", "mutated BT vs leaf FSM")
    assert {"swap_children", "sequence_to_fallback", "invert_condition", "drop_leaf",
            "change_action"} <= set(tally.by_operator)


def test_leaf_fsm_mutants_are_caught():
    tally = run_family(bt_pairs(), "result", "BT vs mutated leaf FSM")
    assert {"retarget_transition", "drop_transition", "change_action", "flip_final"} <= set(
        tally.by_operator)


def converted_bt_pairs() -> list[tuple[BTDocument, FSM]]:
    pairs = []
    for seed in range(2):
        doc = random_bt(f"conv:{seed}", depth=4, breadth=3, max_nodes=16)
        pairs.append((doc, bt_to_hfsm(doc).model))
    return pairs


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
