"""fsmbt diff: every behavioural difference, the edit script, the three outputs, bad input.

Every group the diff reports is confirmed by replaying its witness on both machines (the two
agree up to the last step and differ there); "same" is confirmed by the verifier.
"""

from __future__ import annotations

import copy
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from fsmbt import api, diff
from fsmbt.cli import main
from fsmbt.model.errors import InputError
from fsmbt.semantics.nodes import node_semantics
from fsmbt.verify import verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.native import replay
from fsmbt.verify.orient import orient
from fsmbt.verify.pairing import machines_for

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ROBOT = EXAMPLES / "robot_bt.xml"
SWAP = ("<RobotAtInspection/>\n        <Dock/>", "<Dock/>\n        <RobotAtInspection/>")


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _swapped(tmp_path: Path) -> tuple[Path, Path]:
    text = ROBOT.read_text(encoding="utf-8")
    assert SWAP[0] in text
    return ROBOT, _write(tmp_path, "new.xml", text.replace(*SWAP))


def _confirm(old: api.Model, new: api.Model, report: diff.DiffReport) -> None:
    """Each witness: both agree before its last step and differ at it."""
    oriented = orient(old, new)
    source, result, _ = machines_for(oriented.source, oriented.result)
    for group in report.behaviour.groups:
        steps = replay(source, result, list(group.witness)).steps
        assert all(not step.note for step in steps[:-1]), group
        assert steps[-1].note, group


def test_swapped_fallback_children(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    old, new = _swapped(tmp_path)
    md, svg, junit = tmp_path / "r.md", tmp_path / "p.svg", tmp_path / "j.xml"
    code = main(
        [
            "diff",
            str(old),
            str(new),
            "--markdown",
            str(md),
            "--picture",
            str(svg),
            "--junit",
            str(junit),
        ]
    )
    assert code == 1
    first, second, report = diff.diff_files(old, new)
    _confirm(first.model, second.model, report)
    # every run that reaches the Fallback parts there: each group's OLD ticks RobotAtInspection
    assert report.behaviour.groups
    for group in report.behaviour.groups:
        assert "RobotAtInspection" in group.old_does and "Dock" in group.new_does
    assert [(e.op, e.label) for e in report.script or []] == [("moved", "Dock")]
    text = md.read_text(encoding="utf-8")
    assert "behaviour changed" in text and "`Dock`" in text and "moved" in text
    picture = svg.read_text(encoding="utf-8")
    assert picture.count('stroke="red"') >= 1 and "orange" in picture
    suite = ET.parse(junit).getroot().find("testsuite")
    assert suite is not None
    assert int(suite.get("failures", "-1")) == len(report.behaviour.groups)


def test_same_behaviour_different_structure(tmp_path: Path) -> None:
    text = ROBOT.read_text(encoding="utf-8")
    wrapped = text.replace("<Recharge/>", "<Sequence><Recharge/></Sequence>")
    new = _write(tmp_path, "new.xml", wrapped)
    first, second, report = diff.diff_files(ROBOT, new)
    assert verify(first.model, second.model).equivalent
    assert report.same and not report.behaviour.groups
    assert [(e.op, e.label) for e in report.script or []] == [
        ("added", "Sequence"),
        ("moved", "Recharge"),
    ]
    assert main(["diff", str(ROBOT), str(new)]) == 0


def test_every_difference_not_just_the_first(tmp_path: Path) -> None:
    """Two independent edits: a group for each, and the verdict agrees with the checker."""
    text = ROBOT.read_text(encoding="utf-8").replace(*SWAP)
    text = text.replace("<RobotatCube2/>", "<Cube2Seen/>")
    new = _write(tmp_path, "new.xml", text)
    first, second, report = diff.diff_files(ROBOT, new)
    _confirm(first.model, second.model, report)
    news = [g.new_does for g in report.behaviour.groups]
    assert any("Dock" in d for d in news) and any("Cube2Seen" in d for d in news)
    ops = {(e.op, e.label) for e in report.script or []}
    assert ops == {("moved", "Dock"), ("retyped", "Cube2Seen")}  # a leaf replaced in place


def test_mutants_agree_with_the_checker() -> None:
    model = api.load(ROBOT).model
    seen_same = seen_diff = 0
    for mutant in mutants(model, seed=3, per_operator=2):
        report = diff.diff_models(model, mutant.model)
        assert report.same == verify(model, mutant.model).equivalent, mutant.description
        _confirm(model, mutant.model, report)
        seen_same += report.same
        seen_diff += not report.same
    assert seen_diff > 0


def test_fsm_retarget_and_removed_state(tmp_path: Path) -> None:
    old = api.load(EXAMPLES / "paper_fsm.xml").model
    new = copy.deepcopy(old)
    moved = next(t for t in new.transitions if t.event == "eventAF")
    moved.target = "D"
    report = diff.diff_models(old, new)
    _confirm(old, new, report)
    [group] = report.behaviour.groups
    assert group.old_state == "A" and group.input == "eventAF"
    assert group.old_next == "F" and group.new_next == "D"
    assert [(e.op, e.what) for e in report.script or []] == [("retargeted", "transition")]
    dot = diff.diff_dot(old, new, report)
    assert "removed: eventAF" in dot and "red" in dot


def test_json_and_max(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    old, new = _swapped(tmp_path)
    assert main(["diff", str(old), str(new), "--json", "--max", "1"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert len(data["groups"]) == 1 and data["total_groups"] >= 2 and data["same"] is False


def test_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    broken = _write(tmp_path, "broken.xml", "<root BTCPP_format='4'><BehaviorTree ID='x'>")
    assert main(["diff", str(ROBOT), str(broken)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "broken.xml" in err[0]
    out = tmp_path / "lebt.xml"
    assert main(["convert", str(EXAMPLES / "paper_fsm.xml"), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["diff", str(out), str(ROBOT)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot pair" in err[0]


def test_fsm_against_its_converted_tree(tmp_path: Path) -> None:
    """A BT against the FSM it must implement, in either order: the verdict is the verifier's
    and every witness is confirmed on the machines."""
    fsm = api.load(EXAMPLES / "paper_fsm.xml").model
    bt_path = tmp_path / "paper_bt.xml"
    assert main(["convert", str(EXAMPLES / "paper_fsm.xml"), "-o", str(bt_path)]) == 0
    bt = api.load(bt_path).model
    assert diff.diff_models(fsm, bt).same
    differing = 0
    for mutant in mutants(bt, seed=1, per_operator=3):
        # every mutant is a valid tree (the generator respects each kind's declared arity)
        verdict = verify(fsm, mutant.model).equivalent
        report = diff.diff_models(fsm, mutant.model)
        assert report.same == verdict, mutant.description
        assert report.script is None  # two kinds: no edit script
        assert diff.diff_models(mutant.model, fsm).same == report.same
        _confirm(fsm, mutant.model, report)
        differing += not report.same
    assert differing >= 2


def test_an_invalid_tree_is_refused_alike(tmp_path: Path) -> None:
    """A hand-made invalid tree (a Switch that lost a case): the verifier and the diff refuse
    it with the same one-line message, which names the arity the kind declares."""
    fsm = api.load(EXAMPLES / "paper_fsm.xml").model
    bt_path = tmp_path / "paper_bt.xml"
    assert main(["convert", str(EXAMPLES / "paper_fsm.xml"), "-o", str(bt_path)]) == 0
    bt = api.load(bt_path).model
    switch = next(node for _tree, node in bt.nodes() if node.type.startswith("Switch"))
    spec = node_semantics(switch.type)
    assert spec is not None and spec.children == len(switch.children)
    switch.children.pop(0)
    with pytest.raises(InputError) as by_verify:
        verify(fsm, bt)
    with pytest.raises(InputError) as by_diff:
        diff.diff_models(fsm, bt)
    assert by_verify.value.message == by_diff.value.message
    assert f"needs {spec.children} children" in by_verify.value.message


def test_mutants_respect_the_declared_arity() -> None:
    """No BT mutant breaks its kind's declared child count (``NodeSemantics.allows_children``,
    what ``fsmbt.model.validate`` reads): a Switch never loses a case."""
    bt = api.convert_model(api.load(EXAMPLES / "paper_fsm.xml").model).model
    checked = 0
    for mutant in mutants(bt, seed=1, per_operator=None):
        for _tree, node in mutant.model.nodes():
            spec = node_semantics(node.type)
            if spec is not None and node.children:
                assert spec.allows_children(len(node.children)), mutant.description
                checked += 1
    assert checked
