"""Hierarchical FSM -> BT with one SubTree per composite state: every result is proven
equivalent by the checker (examples, the corpus's hierarchical SCXML, generated HFSMs), and the
tree mirrors the hierarchy."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.convert.hfsm_to_bt import fsm_to_subtree_bt
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from support.conv_helpers import check
from support.conv_hfsm_gen import random_hfsm
from support.corpus import CORPUS

REPO = Path(__file__).resolve().parents[2]


def _composites(fsm: FSM) -> list[str]:
    return [path for path, _m, state in fsm.walk() if not state.is_atomic]


def _subtree_refs(doc) -> list[str]:
    return [node.attrs["ID"] for _tree, node in doc.nodes() if node.type == "SubTree"]


def test_door_example_has_one_tree_per_composite_and_is_equivalent() -> None:
    fsm = api.load(REPO / "examples" / "door_hfsm.scxml").model
    result = convert(fsm, style="lebt")
    doc = result.model
    assert set(doc.trees) == {"MainTree", *_composites(fsm)}
    assert sorted(_subtree_refs(doc)) == sorted(_composites(fsm))
    assert result.stats["hierarchy"] == "subtrees"
    assert check(fsm, doc).equivalent


def test_flatten_mode_gives_one_tree() -> None:
    fsm = api.load(REPO / "examples" / "door_hfsm.scxml").model
    result = convert(fsm, style="lebt", hierarchy="flatten")
    assert list(result.model.trees) == ["MainTree"]
    assert check(fsm, result.model).equivalent


@pytest.mark.parametrize("parallel", [False, True])
def test_generated_hfsms_convert_to_subtrees_equivalently(parallel: bool) -> None:
    failures, with_subtrees = [], 0
    for seed in range(120):
        fsm = random_hfsm(seed, parallel=parallel)
        try:
            result = fsm_to_subtree_bt(fsm)
        except InputError as exc:  # e.g. a cycle of completion transitions: rejected clearly
            assert "eventless" in str(exc)
            continue
        if result.stats.get("hierarchy") == "subtrees":
            with_subtrees += 1
            assert result.stats["subtrees"] == len(result.model.trees) - 1
        if not check(fsm, result.model).equivalent:
            failures.append(seed)
    assert failures == []
    assert with_subtrees >= 60


def test_corpus_hierarchical_scxml_converts_to_subtrees_equivalently() -> None:
    if not CORPUS.is_dir():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    files = sorted(p for p in CORPUS.rglob("*.scxml") if "_malformed" not in p.parts)
    converted, failures = 0, []
    for path in files:
        try:
            model = api.load(path).model
        except InputError:
            continue
        if not isinstance(model, FSM) or not model.is_hierarchical:
            continue
        try:
            result = convert(model, style="lebt")
            report = check(model, result.model, max_states=200_000)
        except InputError:
            continue
        converted += 1
        if not report.equivalent:
            failures.append(path.name)
    print(f"\nhierarchical corpus SCXML converted with SubTrees: {converted}")
    assert failures == []
    assert converted > 0
