"""CI's fuzz budget: a short, seeded atheris run of every reader finds nothing.

Runs fuzz/fuzz_readers.py as a user would (one subprocess per reader batch, memory cap, per-input
alarm), 800 inputs per reader (2 000 with ``FSMBT_FULL_SUITES=1``) with a fixed seed, into a temporary working corpus and
regression folder, and checks the printed table: one row per reader of the format registry,
every budgeted iteration run, no crash, timeout or memory finding. About 3 s per reader.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt.formats import formats
from support.fuzz_harness_loader import ROOT, SCRIPT
from support.sampling import full

#: 800 inputs per reader in CI's budget (every reader of the registry: 17), 2 000 with
#: FSMBT_FULL_SUITES=1
ITERATIONS = 2_000 if full() else 800
SEED = 18

pytest.importorskip("atheris")


def test_seeded_fuzz_budget_of_every_reader_finds_nothing(tmp_path: Path) -> None:
    figures = tmp_path / "figures.json"
    regressions = tmp_path / "regressions"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.run(
        [
            sys.executable,
            str(SCRIPT),
            "--iterations",
            str(ITERATIONS),
            "--reader",
            "all",
            "--seed",
            str(SEED),
            "--batch",
            str(ITERATIONS),
            "--timeout-per-input",
            "5",
            "--work-dir",
            str(tmp_path / "work"),
            "--regressions",
            str(regressions),
            "--json",
            str(figures),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=900,
    )
    print(proc.stdout)
    rows = {row["reader"]: row for row in json.loads(figures.read_text(encoding="utf-8"))}
    assert set(rows) == {f.name for f in formats() if f.read is not None}
    for reader, row in rows.items():
        assert row["iterations"] == ITERATIONS, reader
        assert row["seeds"] > 0, f"{reader}: no seed inputs"
        assert row["cov"] > 0, f"{reader}: no coverage reported (instrumentation off?)"
    saved = sorted(str(p.relative_to(regressions)) for p in regressions.rglob("*.cause"))
    causes = [p.read_text(encoding="utf-8") for p in regressions.rglob("*.cause")]
    assert proc.returncode == 0 and not saved, f"findings: {saved} {causes}\n{proc.stderr[-2000:]}"


def test_the_harness_reports_crashes_timeouts_and_memory_and_saves_the_inputs(
    tmp_path: Path,
) -> None:
    """The fuzz script against a reader with planted bugs: each kind of finding is counted and
    its input saved with its cause, and the run goes on past each one (no finding stops it)."""
    figures = tmp_path / "figures.json"
    regressions = tmp_path / "regressions"
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(Path(__file__).parent)])
    )
    proc = subprocess.run(
        [
            sys.executable,
            str(SCRIPT),
            "--import",
            "planted_reader",
            "--reader",
            "planted-bug",
            "--iterations",
            "2000",
            "--seed",
            "1",
            "--timeout-per-input",
            "0.05",
            "--memory-mb",
            "1024",
            "--hard-timeout",
            "2",
            "--batch",
            "1000",
            "--work-dir",
            str(tmp_path / "work"),
            "--regressions",
            str(regressions),
            "--json",
            str(figures),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    (row,) = json.loads(figures.read_text(encoding="utf-8"))
    assert proc.returncode == 1, proc.stderr[-2000:]  # findings: exit 1
    assert row["iterations"] == 2000
    assert row["crashes"] > 0 and row["timeouts"] > 0 and row["memory"] > 0, row
    causes = {
        p.stem.split("-")[0]: p.read_text(encoding="utf-8")
        for p in (regressions / "planted-bug").glob("*.cause")
    }
    assert "KeyError at " in causes["crash"] and "planted" in causes["crash"]
    assert "no answer within 0.05 s" in causes["timeout"]
    assert "MemoryError" in causes["memory"]
    hard = [
        p.read_text(encoding="utf-8")
        for p in (regressions / "planted-bug").glob("*.cause")
        if "hard timeout" in p.read_text(encoding="utf-8")
    ]
    assert hard, "the sleeping input was not caught by the wall-clock alarm"
    for kind in ("crash", "timeout", "memory"):
        saved = [p.read_bytes() for p in (regressions / "planted-bug").glob(f"{kind}-*.input")]
        trigger = {"crash": b"!", "timeout": b"~", "memory": b"^"}[kind]
        assert any(trigger in data for data in saved), kind
