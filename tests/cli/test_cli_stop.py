"""Clean stops (issue 29, item 2; docs/batch.md and docs/web.md, 'Stopping'): SIGTERM and SIGINT
end ``serve``, ``batch``, ``evaluate`` and ``simulate`` with exit 0 within 5 s of the grace, and
no child process (worker pools, NuSMV, the C++ driver) survives - checked with psutil over the
whole process tree seen while the command ran."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from fsmbt.batch.store import STORE_NAME
from support.web_server import REPO, free_port

#: Seconds after the signal: the command's own grace (3 s) plus the 5 s the issue allows.
STOP_BUDGET_S = 8.0


def _start(*args: str, cwd: Path) -> subprocess.Popen[str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO / "src"), env.get("PYTHONPATH", "")])
    return subprocess.Popen(
        [sys.executable, "-m", "fsmbt.cli", *args],
        cwd=cwd,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def _tree_when(process: subprocess.Popen[str], children: int, seconds: float) -> list:
    """The process's descendants once there are at least ``children`` of them."""
    parent = psutil.Process(process.pid)
    deadline = time.monotonic() + seconds
    seen: dict[int, psutil.Process] = {}
    while time.monotonic() < deadline:
        assert process.poll() is None, process.stderr.read() if process.stderr else ""
        for child in parent.children(recursive=True):
            seen.setdefault(child.pid, child)
        if len(seen) >= children:
            return list(seen.values())
        time.sleep(0.2)
    raise AssertionError(f"only {len(seen)} child processes appeared in {seconds} s")


def _describe(process: psutil.Process) -> str:
    try:
        return f"{process.pid} {process.status()} {' '.join(process.cmdline())[:200]}"
    except psutil.Error as error:
        return f"{process.pid} ({error})"


def _stop_and_check(process: subprocess.Popen[str], tree: list, sig: int) -> None:
    parent = psutil.Process(process.pid)
    tree = {p.pid: p for p in [*tree, *parent.children(recursive=True)]}.values()
    orphans = [_describe(p) for p in tree if p.is_running() and p.ppid() == 1]
    assert orphans == []  # none reparented already
    assert os.getsid(process.pid) == os.getsid(0)
    assert process.poll() is None  # the stop finds the command at work, not already ended
    sent = time.monotonic()
    process.send_signal(sig)
    try:
        code = process.wait(timeout=STOP_BUDGET_S)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        raise AssertionError(f"still running {STOP_BUDGET_S} s after signal {sig}") from None
    _, alive = psutil.wait_procs(
        list(tree), timeout=max(0.1, sent + STOP_BUDGET_S - time.monotonic())
    )
    survivors = [(p.pid, p.name()) for p in alive]
    for p in alive:
        p.kill()
    assert code == 0, process.stderr.read() if process.stderr else code
    assert survivors == []
    for p in tree:  # nothing was started in a session of its own
        assert not p.is_running()


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_serve_stops_with_its_workers(tmp_path, sig):
    process = _start("serve", "--port", str(free_port()), "--workers", "2", cwd=tmp_path)
    tree = _tree_when(process, 2, 60)
    _stop_and_check(process, tree, sig)


#: Models in the stopped batch: about 30 s of work on 2 workers, so the signal sent 3 s in
#: always finds the run going (120 models took 3.4 s, and the race made the test flaky).
MANY_MODELS = 1000


@pytest.fixture(scope="module")
def many_models(tmp_path_factory) -> Path:
    from fsmbt.formats import dumps
    from fsmbt.generate.generator import random_fsm

    folder = tmp_path_factory.mktemp("models")
    for index in range(MANY_MODELS):
        fsm = random_fsm(seed=f"stop-{index}", n_states=12, max_states=12)
        (folder / f"m{index:03d}.scxml").write_text(dumps(fsm, "scxml"), encoding="utf-8")
    return folder


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_batch_stops_and_records_what_finished(tmp_path, many_models, sig):
    out = tmp_path / "out"
    args = ("batch", str(many_models), "-o", str(out), "-j", "2", "-q", "--verifier", "both")
    process = _start(*args, cwd=tmp_path)
    tree = _tree_when(process, 2, 60)
    time.sleep(3.0)  # mid-run: jobs claimed and out
    _stop_and_check(process, tree, sig)
    with sqlite3.connect(out / STORE_NAME) as db:
        rows = db.execute("SELECT key, state FROM results").fetchall()
    assert len(rows) == len({key for key, _ in rows})  # no row twice
    assert {state for _, state in rows} <= {"pending", "done"}
    # every job handed out is in the store: done (finished within the grace or before), or
    # pending (interrupted; the next run resumes it)
    assert rows


def test_evaluate_stops_with_its_workers(tmp_path):
    process = _start(
        "evaluate",
        "--quick",
        "-o",
        str(tmp_path / "ev"),
        "--workers",
        "2",
        "--examples",
        str(REPO / "examples"),
        cwd=tmp_path,
    )
    tree = _tree_when(process, 2, 90)
    _stop_and_check(process, tree, signal.SIGTERM)


def test_simulate_stops(tmp_path):
    process = _start(
        "simulate",
        "robot",
        str(REPO / "examples" / "robot_bt.xml"),
        "--episodes",
        "100000",
        cwd=tmp_path,
    )
    time.sleep(4.0)
    assert process.poll() is None
    _stop_and_check(process, [], signal.SIGTERM)
