"""Lifted counterexamples (``verify/lift.py``, ``verify/lazy_fsm.py``; issue 27): a mutant the
per-node check refutes at one node, or whose region checked whole fails (written per node or
whole), is reported NOT EQUIVALENT with leaf outcomes from the root that the two whole machines
replay differently; never on a pair the whole product proves. (The lazy runner itself is tested
against the flattened machine in ``test_ver_lazy_fsm.py``.)
"""

from __future__ import annotations

import random
import sys
from collections import Counter
from pathlib import Path

from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.semantics.execution import leaf_machine
from fsmbt.verify import verify
from fsmbt.verify.compositional import compositional_report
from fsmbt.verify.lazy_fsm import LazyDataMachine
from fsmbt.verify.native import replay
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import COMPOSITIONAL_LIFTED, LIFTED, PER_NODE_LIFTED
from support.pernode_mutants import BOUND, mutate, seeded_mutants, whole_shortest
from support.whole_mutants import seeded_whole_mutants

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402


def _lifted_trace(report):  # type: ignore[no-untyped-def]
    traces = [p.counterexample for p in report.properties.values() if p.counterexample]
    assert traces
    return traces[0]


def _lifted_tally(pairs):  # type: ignore[no-untyped-def]
    """For each (tree, mutant): never lifted where the whole product proves the pair; where
    it refutes it, a lifted counterexample replays to a difference of the two whole machines
    - the result run lazily, as the lift confirms it, and flattened, as the whole product
    runs it - and has exactly the whole product's shortest length. The methods, counted."""
    tally: Counter[str] = Counter()
    for doc, mutant in pairs:
        best = whole_shortest(doc, mutant)
        with limits.changed(conversion_max_states=BOUND):
            report, _why = compositional_report(doc, mutant, max_states=BOUND)
        lifted = report is not None and report.method in LIFTED
        if best == -1:  # the whole product proves it: never a lifted refutation
            assert not lifted, "a lifted counterexample on a pair the whole product proves"
        if best is None or best == -1:  # undecided past BOUND, or proven
            continue
        if not lifted:
            tally["refuted, not lifted"] += 1
            continue
        assert report is not None and not report.equivalent
        tally[report.method] += 1
        trace = _lifted_trace(report)
        inputs = [step.input for step in trace[1:]]
        assert replay(leaf_machine(doc), LazyDataMachine(mutant), inputs).differs
        with limits.changed(conversion_max_states=BOUND):
            source, result, _mode = machines_for(doc, mutant)
        assert replay(source, result, inputs).differs
        assert len(trace) - 1 == best, f"lifted {len(trace) - 1}, shortest {best}"
    return tally


def test_lifted_counterexamples_are_real_and_as_short_as_the_whole_products() -> None:
    """On the seeded small mutants every lifted counterexample - a failing node's local one
    (``per node, lifted``) or a failing region's own (``compositional, lifted``) - is on a pair
    the whole product refutes, replays to a difference of the two machines, and has exactly as
    many leaf outcomes as the whole product's shortest counterexample (``_lifted_tally``); a
    pair the whole product proves is never lifted. Two samples: per-node results (the lift
    refutes at least 70 of the mutants; 49 before regions checked whole were lifted) and
    results written whole (every region checked whole: at least 65 lifted, none before the
    lazy runner was mended; docs/verification.md §3)."""
    pernode = [
        (doc, mutant)
        for doc, _model, mutants in seeded_mutants(60, seed=4, rng_seed=5)
        for mutant in mutants
    ]
    tally = _lifted_tally(pernode)
    print(f"\n[lifted = shortest, per node] {dict(tally)}")
    assert tally[PER_NODE_LIFTED] + tally[COMPOSITIONAL_LIFTED] >= 70
    assert tally[COMPOSITIONAL_LIFTED] >= 10
    whole = [
        (doc, mutant)
        for doc, _model, mutants in seeded_whole_mutants(150, seed=8)
        for mutant in mutants
    ]
    tally = _lifted_tally(whole)
    print(f"\n[lifted = shortest, written whole] {dict(tally)}")
    assert tally[COMPOSITIONAL_LIFTED] >= 65
    assert tally[PER_NODE_LIFTED] == 0  # nothing is written per node there


def test_mutants_of_a_few_hundred_nodes_are_refuted_with_a_lifted_counterexample() -> None:
    rng = random.Random(27)
    lifted = 0
    tried = 0
    for seed in range(300, 306):
        doc = family_tree("mixed", 150, seed)
        model = bt_to_hfsm(doc, pernode=True).model
        for _ in range(6):
            mutant = mutate(model, rng)
            assert mutant is not None
            tried += 1
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, mutant, max_states=BOUND)
            if report is None or report.method not in LIFTED:
                continue
            assert not report.equivalent
            trace = _lifted_trace(report)
            inputs = [step.input for step in trace[1:]]
            replayed = replay(leaf_machine(doc), LazyDataMachine(mutant), inputs)
            assert replayed.differs
            assert "does not accept" not in replayed.differences[0]
            assert trace[-1].note  # the last step shown is where they differ
            if lifted == 0:  # ``verify`` gives this verdict, its method named
                assert verify(doc, mutant).method == report.method
            lifted += 1
    print(f"\n[a few hundred nodes] {lifted} of {tried} lifted")
    assert lifted >= 3  # of the local failures here (docs/verification.md §7: not all lift)
