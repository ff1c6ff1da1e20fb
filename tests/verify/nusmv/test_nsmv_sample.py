"""The issue's sample in one run (benchmarks/bench_nusmv_sample.py; docs/nusmv.md, "One run: the
issue's sample"): its ``--quick`` smoke sample with real NuSMV - every kind of pair (FSM ~ FSM,
FSM ~ dispatch, trees node by node, trees by macro steps, structured pairs) decided by both
engines, none disagreeing, none past the budget (a per-node mutant the native walk does not
decompose has no local check for NuSMV: *not asked*, and only those); and the per-pair budget itself: a pair past it
is counted as *gave up* and its processes (NuSMV's too) are killed, not left running."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
import bench_nusmv_sample as sample  # noqa: E402


def test_quick_sample_agrees_on_every_pair(nusmv_binary, monkeypatch, capsys) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    assert sample.main(["--quick"]) == 0
    out = capsys.readouterr().out
    rows = [line.split(" | ") for line in out.splitlines() if not line.startswith("#")]
    rows = [r for r in rows if len(r) == 8]
    kinds = {r[0] for r in rows}
    assert kinds == set(sample.KINDS), kinds  # every kind of the sample is in it
    # every pair NuSMV was asked about agrees; the only others are per-node mutants the native
    # walk did not decompose (no local check to give NuSMV), named as such
    asked = [r for r in rows if r[4] != sample.NOT_ASKED]
    assert {r[4] for r in asked} == {sample.AGREE}, [r for r in asked if r[4] != sample.AGREE]
    assert all(r[0] == "pernode" and r[3] == "not decomposed" for r in rows if r not in asked)
    assert any(r[0] == "pernode" and r[2] == "mutant" for r in asked)
    assert {r[2] for r in rows} == {"copy", "mutant"}
    assert any(r[3] == "not equivalent" for r in rows)  # failing pairs are compared too
    total = next(line for line in out.splitlines() if line.startswith("total"))
    pairs, agree, disagree, gave_up, refused = (int(x) for x in total.split()[1:6])
    assert pairs == len(rows) and agree == len(asked) and disagree == gave_up == refused == 0


def test_a_pair_past_the_budget_gave_up_and_its_processes_are_killed(tmp_path) -> None:
    marker = tmp_path / "pid"

    def slow() -> tuple[str, str]:
        child = subprocess.Popen(["sleep", "30"])  # stands for a NuSMV run
        marker.write_text(str(child.pid))
        child.wait()
        return sample.AGREE, ""

    started = time.perf_counter()
    outcome, detail, _cpu, wall = sample.within(1.0, slow)
    assert outcome == sample.GAVE_UP and "budget" in detail
    assert 1.0 <= wall < 5.0 and time.perf_counter() - started < 5.0
    pid = int(marker.read_text())
    time.sleep(0.2)
    status = Path(f"/proc/{pid}/stat")
    assert not status.exists() or status.read_text().split()[2] == "Z"  # gone (or reaped soon)


def test_outcomes_inside_the_budget_are_passed_back() -> None:
    assert sample.within(10.0, lambda: (sample.DISAGREE, "x"))[:2] == (sample.DISAGREE, "x")

    def broken() -> tuple[str, str]:
        raise KeyError("where")

    outcome, detail, _cpu, _wall = sample.within(10.0, broken)
    assert outcome == sample.ERROR and "KeyError" in detail
