"""The compositional check (``fsmbt.verify.compositional``, docs/semantics.md §4c) agrees with
the whole product on every pair the latter decides.

Generated pairs (8 batches of 250 seeded trees: about 2 000 converted trees and one mutant of
each, about 3 980 pairs; a mutant changes one transition of the top machine or of any
sub-machine, regions included): seeded random trees mixing plain, reactive and WithMemory controls with
Inverter/ForceSuccess/ForceFailure/Repeat/RetryUntilSuccessful decorators and built-in leaves (``support.random_trees``), each converted
by ``bt_to_hfsm`` and checked against its HFSM and against single mutants of that HFSM
(``fsmbt.verify.mutations``). For every pair: when the compositional check proves it
equivalent, the whole product (fsmbt's interpreter, canonical states) says equivalent too; the
compositional check decides a good share of the pairs (so the agreement is not vacuous); and a
mutant the whole product refutes is refuted by ``verify`` with a counterexample that replays, its
method not ``compositional``.
"""

from __future__ import annotations

import random
import re

import pytest

from fsmbt import api, limits
from fsmbt.cli import main
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import ASSIGN, DATAMODEL, parse_lines
from fsmbt.verify import replay, verify
from fsmbt.verify.compositional import (
    FAILED_PART,
    NotDecomposable,
    compositional_report,
    decompose,
    fsm_regions,
    tree_regions,
)
from fsmbt.verify.native import check
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import COMPOSITIONAL, LIFTED
from support.random_trees import random_tree
from support.sampling import seed
from support.ver_models import memory_regions_tree
from support.whole_mutants import CONTROLS, DECORATORS, deep_mutants

#: Batches and trees per batch: 8 x 250 = 2 000 trees, each with its HFSM and one mutant.
BATCHES, TREES = 8, 250


def _pairs(batch: int) -> list[tuple[BTDocument, FSM, bool]]:
    """(tree, HFSM or a mutant of it, is the converter's own HFSM) for one seeded batch."""
    rng = random.Random(f"{seed()}:compositional:{batch}")
    out: list[tuple[BTDocument, FSM, bool]] = []
    for _ in range(TREES):
        doc = random_tree(rng, controls=CONTROLS, decorators=DECORATORS, max_nodes=12)
        try:
            hfsm = bt_to_hfsm(doc).model
        except (InputError, UnsupportedError):
            continue  # a tree the converter refuses has no pair
        out.append((doc, hfsm, True))
        for mutant in deep_mutants(hfsm, rng.randrange(1 << 30), per_operator=1)[:1]:
            out.append((doc, mutant, False))
    return out


def _whole(doc: BTDocument, fsm: FSM):  # type: ignore[no-untyped-def]
    source, result, _mode = machines_for(doc, fsm)
    return check(source, result)


@pytest.mark.parametrize("batch", range(BATCHES))
def test_compositional_agrees_with_the_whole_product(batch: int) -> None:
    decided = pairs = refuted = lifted = 0
    for doc, fsm, _own in _pairs(batch):
        try:
            whole = _whole(doc, fsm)
        except InputError:
            continue  # e.g. a state limit: the whole product does not decide this pair
        pairs += 1
        proved, _why = compositional_report(doc, fsm)
        if proved is not None and proved.method in LIFTED:  # a failing part's counterexample
            lifted += 1
            assert not whole.equivalent, (
                "a lifted counterexample on a pair the whole product proves"
            )
            # and it tells the two flattened machines apart (not only the lazy runner)
            trace = next(p.counterexample for p in proved.properties.values() if not p.holds)
            assert trace is not None
            source, result, _mode = machines_for(doc, fsm)
            inputs = [step.input for step in trace[1:] if step.input is not None]
            assert replay(source, result, inputs).differs
        elif proved is not None:
            decided += 1
            assert whole.equivalent, (
                f"compositional proved a pair the whole product refutes: {_why}"
            )
        if not whole.equivalent:
            refuted += 1
    print(
        f"batch {batch}: {pairs} pairs, {decided} decided compositionally, {lifted} refuted "
        f"by a lifted counterexample, {refuted} refuted"
    )
    assert pairs >= 400
    assert decided >= pairs // 10  # the agreement covers real compositional proofs
    assert refuted >= pairs // 10  # and mutants that differ


def test_regions_are_the_topmost_nodes_with_memory() -> None:
    doc = memory_regions_tree()
    assert [n.type for n in tree_regions(doc)] == ["SequenceWithMemory", "ReactiveSequence"]


def test_verify_names_the_compositional_method() -> None:
    doc = memory_regions_tree()
    hfsm = bt_to_hfsm(doc).model
    report = verify(doc, hfsm)
    assert report.equivalent
    assert report.method == COMPOSITIONAL
    assert report.stats["regions"] == 2
    assert _whole(doc, hfsm).equivalent


def test_every_mutant_is_refuted_with_a_counterexample_that_replays() -> None:
    doc = memory_regions_tree()
    hfsm = bt_to_hfsm(doc).model
    found = said = 0
    for mutated in deep_mutants(hfsm, seed(), per_operator=None):
        report = verify(doc, mutated)
        whole = _whole(doc, mutated)
        assert report.equivalent == whole.equivalent
        if report.equivalent:
            continue
        found += 1
        assert report.method != COMPOSITIONAL
        if str(report.stats.get("compositional", "")).startswith(FAILED_PART):
            said += 1  # the verdict says which local check failed before the whole product
        failing = [p for p in report.properties.values() if not p.holds]
        trace = failing[0].counterexample
        assert trace is not None
        source, result, _mode = machines_for(doc, mutated)
        inputs = [step.input for step in trace[1:] if step.input is not None]
        assert replay(source, result, inputs).differs
    assert found >= 5
    assert said >= 1


def _data_regions_tree() -> BTDocument:
    """Sequence(ReactiveSequence(c1, Sequence(a1, a2)), ReactiveSequence(c2, Sequence(a3, a4))):
    two regions whose plain Sequence under a reactive one keeps a running index (data)."""

    def region(c: str, x: str, y: str) -> BTNode:
        inner = BTNode(
            "Sequence",
            NodeKind.CONTROL,
            children=[
                BTNode("Act", NodeKind.ACTION, name=x),
                BTNode("Act", NodeKind.ACTION, name=y),
            ],
        )
        return BTNode(
            "ReactiveSequence",
            NodeKind.CONTROL,
            children=[BTNode("Cond", NodeKind.CONDITION, name=c), inner],
        )

    return BTDocument.single(
        BTNode(
            "Sequence",
            NodeKind.CONTROL,
            children=[region("c1", "a1", "a2"), region("c2", "a3", "a4")],
        )
    )


def test_regions_with_data_are_proved_and_a_shared_variable_is_refused() -> None:
    doc = _data_regions_tree()
    hfsm = bt_to_hfsm(doc).model
    assert DATAMODEL in hfsm.attrs  # the compact regions keep their indices as data
    assert decompose(doc, hfsm).equivalent
    assert verify(doc, hfsm).method == COMPOSITIONAL
    first, second = fsm_regions(hfsm)[:2]
    names = [name for name, _init in parse_lines(hfsm.attrs[DATAMODEL])]
    words = {
        w
        for t in second.machine.transitions
        for w in re.findall(r"[A-Za-z_][A-Za-z0-9_]*", " ".join(t.attrs.values()))
    }
    theirs = [n for n in names if n in words]
    mine = [n for n in names if n not in theirs]
    assert mine and theirs
    # the second region now also writes a variable of the first: they are coupled
    second.machine.transitions[0].attrs[ASSIGN] = f"{mine[0]}=0"
    with pytest.raises(NotDecomposable, match="shared"):
        decompose(doc, hfsm)


def test_a_subtree_or_a_flat_machine_is_out_of_scope() -> None:
    doc = memory_regions_tree()
    sub = BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "S"})
    with_subtree = BTDocument.single(
        BTNode("Sequence", NodeKind.CONTROL, children=[sub, BTNode("Act", NodeKind.ACTION)])
    )
    with pytest.raises(NotDecomposable, match="SubTree"):
        tree_regions(with_subtree)
    flat = FSM(name="flat")
    flat.add_state("x")
    with pytest.raises(NotDecomposable, match="flat"):
        decompose(doc, flat)


def test_the_cli_proves_compositionally_with_or_without_a_certificate(tmp_path, capsys) -> None:
    """Through files (the HFSM written as SCXML and read back, its sub-machines renamed): the
    command names the compositional method; with ``--certificate`` too, whose units (one per
    region, one for the skeleton) ``check-certificate`` validates."""
    doc = memory_regions_tree()
    tree = api.write(doc, tmp_path / "tree.xml")
    machine = api.write(bt_to_hfsm(doc).model, tmp_path / "tree.scxml")
    assert main(["verify", str(tree), str(machine)]) == 0
    assert f"proven by: {COMPOSITIONAL}" in capsys.readouterr().out
    certificate = tmp_path / "proof.json"
    assert main(["verify", str(tree), str(machine), "--certificate", str(certificate)]) == 0
    assert f"proven by: {COMPOSITIONAL}" in capsys.readouterr().out
    assert main(["check-certificate", str(tree), str(machine), str(certificate)]) == 0
    assert "2 region, 1 skeleton" in capsys.readouterr().out


def test_a_part_past_a_limit_is_a_fallback_not_an_error() -> None:
    """A region whose data expansion passes the conversion limit makes the compositional check
    give way (the whole product then gives whatever it gave before), never raise itself."""
    doc = _data_regions_tree()
    hfsm = bt_to_hfsm(doc).model
    with limits.changed(conversion_max_states=2):
        proved, why = compositional_report(doc, hfsm)
    assert proved is None
    assert why.startswith("a part cannot be checked")


def test_one_region_gives_way_before_any_part_is_checked() -> None:
    """A tree whose root is reactive is one region: the whole tree. ``verify``'s attempt gives
    way at once (``min_regions=2``: no region is explored, the reason says so) and the whole
    product decides; the same pair checked with ``min_regions=1`` explores the region."""
    doc = memory_regions_tree()
    assert doc.main.root is not None
    doc.main.root.type = "ReactiveFallback"
    hfsm = bt_to_hfsm(doc).model
    assert len(tree_regions(doc)) == 1
    proved, why = compositional_report(doc, hfsm, min_regions=2)
    assert proved is None and "1 region(s) paired" in why
    alone, _why = compositional_report(doc, hfsm)
    assert alone is not None and alone.stats["region_product_states"] > 0
    report = verify(doc, hfsm)
    assert report.equivalent and report.method != COMPOSITIONAL
    assert report.equivalent == _whole(doc, hfsm).equivalent


#: Controls of the Parallel sample: plain ones around, a Parallel or ParallelAll heading regions.
PARALLEL_CONTROLS = ("Sequence", "Fallback", "Sequence", "Fallback", "Parallel", "ParallelAll")


def _parallel_pairs(count: int) -> list[tuple[BTDocument, FSM]]:
    """Seeded trees with a Parallel written as a ``<parallel>`` region (``bt_parallel``): each
    with its HFSM and every single mutant of the parallel state's machines, one per operator."""
    rng = random.Random(f"{seed()}:compositional:parallel")
    out: list[tuple[BTDocument, FSM]] = []
    for _ in range(count):
        doc = random_tree(rng, controls=PARALLEL_CONTROLS, decorators=DECORATORS, max_nodes=10)
        try:
            hfsm = bt_to_hfsm(doc).model
        except (InputError, UnsupportedError):
            continue
        labels = frozenset(n.label for n in tree_regions(doc))
        try:
            regions = fsm_regions(hfsm, labels)
        except NotDecomposable:
            continue
        if not any(region.machine.is_hierarchical for region in regions):
            continue  # no <parallel> region: the other tests cover it
        out.append((doc, hfsm))
        out.extend((doc, m) for m in deep_mutants(hfsm, rng.randrange(1 << 30), 1)[:3])
    return out


def test_a_parallel_written_as_parallel_regions_is_a_region() -> None:
    """A Parallel heading its region as a ``<parallel>`` state (``convert/bt_parallel.py``) is
    one region, checked whole: the compositional check agrees with the whole product on
    every pair the latter decides, and proves the converter's own results (before, such a
    state was "data outside a region" and a large tree holding one went to the whole
    product, which stops at its state limit: ``bench_decorated_mutants.py``)."""
    decided = pairs = refuted = 0
    for doc, fsm in _parallel_pairs(300):
        try:
            whole = _whole(doc, fsm)
        except InputError:
            continue
        pairs += 1
        proved, _why = compositional_report(doc, fsm)
        if proved is not None and proved.method in LIFTED:
            assert not whole.equivalent
        elif proved is not None:
            decided += 1
            assert whole.equivalent, "compositional proved a pair the whole product refutes"
        refuted += not whole.equivalent
    print(
        f"\n[parallel regions] {pairs} pairs, {decided} proven compositionally, {refuted} refuted"
    )
    assert decided >= 20
    assert refuted >= 12
