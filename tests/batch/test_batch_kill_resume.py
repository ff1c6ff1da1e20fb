"""``fsmbt batch`` killed with SIGKILL mid-run, then run again: every input has exactly one row,
the rows finished before the kill are kept as they were, every output is complete and verifies.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import psutil

from fsmbt import api
from fsmbt.batch import STORE_NAME
from support.batch_models import write_models

SRC = Path(__file__).resolve().parents[2] / "src"


def _batch(args: list[str]) -> subprocess.Popen[bytes]:
    env = {**os.environ, "PYTHONPATH": f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    return subprocess.Popen(
        [sys.executable, "-m", "fsmbt.cli", "batch", *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )


def _done_rows(store: Path) -> dict[str, float]:
    if not store.exists():
        return {}
    try:
        with sqlite3.connect(f"file:{store}?mode=ro", uri=True, timeout=5) as db:
            return dict(db.execute("SELECT key, finished_at FROM results WHERE state = 'done'"))
    except sqlite3.OperationalError:  # the tables are not created yet
        return {}


def test_sigkill_mid_run_then_resume_loses_and_duplicates_nothing(tmp_path: Path) -> None:
    inputs = write_models(tmp_path / "in", 60)
    out = tmp_path / "out"
    store = out / STORE_NAME
    run = _batch([str(tmp_path / "in"), "-o", str(out), "-j", "2", "--quiet"])
    deadline = time.monotonic() + 180
    while len(_done_rows(store)) < 5:
        assert run.poll() is None, run.communicate()
        assert time.monotonic() < deadline, "the batch stored no result in time"
        time.sleep(0.05)
    workers = psutil.Process(run.pid).children(recursive=True)
    run.send_signal(signal.SIGKILL)
    run.wait(timeout=30)
    _gone, alive = psutil.wait_procs(workers, timeout=30)  # orphans finish or notice
    for process in alive:
        process.kill()
    before = _done_rows(store)
    assert 5 <= len(before) < len(inputs), "the kill came too late to test anything"

    resumed = _batch([str(tmp_path / "in"), "-o", str(out), "-j", "2", "--quiet", "--json"])
    stdout, stderr = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, stderr.decode()
    with sqlite3.connect(store) as db:
        rows = db.execute(
            "SELECT input, state, status, output, key, finished_at FROM results"
        ).fetchall()
    assert sorted(row[0] for row in rows) == sorted(str(p) for p in inputs)  # one row each
    assert {row[1] for row in rows} == {"done"} and {row[2] for row in rows} == {"equivalent"}
    after = {row[4]: row[5] for row in rows}
    assert all(after[key] == finished for key, finished in before.items())  # kept, not redone
    for source, _state, _status, output, _key, _at in rows:
        result = api.load(output)  # complete: it reads back
        assert api.verify_either_order(api.load(source).model, result.model).equivalent
    leftovers = [p for p in out.rglob("*") if p.name.endswith(".tmp")]
    assert leftovers == []
