"""CHDS-BT baseline (Marzinotto et al.): FSM -> switching/mode BT and BT -> one sub-FSM per
control node, verified by the same checker as the rules engine."""

from __future__ import annotations

from pathlib import Path

from fsmbt import api
from fsmbt.model.bt import BTDocument
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

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def test_chds_generated_fsms_all_equivalent():
    assert not_equivalent_seeds("chds", generated_fsms()) == []


def test_chds_generated_bts_all_equivalent():
    assert not_equivalent_seeds("chds", generated_bts()) == []


def test_chds_paper_fsm_one_switch_per_transition():
    fsm = api.load(EXAMPLES / "paper_fsm.json").model
    result = convert("chds", fsm)
    root = result.model.main.root
    switches = [c for c in root.children if c.children[0].type == sv.GUARD]
    modes = [c for c in root.children if c.children[0].type == sv.IS_STATE]
    assert len(switches) == len(fsm.transitions) + 1  # + the initial event
    assert len(modes) == len(fsm.states)
    assert all(s.children[1].type == sv.ASSIGN for s in switches)
    assert verify(fsm, result.model).equivalent


def test_chds_robot_bt_one_sub_fsm_per_control_node():
    bt = api.load(EXAMPLES / "robot_bt.xml").model
    result = convert("chds", bt)
    controls = sum(1 for _t, n in bt.nodes() if n.kind.value == "Control")
    assert result.model.is_hierarchical
    assert result.stats["k"] == controls + 1  # the top machine + one per control node
    assert verify(bt, result.model).equivalent


def test_chds_reactive_restart_crosses_levels():
    bt = BTDocument.single(
        ctrl(
            "Sequence",
            leaf("a0"),
            ctrl(
                "ReactiveSequence",
                leaf("c1", True),
                ctrl("ReactiveFallback", leaf("c2", True), leaf("a3")),
            ),
        )
    )
    result = convert("chds", bt)
    assert verify(bt, result.model).equivalent


def test_chds_plain_node_under_reactive_is_not_equivalent_by_construction():
    bt = plain_under_reactive()
    report = verify(bt, convert("chds", bt).model)
    assert not report.equivalent
    assert any(p.counterexample for p in report.properties.values() if not p.holds)


def test_chds_broken_mode_is_caught():
    fsm = api.load(EXAMPLES / "paper_fsm.json").model
    doc = convert("chds", fsm).model
    mode = next(c for c in doc.main.root.children if c.children[0].type == sv.IS_STATE)
    mode.children[1].attrs["final"] = "true"  # A would terminate at once
    assert not verify(fsm, doc).equivalent
