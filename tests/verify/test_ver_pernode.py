"""The per-node check (``verify/pernode.py``; issue 27 item 2) agrees with the whole product.

On every pair the whole product decides here - one-transition mutants of the per-node
sub-machines of seeded small trees (the bench families and every kind ``convert/bt_pernode``
writes; the 2 000 unmutated pairs are in tests/convert/test_conv_bt_pernode.py) (a retargeted transition, a dropped guard, a dropped or changed
assignment) - the per-node check never proves a pair the whole product finds different, and
it proves most of the equivalent ones on its own (the rest fall back to the whole product, as
the verdict says). A failure no run is lifted to, in a small region, has that region checked
whole (``compositional_report``), whose verdict must be the whole product's. Counts are printed (``pytest -s``).
"""

from __future__ import annotations

import copy
import random
import sys
from collections import Counter
from pathlib import Path

from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.fsm_data import ASSIGN, parse_lines
from fsmbt.verify import verify
from fsmbt.verify.compositional import compositional_report
from fsmbt.verify.report import PER_NODE
from support.pernode_mutants import BOUND, pernode_machine, seeded_mutants, whole
from support.pernode_trees import seeded_trees

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402


def test_per_node_agrees_with_the_whole_product_on_mutants() -> None:
    """The unmutated pairs are in tests/convert/test_conv_bt_pernode.py (2 000 trees)."""
    tally: Counter[str] = Counter()
    for doc, _model, mutants in seeded_mutants(300, seed=4, rng_seed=27):
        for candidate in mutants:
            verdict = whole(doc, candidate)
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, candidate, max_states=BOUND)
            proved = report is not None and report.method == PER_NODE
            tally["pairs"] += 1
            tally[f"whole {verdict}, per node {'proved' if proved else 'fell back'}"] += 1
            if proved:
                assert verdict is True, "the per-node check proved a pair that differs"
            if report is not None and report.stats.get("regions_checked_whole"):
                # a per-node failure no run was lifted to: its region checked whole decided
                tally[f"whole {verdict}, region checked whole: {report.equivalent}"] += 1
                assert report.equivalent is verdict
    print(f"\n[per-node vs whole product] {dict(tally)}")
    assert tally["pairs"] >= 450
    assert tally["whole True, per node proved"] >= 40  # harmless mutants proven per node
    assert tally["whole False, per node fell back"] >= 200  # mutants do differ
    # per-node failures with no run to them, proven by their small region's whole check
    assert tally["whole True, region checked whole: True"] >= 30


def test_verify_names_the_per_node_method_on_a_1000_node_tree() -> None:
    doc = family_tree("mixed", 700, 1000)
    model = bt_to_hfsm(doc).model
    report = verify(doc, model)
    assert report.equivalent
    assert report.method == PER_NODE
    assert report.stats["per_node_distinct"] < report.stats["per_node_nodes"]
    assert any("per node" in sentence for sentence in report.abstractions)


def test_a_region_without_its_halt_resets_is_not_proven_per_node() -> None:
    """Dropping every halt reset of a reactive node's chain: the decomposition refuses (a
    partial halt) or the local check fails; never a proof."""
    refused = 0
    for doc in seeded_trees(300, seed=8):
        model = bt_to_hfsm(doc, pernode=True).model
        sub = pernode_machine(model)
        if sub is None:
            continue
        chains = [
            t
            for t in sub.transitions
            if ".halt" in t.source and ASSIGN in t.attrs and len(parse_lines(t.attrs[ASSIGN])) > 1
        ]
        if not chains:
            continue
        mutant = copy.deepcopy(model)
        target = pernode_machine(mutant)
        assert target is not None
        for t in target.transitions:
            if ".halt" in t.source and ASSIGN in t.attrs:
                pairs = parse_lines(t.attrs[ASSIGN])
                t.attrs[ASSIGN] = "\n".join(f"{n}={e}" for n, e in pairs[1:])
        with limits.changed(conversion_max_states=BOUND):
            report, _why = compositional_report(doc, mutant, max_states=BOUND)
        assert report is None or report.method != PER_NODE or whole(doc, mutant)
        refused += report is None or report.method != PER_NODE
    assert refused >= 5


def test_lying_tags_never_give_a_wrong_proof() -> None:
    """The tags are hints: a state moved to another node's fragment (its tag rewritten to a
    random node of the region) and one transition retargeted must never be proven per node
    unless the whole product agrees."""
    from fsmbt.convert.bt_pernode import NODE_ATTR

    rng = random.Random(11)
    tally: Counter[str] = Counter()
    for doc in seeded_trees(160, seed=13):
        model = bt_to_hfsm(doc, pernode=True).model
        if pernode_machine(model) is None:
            continue
        mutant = copy.deepcopy(model)
        sub = pernode_machine(mutant)
        assert sub is not None
        tags = sorted({s.attrs[NODE_ATTR] for s in sub.states.values() if NODE_ATTR in s.attrs})
        tagged = [s for s in sub.states.values() if NODE_ATTR in s.attrs]
        rng.choice(tagged).attrs[NODE_ATTR] = rng.choice(tags)
        t = rng.choice(sub.transitions)
        t.target = rng.choice([s for s in sub.states if s != t.target])
        with limits.changed(conversion_max_states=BOUND):
            report, _why = compositional_report(doc, mutant, max_states=BOUND)
        proved = report is not None and report.method == PER_NODE
        tally["proved" if proved else "not proved"] += 1
        if proved:
            assert whole(doc, mutant) is True
    print(f"\n[lying tags] {dict(tally)}")
    assert sum(tally.values()) >= 100
