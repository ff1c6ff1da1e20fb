"""The lazy runner (``verify/lazy_fsm.py``) takes exactly the steps ``FSMLeafMachine`` takes on
the flattened machine (``model/flatten.py`` without data, the W3C reading of the machine as
SCXML with data: docs/semantics.md §6, §6a) - the machine a lifted counterexample is confirmed
on (docs/verification.md §3).

Differential: seeded random outcome walks *and* the native product of the two machines (every
reachable pair, which proves them equal on every input sequence) over (a) results written
whole (``bt_to_hfsm`` without per node) of the compositional test's random trees, (b) their
one-transition mutants (one per operator of ``verify/mutations.py`` in every machine, regions
included), (c) per-node results and their mutants (``support.pernode_mutants``) and (d) the
bench families, and (e) results holding a Parallel written as ``<parallel>`` (run as a block,
``verify/lazy_block.py``) with their mutants. The runner refuses a machine only when it has a
parallel state it cannot run as a block or when the flattening refuses it too, and never fails
in the middle of a run the flattening explores.
Then the rules the comparison found, one machine each, against the flattened machine.
"""

from __future__ import annotations

import random
import sys
from collections import Counter
from pathlib import Path

import pytest

from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.errors import FsmbtError, InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import ASSIGN, COND, DATAMODEL, ONEXIT
from fsmbt.semantics.machine import FINAL, LEAF_OUTCOMES, FSMLeafMachine
from fsmbt.verify.lazy_block import holds_parallel
from fsmbt.verify.lazy_fsm import LazyDataMachine, Unsupported
from fsmbt.verify.native import StateLimitError, check
from support.pernode_mutants import BOUND, mutate, seeded_mutants
from support.random_trees import random_tree
from support.whole_mutants import DECORATORS, deep_mutants, seeded_whole_mutants

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402


def _compare(model: FSM, rng: random.Random, walks: int = 8, steps: int = 30) -> str:
    """``"same"`` when the two machines agree on ``walks`` random walks and on their whole
    product (``"same walks, ..."``: the product passes ``BOUND`` states); ``"refused"`` when the runner refuses the machine (the assertions say when it
    may); ``"flattening refuses"`` when ``FSMLeafMachine`` cannot be built. Fails on any
    difference."""
    try:
        with limits.changed(conversion_max_states=BOUND):
            reference = FSMLeafMachine(model)
    except FsmbtError:
        reference = None
    try:
        lazy = LazyDataMachine(model)
    except Unsupported as exc:
        if reference is not None:  # only a parallel state is refused where it runs
            assert "parallel state" in str(exc), f"refused a machine it should run: {exc}"
        return "refused"
    if reference is None:
        return "flattening refuses"
    for _walk in range(walks):
        a, out_a = lazy.start()
        b, out_b = reference.start()
        assert out_a == out_b, "the start differs"
        done = []
        for _step in range(steps):
            if reference.status(b) == FINAL:
                break
            symbol = rng.choice(LEAF_OUTCOMES)
            done.append(symbol)
            a, out_a = lazy.step(a, symbol)
            b, out_b = reference.step(b, symbol)
            assert out_a == out_b, f"outputs differ after {done}: {out_a} vs {out_b}"
            assert lazy.status(a) == reference.status(b), f"status differs after {done}"
    try:
        report = check(reference, lazy, max_states=BOUND)
    except StateLimitError:  # the runner keeps every variable, the W3C reading the read ones
        return "same walks, product past the bound"
    failed = [p.detail for p in report.properties.values() if not p.holds]
    assert report.equivalent, f"the product tells them apart: {failed[:1]}"
    return "same"


def test_whole_written_results_and_their_mutants() -> None:
    """(a) and (b): results written whole and a mutant per operator of every machine."""
    tally: Counter[str] = Counter()
    rng = random.Random(41)
    for _doc, model, _mutants in seeded_whole_mutants(120, seed=27, per_tree=0):
        tally[_compare(model, rng)] += 1
        for mutant in deep_mutants(model, rng.randrange(1 << 30), 1, every_machine=True):
            tally[_compare(mutant, rng)] += 1
    print(f"\n[whole-written results and mutants] {dict(tally)}")
    assert tally["same"] >= 800
    assert tally["refused"] <= tally["same"] // 10


def test_per_node_results_their_mutants_and_the_bench_families() -> None:
    """(c) and (d): per-node results with the per-node sample's mutants and a mutant per
    operator of every machine; the bench families' trees, whole and per node, and mutants."""
    tally: Counter[str] = Counter()
    rng = random.Random(43)
    for _doc, model, mutants in seeded_mutants(40, seed=11, rng_seed=12, per_tree=3):
        for candidate in [model, *mutants]:
            tally[_compare(candidate, rng)] += 1
        for mutant in deep_mutants(model, rng.randrange(1 << 30), 1, every_machine=True)[:8]:
            tally[_compare(mutant, rng)] += 1
    for family in ("memory", "mixed", "reactive-plain"):
        for seed in range(2):
            doc = family_tree(family, 10, seed)
            for pernode in (False, True):
                model = bt_to_hfsm(doc, pernode=pernode).model
                candidates = [model, *deep_mutants(model, seed, 1, every_machine=True)[:8]]
                if pernode:
                    candidates.extend(m for m in (mutate(model, rng) for _ in range(3)) if m)
                for candidate in candidates:
                    tally[_compare(candidate, rng, walks=4, steps=40)] += 1
    print(f"\n[per-node results, mutants, bench families] {dict(tally)}")
    assert tally["same"] >= 300


#: Controls of (e): a Parallel or ParallelAll heading regions, with and without memory.
PARALLEL_CONTROLS = (
    "Sequence",
    "Fallback",
    "Parallel",
    "ParallelAll",
    "SequenceWithMemory",
    "ReactiveSequence",
)


def test_parallel_blocks_run_as_the_flattened_machine() -> None:
    """(e): a composite state holding a ``<parallel>`` is a block: its sub-machine flattened
    alone and stepped inside the run, the same steps as the whole machine flattened."""
    tally: Counter[str] = Counter()
    rng = random.Random(47)
    trees = 0
    while trees < 60:
        doc = random_tree(rng, controls=PARALLEL_CONTROLS, decorators=DECORATORS, max_nodes=14)
        try:
            model = bt_to_hfsm(doc).model
        except (InputError, UnsupportedError):
            continue
        if not any(holds_parallel(state) for _path, _machine, state in model.walk()):
            continue
        trees += 1
        tally[_compare(model, rng)] += 1
        for mutant in deep_mutants(model, rng.randrange(1 << 30), 1, every_machine=True)[:5]:
            tally[f"mutant {_compare(mutant, rng)}"] += 1
    print(f"\n[parallel blocks] {dict(tally)}")
    assert tally["same"] == trees  # every converted result runs, and runs the same
    assert tally["mutant same"] >= 150


# -- the rules, one machine each ---------------------------------------------------------------
def _region_machine(*, data: bool, final_sub: bool = True) -> FSM:
    """R (a region: a -success-> b -success-> SUCCESS; ``a`` marked final when ``final_sub``)
    completing on SUCCESS only; with ``data``, an (unused) data model."""
    region = FSM(name="compact_R")
    region.add_state(State("a", action="a", final=final_sub))
    region.add_state(State("b", action="b"))
    region.add_state(State("SUCCESS", action=None, final=True))
    region.add_transition("a", "success", "b")
    region.add_transition("b", "success", "SUCCESS")
    top = FSM(name="top")
    top.add_state(State("R", action=None, regions=[region]))
    top.add_state(State("SUCCESS", action="SUCCESS", final=True))
    top.add_transition("R", None, "SUCCESS", exit="SUCCESS")
    if data:
        top.attrs[DATAMODEL] = "x=0"
    return top


def _outputs(machine: object, symbols: list[str]) -> list[tuple[str, ...]]:
    state, out = machine.start()  # type: ignore[attr-defined]
    seen = [out]
    for symbol in symbols:
        state, out = machine.step(state, symbol)  # type: ignore[attr-defined]
        seen.append(out)
    return seen


@pytest.mark.parametrize("data", [False, True])
def test_a_final_sub_state_the_region_does_not_complete_on(data: bool) -> None:
    """The defect behind the lift's false counterexamples on regions written whole (a mutant
    that flips a leaf's final flag): such a state is entered and its action output (the runner
    output nothing). Without data it then handles no outcome (a final state is done); with
    data (the W3C reading of ``<final>`` with transitions) its transitions are taken."""
    model = _region_machine(data=data)
    reference = FSMLeafMachine(model)
    lazy = LazyDataMachine(model)
    symbols = ["success", "success", "running"]
    expected = _outputs(reference, symbols)
    assert _outputs(lazy, symbols) == expected
    assert expected[0] == ("a",)
    assert expected[1] == (("b",) if data else ("a",))
    assert check(reference, lazy).equivalent


def test_an_empty_action_is_an_output_without_data_and_none_with_it() -> None:
    for data in (False, True):
        model = _region_machine(data=data, final_sub=False)
        model.states["R"].regions[0].states["a"].action = ""
        reference, lazy = FSMLeafMachine(model), LazyDataMachine(model)
        assert _outputs(lazy, []) == _outputs(reference, []) == [() if data else ("",)]
        assert check(reference, lazy).equivalent


def test_nested_regions_run_as_flattened() -> None:
    """A composite state inside a region (a plain control over a region, written whole)."""
    model = _region_machine(data=False, final_sub=False)
    outer = FSM(name="compact_P")
    outer.add_state(State("R", action=None, regions=[model.states["R"].regions[0]]))
    outer.add_state(State("SUCCESS", action=None, final=True))
    outer.add_transition("R", None, "SUCCESS", exit="SUCCESS")
    model.states["R"].regions = [outer]
    reference, lazy = FSMLeafMachine(model), LazyDataMachine(model)
    assert _outputs(lazy, ["success", "success"]) == _outputs(reference, ["success", "success"])
    assert _outputs(reference, ["success", "success"])[-1] == ("SUCCESS",)
    assert check(reference, lazy).equivalent


def test_data_onexit_then_the_completion_s_assignments_then_guards() -> None:
    """With data, leaving R runs R's ``onexit`` before the completion's own assignments (the
    runner skipped them): here ``y = x + 1`` after ``x = 1`` picks the guarded arm of C."""
    model = _region_machine(data=True, final_sub=False)
    model.attrs[DATAMODEL] = "x=0\ny=0"
    model.states["R"].attrs[ONEXIT] = "x=1"
    model.transitions[0].attrs[ASSIGN] = "y=x + 1"
    model.transitions[0].target = "C"
    model.add_state(State("C", action="c"))
    model.add_state(State("FAILURE", action="FAILURE", final=True))
    model.add_transition("C", "success", "SUCCESS", attrs={COND: "y == 2"})
    model.add_transition("C", "success", "FAILURE")
    reference, lazy = FSMLeafMachine(model), LazyDataMachine(model)
    symbols = ["success", "success", "success"]
    assert _outputs(lazy, symbols) == _outputs(reference, symbols)
    assert _outputs(reference, symbols)[-1] == ("SUCCESS",)
    assert check(reference, lazy).equivalent


def test_out_of_scope_shapes_are_refused_by_name_never_run_differently() -> None:
    """A parallel state is refused naming it; a cycle of completions (the flattening refuses
    the machine) raises ``Unsupported`` when met, not a recursion error."""
    model = _region_machine(data=False)
    model.states["R"].regions.append(FSM(name="other", states={"z": State("z", action="z")}))
    with pytest.raises(Unsupported, match="parallel state"):
        LazyDataMachine(model)
    cycle = _region_machine(data=False, final_sub=False)
    region = cycle.states["R"].regions[0]
    region.initial = "SUCCESS"
    cycle.transitions[0].target = "R"  # R completes at once into R again
    with pytest.raises(FsmbtError):
        FSMLeafMachine(cycle)
    with pytest.raises(Unsupported, match="cycle"):
        LazyDataMachine(cycle).start()
