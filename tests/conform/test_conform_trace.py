"""The py_trees trace (JSON lines): written while py_trees runs a tree with scripted leaves,
read back, replayed; a trace of a mutated tree is caught at the swapped node."""

from __future__ import annotations

import json
import random
from pathlib import Path

import pytest

from fsmbt import api, conform
from fsmbt.cli import main
from fsmbt.model.bt import BTNode

pytest.importorskip("py_trees")
from fsmbt.conform.trace import TracedPyTreesRunner  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "examples" / "robot_bt.xml"
SWAP = ("<RobotAtInspection/>\n        <Dock/>", "<Dock/>\n        <RobotAtInspection/>")


def _trace(doc: api.Model, path: Path, seed: int, ticks: int = 40) -> Path:
    rng = random.Random(seed)

    def env(node: BTNode, _path: str) -> str:
        kind = node.kind.value
        return rng.choice(
            ("success", "failure", "running") if kind == "action" else ("success", "failure")
        )

    with path.open("w", encoding="utf-8") as stream:
        runner = TracedPyTreesRunner(doc, env, stream)
        for _ in range(ticks):
            runner.tick_once()
    return path


def test_trace_conforms_and_mutant_is_caught(tmp_path: Path) -> None:
    model = api.load(ROBOT).model
    traces = [_trace(model, tmp_path / f"t{s}.jsonl", s) for s in range(4)]
    assert main(["conform", str(ROBOT), *map(str, traces)]) == 0
    header = json.loads(traces[0].read_text(encoding="utf-8").splitlines()[0])
    assert header["fsmbt_trace"] == 1 and header["engine"] == "py_trees"
    swapped = tmp_path / "swapped.xml"
    swapped.write_text(ROBOT.read_text(encoding="utf-8").replace(*SWAP), encoding="utf-8")
    mutant = api.load(swapped).model
    found = []
    for s in range(4):
        trace = _trace(mutant, tmp_path / f"m{s}.jsonl", s)
        assert conform.conform_files(swapped, [trace]).conforms
        [result] = conform.conform_files(ROBOT, [trace]).results
        if result.deviation is not None:
            found.append(result.deviation)
    assert found and all(d.node == "Dock@2/0" for d in found)


def test_bad_traces(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    good = _trace(api.load(ROBOT).model, tmp_path / "good.jsonl", 0, ticks=3)
    lines = good.read_text(encoding="utf-8").splitlines()
    cases = {
        "notjson.jsonl": (lines[0] + "\n{oops\n", ":2:"),
        "uid.jsonl": (lines[0] + '\n{"t": 1, "uid": 999, "status": "SUCCESS"}\n', ":2:"),
        "status.jsonl": (lines[0] + '\n{"t": 1, "uid": 2, "status": "DONE"}\n', ":2:"),
    }
    for name, (text, where) in cases.items():
        bad = tmp_path / name
        bad.write_text(text, encoding="utf-8")
        assert main(["conform", str(ROBOT), str(bad)]) == 2, name
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"{bad}{where}" in err[0], (name, err)
