"""fsmbt conform on logs recorded by BehaviorTree.CPP 4.8.2 itself (behaviortreepy's
FileLogger, the FileLogger2 .btlog format): a tree's logs conform to it, a mutant's logs are
caught with the node named, and bad logs are one located line with exit 2."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api, conform
from fsmbt.cli import main
from fsmbt.verify import verify
from fsmbt.verify.mutations import mutants

pytest.importorskip("behaviortreepy")
from support.btlog_record import record_btlog  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "examples" / "robot_bt.xml"
SWAP = ("<RobotAtInspection/>\n        <Dock/>", "<Dock/>\n        <RobotAtInspection/>")
SEEDS = range(6)
TICKS = 40


def _record(tmp_path: Path, xml_path: Path, seed: int, name: str = "run") -> Path:
    log = tmp_path / f"{name}{seed}.btlog"
    record_btlog(
        api.load(xml_path).model, xml_path.read_text(encoding="utf-8"), log, seed=seed, ticks=TICKS
    )
    return log


def test_logs_of_the_tree_conform(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    logs = [_record(tmp_path, ROBOT, seed) for seed in SEEDS]
    assert main(["conform", str(ROBOT), *map(str, logs)]) == 0
    out = capsys.readouterr().out
    assert out.count(": conforms (") == len(logs)
    report = conform.conform_files(ROBOT, list(logs))
    assert all(r.leaf_ticks > 0 for r in report.results)
    seen, total = report.coverage.transitions
    assert 0 < seen <= total == 6 * 2 + 6 * 3  # six conditions, six actions
    assert "coverage: states" in out


def test_swapped_fallback_is_caught_at_the_right_node(tmp_path: Path) -> None:
    swapped = tmp_path / "swapped.xml"
    swapped.write_text(ROBOT.read_text(encoding="utf-8").replace(*SWAP), encoding="utf-8")
    deviations = []
    for seed in SEEDS:
        log = _record(tmp_path, swapped, seed, "swapped")
        assert conform.conform_files(swapped, [log]).conforms  # its own model: no false alarm
        [result] = conform.conform_files(ROBOT, [log]).results
        if result.deviation is not None:
            deviations.append(result.deviation)
    assert deviations
    for found in deviations:
        # the log ticks Dock where the model ticks RobotAtInspection (both at 2/0)
        assert found.node == "Dock@2/0", found.text()
        assert "RobotAtInspection@2/0" in found.allowed
        assert found.index >= 1 and found.time_us >= 0


def test_mutants_logs_against_the_source(tmp_path: Path) -> None:
    model = api.load(ROBOT).model
    caught = 0
    for k, mutant in enumerate(mutants(model, seed=5, per_operator=1)):
        path = api.write(mutant.model, tmp_path / f"m{k}.xml")
        logs = [_record(tmp_path, path, seed, f"m{k}_") for seed in range(3)]
        assert conform.conform_files(path, logs).conforms, mutant.description
        against_source = conform.conform_files(ROBOT, logs)
        if verify(model, mutant.model).equivalent:
            assert against_source.conforms, mutant.description
        elif not against_source.conforms:
            caught += 1
    assert caught >= 2


def _bytes(path: Path) -> bytes:
    return path.read_bytes()


def test_bad_logs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = _record(tmp_path, ROBOT, 0)
    data = _bytes(log)
    cases = {
        "truncated.btlog": (data[:-4], "truncated"),
        "header.btlog": (data[:40], "truncated"),
        "foreign.btlog": (b"\x89PNG\r\n\x1a\n" + data[8:], "not a log"),
        "uid.btlog": (data[:-3] + b"\xff\x7f" + data[-1:], "not in the tree the log embeds"),
        "status.btlog": (data[:-1] + b"\x09", "not a BehaviorTree.CPP NodeStatus"),
        "empty.jsonl": (b"{}\n", "not a fsmbt trace"),
    }
    for name, (content, words) in cases.items():
        bad = tmp_path / name
        bad.write_bytes(content)
        assert main(["conform", str(ROBOT), str(bad)]) == 2, name
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(bad) in err[0] and words in err[0], (name, err)
    other = _record(tmp_path, ROOT / "examples" / "prey_bt.xml", 0, "prey")
    assert main(["conform", str(ROBOT), str(other)]) == 2
    err = capsys.readouterr().err
    assert "another tree" in err and str(other) in err
    broken = tmp_path / "broken.xml"
    broken.write_text("<root BTCPP_format='4'><BehaviorTree", encoding="utf-8")
    assert main(["conform", str(broken), str(log)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "broken.xml" in err[0]


def test_fsm_model_through_leaf_state_mapping(tmp_path: Path) -> None:
    """The tree's logs conform to the state machine converted from it (a state is the leaf
    about to be ticked); a mutant of that FSM is caught on some log."""
    fsm_path = tmp_path / "robot.scxml"
    assert main(["convert", str(ROBOT), "-o", str(fsm_path)]) == 0
    fsm = api.load(fsm_path).model
    logs = [_record(tmp_path, ROBOT, seed) for seed in SEEDS]
    report = conform.conform_files(fsm_path, list(logs))
    assert report.conforms
    seen, total = report.coverage.states
    assert 0 < seen <= total
    caught = 0
    for mutant in mutants(fsm, seed=1, per_operator=2):
        if mutant.operator != "retarget_transition" or verify(fsm, mutant.model).equivalent:
            continue
        result = conform.conform(mutant.model, [conform.read_log(p) for p in logs])
        caught += not result.conforms
    assert caught >= 1
