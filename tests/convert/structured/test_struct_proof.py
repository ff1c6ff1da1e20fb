"""The outcome pairing proves structured trees and finds wrong ones (docs/semantics.md §11):
mutated trees are NOT equivalent, the BT -> FSM conversion of a structured tree is proven
equivalent to the source machine, and the blackboard model refuses what it does not cover."""

from __future__ import annotations

import copy

import pytest

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.structured import fsm_to_structured
from fsmbt.generate.outcome_machines import random_outcome_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import UnsupportedError
from fsmbt.verify import verify
from fsmbt.verify.native import check
from fsmbt.verify.outcome_roundtrip import leaf_fsm_machines
from support.structured_machines import machine, pipeline

DISPATCH = {
    "Look": {"found": "Grasp", "lost": "Search", "blocked": "aborted"},
    "Grasp": {"succeeded": "succeeded", "aborted": "aborted"},
    "Search": {"succeeded": "Grasp", "aborted": "aborted"},
}


def _equivalent(fsm, doc: BTDocument) -> bool:
    return bool(verify(fsm, doc, outcome_driven=True).equivalent)


def _first(doc: BTDocument, kind: str) -> BTNode:
    return next(n for _t, n in doc.nodes() if n.type.startswith(kind))


def test_a_wrong_child_order_is_found_not_equivalent() -> None:
    fsm = pipeline(4)
    doc = copy.deepcopy(fsm_to_structured(fsm).model)
    root = doc.main.root
    assert root is not None
    root.children[1], root.children[2] = root.children[2], root.children[1]
    report = verify(fsm, doc, outcome_driven=True)
    assert report.equivalent is False
    assert any(not p.holds and p.counterexample for p in report.properties.values())


def test_a_swapped_outcome_case_is_found_not_equivalent() -> None:
    fsm = machine(DISPATCH)
    doc = fsm_to_structured(fsm).model
    assert _equivalent(fsm, doc)
    swapped = copy.deepcopy(doc)
    switch = _first(swapped, "Switch")
    switch.attrs["case_1"], switch.attrs["case_2"] = switch.attrs["case_2"], switch.attrs["case_1"]
    assert not _equivalent(fsm, swapped)


def test_swapped_branches_and_a_lost_state_are_found() -> None:
    fsm = machine(
        {
            "A": {"succeeded": "B", "aborted": "C"},
            "B": {"succeeded": "succeeded", "aborted": "aborted"},
            "C": {"succeeded": "succeeded", "aborted": "aborted"},
        }
    )
    doc = fsm_to_structured(fsm).model
    assert _equivalent(fsm, doc)
    swapped = copy.deepcopy(doc)
    branch = _first(swapped, "IfThenElse")
    branch.children[1], branch.children[2] = branch.children[2], branch.children[1]
    assert not _equivalent(fsm, swapped)
    lost = copy.deepcopy(doc)
    _first(lost, "IfThenElse").children[2].name = "D"
    assert not _equivalent(fsm, lost)


@pytest.mark.parametrize("seed", [s for s in range(40) if s % 3 == 0])
def test_bt_to_fsm_of_a_structured_tree_is_proven_equivalent_to_the_source(seed: int) -> None:
    fsm = random_outcome_fsm(seed, states=6, containers=0.0)
    doc = fsm_to_structured(fsm).model
    if any(n.type.startswith("Switch") for _t, n in doc.nodes()):
        fsm = pipeline(3 + seed % 5)  # the rules engine's BT -> FSM refuses Switch
        doc = fsm_to_structured(fsm).model
    back = bt_to_hfsm(doc).model
    source, result, mode = leaf_fsm_machines(fsm, back)
    report = check(source, result, mode=mode)
    assert report.equivalent, report.verdicts()
    # and a mutated round trip is found: one transition of the converted FSM retargeted
    wrong = copy.deepcopy(back)
    for t in wrong.transitions:
        if t.event == "failure" and t.target != t.source:
            t.target = t.source
            break
    source, result, mode = leaf_fsm_machines(fsm, wrong)
    assert not check(source, result, mode=mode).equivalent


def test_the_blackboard_model_refuses_other_uses_of_a_modelled_entry() -> None:
    fsm = machine(DISPATCH)
    doc = copy.deepcopy(fsm_to_structured(fsm).model)
    grasp = next(n for _t, n in doc.nodes() if n.name == "Grasp")
    grasp.attrs["goal"] = "{Look_outcome}"  # another writer of the entry a Switch reads
    with pytest.raises(UnsupportedError, match="Look_outcome"):
        verify(fsm, doc, outcome_driven=True)


def test_both_engines_check_the_outcome_pairing(nusmv_binary: object) -> None:
    fsm = pipeline(2)
    doc = fsm_to_structured(fsm).model
    report = verify(fsm, doc, engine="both", outcome_driven=True)
    assert report.equivalent and report.engine == "native+nusmv"
    assert "nusmv_limit" not in report.stats  # NuSMV decided it (tests/verify/nusmv/)
