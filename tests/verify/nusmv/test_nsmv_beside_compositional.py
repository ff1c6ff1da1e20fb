"""``--engine both`` on a pair the compositional check decides by parts (docs/verification.md,
"What a verdict says"): NuSMV's whole encodings decide beside the compositional verdict, and the
native verdict is never computed a second time by the whole product (real NuSMV).

A proof by regions must meet NuSMV's on all five properties; a region's lifted counterexample
names only the properties its replay shows failing, and NuSMV must fail each of them and say
NOT EQUIVALENT. The whole product's check is replaced by one that fails the test, so a verdict
that went through it cannot pass.
"""

from __future__ import annotations

import random

import pytest

import fsmbt.verify as verify_module
from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.errors import FsmbtError
from fsmbt.verify import verify
from fsmbt.verify.report import COMPOSITIONAL, COMPOSITIONAL_LIFTED, SYMBOLIC
from support.pernode_mutants import mutate, whole
from support.random_trees import random_tree
from support.sampling import seed
from support.ver_models import memory_regions_tree

CONTROLS = ("Sequence", "Fallback", "SequenceWithMemory", "ReactiveSequence", "ReactiveFallback")
DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "Repeat", "RetryUntilSuccessful")
#: Lifted region counterexamples wanted, and the trees drawn at most to find them.
WANTED, DRAWS = 4, 1_500


def _forbid_the_whole_product(monkeypatch: pytest.MonkeyPatch) -> None:
    """From here on the whole native product may not run: ``verify``'s own entry to it fails
    the test."""

    def refuse(*_args: object, **_kwargs: object) -> None:
        raise AssertionError("the whole native product was computed again")

    monkeypatch.setattr(verify_module, "check_witnessed", refuse)


def test_both_confirms_a_proof_by_regions_without_the_whole_product(
    nusmv_binary, monkeypatch
) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    _forbid_the_whole_product(monkeypatch)
    doc = memory_regions_tree()
    report = verify(doc, bt_to_hfsm(doc).model, engine="both")
    assert report.equivalent
    assert report.method == f"{COMPOSITIONAL}+{SYMBOLIC}"
    assert report.engine == "native+nusmv"
    assert "NuSMV" in report.engines and "nusmv_limit" not in report.stats
    assert report.stats["regions"] == 2


def _region_lifted_pairs() -> list[tuple[object, object]]:
    """Seeded per-node conversions and one-transition mutants the native check refutes by a
    region's lifted counterexample (``compositional, lifted``)."""
    rng = random.Random(f"{seed()}:beside")
    found: list[tuple[object, object]] = []
    for _ in range(DRAWS):
        doc = random_tree(rng, controls=CONTROLS, decorators=DECORATORS, max_nodes=16)
        try:
            mutant = mutate(bt_to_hfsm(doc, pernode=True).model, rng)
            if mutant is not None and verify(doc, mutant).method == COMPOSITIONAL_LIFTED:
                found.append((doc, mutant))
        except FsmbtError:
            continue  # a tree the converter refuses, or a mutant that is not a machine
        if len(found) == WANTED:
            break
    return found


def test_both_confirms_a_lifted_region_counterexample(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    pairs = _region_lifted_pairs()
    assert len(pairs) == WANTED  # the sample holds region lifts (else the test is vacuous)
    _forbid_the_whole_product(monkeypatch)
    confirmed = 0
    for doc, mutant in pairs:
        try:
            with limits.changed(nusmv_max_seconds=30):
                report = verify(doc, mutant, engine="both")  # type: ignore[arg-type]
        except FsmbtError as exc:  # NuSMV does not encode this tree (named), not a verdict
            assert "NuSMV" in str(exc)
            continue
        assert not report.equivalent
        assert report.method == f"{COMPOSITIONAL_LIFTED}+{SYMBOLIC}"
        assert whole(doc, mutant) is False  # type: ignore[arg-type]
        failing = [p for p in report.properties.values() if not p.holds]
        assert failing and all(p.counterexample for p in failing)
        confirmed += "nusmv_limit" not in report.stats
    assert confirmed >= WANTED // 2  # NuSMV decided most of them itself
