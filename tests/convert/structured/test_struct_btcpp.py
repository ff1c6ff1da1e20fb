"""Differential: the structured trees of the corpus SMACH/FlexBE files and of seeded generated
outcome-driven machines run in BehaviorTree.CPP 4.8.2 (behaviortreepy) like their source
machines: the same leaf calls and the same result under the same scripted outcomes
(tests/support/structured_btcpp.py); and each tree stays within 1.25x the nodes of a tree
written by hand for its machine (tests/data/structured/)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert.structured import fsm_to_structured
from fsmbt.generate.outcome_machines import random_outcome_fsm
from fsmbt.model.bt import BTDocument
from support.corpus import CORPUS
from support.structured_btcpp import run_btcpp, run_source

pytest.importorskip("behaviortreepy")

FSM_DIR = CORPUS / "fsm"
CORPUS_FILES = sorted(
    [
        *FSM_DIR.glob("smach_tutorials/*.py"),
        *FSM_DIR.glob("smach_tests/*.py"),
        *FSM_DIR.glob("flexbe_turtlesim_demo/*_sm.py"),
    ]
)
HAND = Path(__file__).resolve().parents[2] / "data" / "structured"
BUDGET = 40


def _same_in_btcpp(fsm, doc: BTDocument, seeds: range) -> None:
    for seed in seeds:
        ours = run_source(fsm, seed, BUDGET)
        theirs = run_btcpp(doc, fsm, seed, BUDGET)
        assert theirs == ours, (seed, ours, theirs)


@pytest.mark.skipif(not FSM_DIR.exists(), reason="corpus not present (FSMBT_CORPUS)")
@pytest.mark.parametrize("path", CORPUS_FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_corpus_structured_trees_run_in_btcpp_like_their_machines(path: Path) -> None:
    fsm = api.load(path).model
    doc = fsm_to_structured(fsm).model
    _same_in_btcpp(fsm, doc, range(6))


@pytest.mark.parametrize("seed", range(50))
def test_generated_structured_trees_run_in_btcpp_like_their_machines(seed: int) -> None:
    fsm = random_outcome_fsm(seed, states=7)
    doc = fsm_to_structured(fsm).model
    _same_in_btcpp(fsm, doc, range(seed * 3, seed * 3 + 3))


def test_the_engine_run_tells_a_wrong_tree_apart() -> None:
    from support.structured_machines import machine

    fsm = machine(
        {
            "Look": {"found": "Grasp", "lost": "Search", "blocked": "aborted"},
            "Grasp": {"succeeded": "succeeded", "aborted": "aborted"},
            "Search": {"succeeded": "Grasp", "aborted": "aborted"},
        }
    )
    doc = fsm_to_structured(fsm).model
    _same_in_btcpp(fsm, doc, range(5))
    switch = next(n for _t, n in doc.nodes() if n.type.startswith("Switch"))
    switch.attrs["case_1"], switch.attrs["case_2"] = switch.attrs["case_2"], switch.attrs["case_1"]
    runs = [(run_source(fsm, s, BUDGET), run_btcpp(doc, fsm, s, BUDGET)) for s in range(20)]
    assert any(ours != theirs for ours, theirs in runs)


def _nodes(doc: BTDocument) -> int:
    return sum(1 for _tree, _node in doc.nodes())


@pytest.mark.skipif(not FSM_DIR.exists(), reason="corpus not present (FSMBT_CORPUS)")
@pytest.mark.parametrize(
    "name",
    [
        "smach_tests/sequence.py",
        "smach_tutorials/state_machine_nesting2.py",
        "flexbe_turtlesim_demo/example_2_sm.py",
        "smach_tutorials/actionlib_test.py",
    ],
)
def test_structured_trees_are_no_bigger_than_hand_written_ones(name: str) -> None:
    fsm = api.load(FSM_DIR / name).model
    doc = fsm_to_structured(fsm).model
    hand = api.load(HAND / (name.replace("/", "__").removesuffix(".py") + ".xml")).model
    assert isinstance(hand, BTDocument)
    assert _nodes(doc) <= 1.25 * _nodes(hand), (_nodes(doc), _nodes(hand))
