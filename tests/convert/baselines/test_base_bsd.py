"""BSD baseline: FSM -> state-variable BT and BT -> one-state-per-leaf FSM, verified by the
same checker as the rules engine."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics import state_variable_runtime as sv
from fsmbt.verify import verify
from support.base_helpers import (
    convert,
    ctrl,
    generated_bts,
    generated_fsms,
    leaf,
    not_equivalent_seeds,
    plain_under_reactive,
)

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"


def test_bsd_generated_fsms_all_equivalent():
    assert not_equivalent_seeds("bsd", generated_fsms()) == []


def test_bsd_generated_bts_all_equivalent():
    assert not_equivalent_seeds("bsd", generated_bts()) == []


def test_bsd_paper_fsm_shape_and_verdict():
    fsm = api.load(EXAMPLES / "paper_fsm.json").model
    result = convert("bsd", fsm)
    root = result.model.main.root
    assert root.type == "ReactiveFallback"
    # the start pseudo-state's subtree (initial event), then one guarded subtree per state
    assert len(root.children) == 1 + len(fsm.states)
    for subtree, name in zip(root.children[1:], fsm.states):
        assert [c.type for c in subtree.children] == [sv.IS_STATE, sv.ENTRY_ACTION, sv.TRANSITION]
        assert subtree.children[0].attrs["state"] == name
    a_exits = sv.decode_transitions(root.children[1].children[2].attrs["transitions"])
    assert a_exits == {"eventAB": "B", "eventAC": "C", "eventAD": "D", "eventAF": "F"}
    assert verify(fsm, result.model).equivalent


def test_bsd_element_count_is_8m_plus_1_without_start_event():
    from fsmbt.metrics import elements

    fsm = api.load(EXAMPLES / "paper_fsm.json").model
    fsm.start_name = fsm.initial_event = None
    result = convert("bsd", fsm)
    assert elements(result.model).graphical == 8 * len(fsm.states) + 1
    assert verify(fsm, result.model).equivalent


def test_bsd_robot_bt():
    bt = api.load(EXAMPLES / "robot_bt.xml").model
    result = convert("bsd", bt)
    fsm = result.model
    assert not fsm.is_hierarchical
    leaves = [n for _t, n in bt.nodes() if n.is_leaf]
    assert len(fsm.states) == len(leaves) + 2  # one state per leaf + SUCCESS/FAILURE
    assert verify(bt, fsm).equivalent


def test_bsd_broken_tree_is_caught_with_a_counterexample():
    """The runtime is not vacuous: redirect one transition and the checker must object."""
    fsm = api.load(EXAMPLES / "paper_fsm.json").model
    doc = convert("bsd", fsm).model
    transition = doc.main.root.children[1].children[2]  # A's transition leaf
    transition.attrs["transitions"] = transition.attrs["transitions"].replace("/B", "/C")
    report = verify(fsm, doc)
    assert not report.equivalent
    failed = [p for p in report.properties.values() if not p.holds]
    assert failed and failed[0].counterexample


def test_bsd_plain_node_under_reactive_is_not_equivalent_by_construction():
    bt = plain_under_reactive()
    report = verify(bt, convert("bsd", bt).model)
    assert not report.equivalent
    trace = next(p.counterexample for p in report.properties.values() if not p.holds)
    inputs = [step.input for step in trace if step.input is not None]
    assert "running" in inputs  # the divergence comes after a3 ran (resume vs restart)


def test_bsd_all_reactive_tree_is_exact():
    bt = BTDocument.single(
        ctrl(
            "ReactiveSequence",
            leaf("c1", True),
            ctrl("ReactiveFallback", leaf("c2", True), leaf("a3")),
            leaf("a4"),
        )
    )
    assert verify(bt, convert("bsd", bt).model).equivalent


def test_bsd_refuses_nodes_without_classical_mapping():
    bt = BTDocument.single(ctrl("Parallel", leaf("a"), leaf("b")))
    with pytest.raises(UnsupportedError):
        convert("bsd", bt)


def test_bsd_cli_convert_engine(tmp_path):
    out = tmp_path / "aj_bsd.xml"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "fsmbt.cli",
            "convert",
            str(EXAMPLES / "paper_fsm.json"),
            "--engine",
            "bsd",
            "-o",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert "EQUIVALENT" in proc.stdout
    written = api.load(out).model  # the XML round trip keeps the state-variable leaves
    assert verify(api.load(EXAMPLES / "paper_fsm.json").model, written).equivalent
