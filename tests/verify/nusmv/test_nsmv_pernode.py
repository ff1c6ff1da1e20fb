"""NuSMV node by node (``verify/nusmv/pernode.py``, ``encode_local.py``; docs/nusmv.md, "Trees
node by node"; issue 27 item 2).

- On seeded small trees converted per node and one-transition mutants of their per-node
  sub-machines (tests/support/pernode_trees.py, pernode_mutants.py), NuSMV's verdict on every
  distinct local check is the native per-node check's verdict (unit by unit, so also the
  failing unit of a mutant), with the few units NuSMV does not encode counted apart;
- where NuSMV proves a small pair node by node, its whole-tree encoding finds the pair
  equivalent too (and it finds most of the unmutated ones so);
- σ comes from the native walk but is not trusted: a swapped σ makes the unit fail;
- ``verify(engine="both"/"nusmv")`` on a large tree names the method and counts the units; on
  a mutant the failing unit is named with its counterexample. Counts are printed (``-s``).
"""

from __future__ import annotations

import random
import sys
from collections import Counter
from pathlib import Path

from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.verify import verify
from fsmbt.verify.compositional import CheckPlan, compositional_report
from fsmbt.verify.nusmv import check as whole_check
from fsmbt.verify.nusmv.pernode import check_plan, check_units
from fsmbt.verify.report import PER_NODE, PER_NODE_LIFTED, SYMBOLIC_PER_NODE
from support.pernode_mutants import BOUND, mutate, pernode_machine, seeded_mutants
from support.pernode_trees import seeded_trees
from support.pernode_units import units_agree

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
from bench_reactive import family_tree, leaves_for  # noqa: E402


def _plan(doc, model) -> CheckPlan:  # type: ignore[no-untyped-def]
    plan = CheckPlan()
    with limits.changed(conversion_max_states=BOUND):
        compositional_report(doc, model, max_states=BOUND, plan=plan)
    return plan


def test_nusmv_decides_every_local_check_as_the_native_walk(nusmv_binary) -> None:
    tally: Counter[str] = Counter()
    for doc, model, mutants in seeded_mutants(44, seed=4, rng_seed=27):
        for candidate in [model, *mutants]:
            plan = _plan(doc, candidate)
            if not plan.units:
                tally["not per node"] += 1
                continue
            units, checked, refused = units_agree(plan)
            tally["units agree"] += len(checked)
            tally["units failing (both)"] += sum(not unit.held for unit in checked)
            tally["units refused by NuSMV"] += len(refused)
            tally["pairs"] += 1
            tally["pairs with a failing unit"] += not all(u.held for u in units)
    print(f"\n[NuSMV per node vs native per node] {dict(tally)}")
    assert tally["pairs"] >= 80
    assert tally["units agree"] >= 250
    assert tally["units failing (both)"] >= 40  # the mutants do fail, in both engines
    assert tally["units refused by NuSMV"] <= tally["units agree"] // 50


def test_a_proof_node_by_node_is_confirmed_by_the_whole_encoding(nusmv_binary) -> None:
    """Small trees (at most 6 leaves) and one mutant each: NuSMV's per-node proof (every unit
    and the skeleton) implies NuSMV's whole-tree verdict ``equivalent``."""
    rng = random.Random(3)
    tally: Counter[str] = Counter()
    for doc in seeded_trees(40, seed=9):
        if len(doc.main.root.children) > 3 or _leaves(doc) > 6:
            continue
        model = bt_to_hfsm(doc, pernode=True).model
        if pernode_machine(model) is None:
            continue
        for candidate in [model, mutate(model, rng)]:
            assert candidate is not None
            plan = _plan(doc, candidate)
            if not plan.units:
                continue
            found = check_plan(plan.units, plan.wholes)
            if found.limits:
                tally["NuSMV's limit"] += 1
                continue
            whole = whole_check(doc, candidate).equivalent
            tally[f"per node {'proved' if found.holds else 'failed'}, whole {whole}"] += 1
            if found.holds:
                assert whole, "NuSMV proved per node a pair its whole encoding finds different"
    print(f"\n[NuSMV per node vs NuSMV whole] {dict(tally)}")
    assert tally["per node proved, whole True"] >= 8
    assert tally["per node failed, whole False"] >= 3


def _leaves(doc) -> int:  # type: ignore[no-untyped-def]
    count, stack = 0, [doc.main.root]
    while stack:
        node = stack.pop()
        count += not node.children
        stack.extend(node.children)
    return count


def test_sigma_is_checked_not_trusted(nusmv_binary) -> None:
    """σ (the native pairing of statuses with exits) swapped on a unit that held: NuSMV fails
    it, and says the tree's exit and the fragment's differ."""
    doc = family_tree("mixed", 40, 3)
    plan = _plan(doc, bt_to_hfsm(doc, pernode=True).model)
    units = [u for _r, region_units in plan.units for u in region_units]
    swappable = [u for u in units if len({e for e in u.sigma.values()}) >= 2]
    assert swappable
    unit = swappable[0]
    statuses = sorted(unit.sigma)
    exits = [unit.sigma[s] for s in statuses]
    unit.sigma = dict(zip(statuses, exits[1:] + exits[:1]))
    found = check_units([unit])
    assert not found.verdicts[0].holds
    assert any("exits" in step for step in found.verdicts[0].steps)


def test_verify_both_names_the_method_and_counts_units_on_a_large_tree(nusmv_binary) -> None:
    doc = family_tree("decorated", leaves_for(300), 2)
    model = bt_to_hfsm(doc).model
    report = verify(doc, model, engine="both")
    assert report.equivalent
    assert report.method == f"{PER_NODE}+{SYMBOLIC_PER_NODE}"
    stats = report.stats["nusmv"]
    assert stats["units"] == stats["units_held"] == report.stats["per_node_distinct"]
    assert "NuSMV" in report.engines
    alone = verify(doc, model, engine="nusmv")
    assert alone.method == SYMBOLIC_PER_NODE and alone.equivalent


def test_a_mutant_s_failing_unit_is_named_by_both_engines(nusmv_binary) -> None:
    doc = family_tree("mixed", leaves_for(300), 1)
    model = bt_to_hfsm(doc).model
    rng = random.Random(5)
    for _attempt in range(10):
        mutant = mutate(model, rng)
        assert mutant is not None
        with limits.changed(conversion_max_states=BOUND):
            report = verify(doc, mutant, engine="both", max_states=BOUND)
        if report.method != PER_NODE_LIFTED:
            continue
        assert not report.equivalent
        stats = report.stats["nusmv"]
        assert stats["failed"] == report.stats["per_node_failed"]
        assert stats["units_held"] == stats["units"] - 1
        assert stats["counterexample"][-2].startswith("then the tree:")
        return
    raise AssertionError("no mutant was refuted per node")


def test_a_certificate_of_a_proof_both_engines_made_checks(nusmv_binary) -> None:
    """The native parts of a ``compositional (per node)+symbolic (per node)`` proof are kept and
    re-checked like those of the native proof (the method's first part names them)."""
    import json

    from fsmbt.verify import certificate
    from support.pernode_certs import RESULT, SOURCE, family_pair, recheck

    doc, model = family_pair("memory", 30, 4)
    with certificate.collecting() as sink:
        report = verify(doc, model, engine="both")
    assert report.method == f"{PER_NODE}+{SYMBOLIC_PER_NODE}"
    data = json.loads(
        json.dumps(certificate.build(sink, report, source_digest=SOURCE, result_digest=RESULT))
    )
    checked = recheck(data, doc, model)
    assert checked.equivalent and checked.method == report.method
