"""The Ray executor against a real cluster of two raylets on loopback, started by the test with
the ``ray`` command (``ray start --head`` and a second node joining it), the second node
killed mid-run while it runs a chunk (its raylet, then its workers): every input still has exactly one result in the store, all equivalent,
none delivered twice, and no process of the cluster survives the test.

Every process the two ``ray start`` commands leave behind (GCS, raylets, agents, workers)
carries this test's mark in its environment; the cleanup kills exactly those, never another
Ray on the machine (``ray stop --force`` would stop every Ray of the user, other sessions'
too). Token authentication is off for this loopback-only cluster (``RAY_AUTH_MODE``), so the
test does not depend on a token in the home folder.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import uuid
from collections import Counter
from pathlib import Path

import psutil
import pytest

from fsmbt import api
from fsmbt.batch import JobResult, ResultStore, make_jobs, run_jobs
from support.batch_models import write_models

ray = pytest.importorskip("ray")
pytestmark = pytest.mark.slow

RAY = Path(sys.executable).with_name("ray")
MARK = "FSMBT_TEST_RAY_CLUSTER"
#: Faster detection of a dead node than Ray's defaults (the GCS's health checks).
FAST_FAILURE = {
    "RAY_health_check_initial_delay_ms": "0",
    "RAY_health_check_period_ms": "500",
    "RAY_health_check_timeout_ms": "500",
    "RAY_health_check_failure_threshold": "2",
}


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _marked(prefix: str) -> list[psutil.Process]:
    """This machine's processes whose environment carries ``MARK`` starting with ``prefix``."""
    found = []
    for process in psutil.process_iter():
        try:
            if process.environ().get(MARK, "").startswith(prefix):
                found.append(process)
        except psutil.Error:
            continue
    return found


def _ray_start(arguments: list[str], mark: str, temp: Path) -> None:
    env = {**os.environ, **FAST_FAILURE, MARK: mark, "RAY_USAGE_STATS_ENABLED": "0"}
    done = subprocess.run(
        [str(RAY), "start", *arguments, "--num-cpus=1", "--node-ip-address=127.0.0.1"]
        + ["--object-store-memory=100000000", "--disable-usage-stats"],
        env=env,
        cwd=temp,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-3000:]


def _busy_worker(processes: list[psutil.Process]) -> bool:
    for process in processes:
        try:
            if " ".join(process.cmdline()).startswith("ray::run_chunk"):
                return True
        except psutil.Error:
            continue
    return False


def test_a_killed_node_of_a_two_raylet_cluster_loses_and_duplicates_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("RAY_AUTH_MODE", "disabled")
    monkeypatch.setenv("RAY_USAGE_STATS_ENABLED", "0")
    write_models(tmp_path / "in", 60, max_states=12)
    jobs = make_jobs([tmp_path / "in"], tmp_path / "out", options={"timeout_s": 60})
    run = uuid.uuid4().hex
    temp = Path(tempfile.mkdtemp(prefix="fsmbt-ray-"))  # short: Ray's socket paths fit
    port = _free_port()
    killed: list[int] = []

    def kill_the_second_node(_result: JobResult) -> None:
        if killed:
            return
        second = _marked(f"{run}-node2")
        if not _busy_worker(second):
            return  # wait until the second node is running a chunk
        # the node dies as a machine would: its raylet first, then every process on it (a
        # worker alone outlives its raylet long enough to hand a small result back)
        second.sort(key=lambda process: process.name() != "raylet")
        for process in second:
            try:
                process.send_signal(signal.SIGKILL)
            except psutil.Error:
                continue
            killed.append(process.pid)

    try:
        _ray_start(
            ["--head", f"--port={port}", "--include-dashboard=false", f"--temp-dir={temp}"],
            f"{run}-head",
            temp,
        )
        _ray_start([f"--address=127.0.0.1:{port}"], f"{run}-node2", temp)
        assert any(p.name() == "raylet" for p in _marked(f"{run}-node2"))
        with ResultStore(tmp_path / "out") as store:
            results = run_jobs(
                jobs,
                store=store,
                executor="ray",
                ray_address=f"127.0.0.1:{port}",
                workers=2,
                chunk_size=3,
                on_result=kill_the_second_node,
            )
            assert killed, "the second node never ran a chunk while results came in"
            assert not ray.is_initialized()  # the executor disconnected
            delivered = Counter(r.key for r in results)
            assert sorted(delivered) == sorted(j.key for j in jobs)
            assert set(delivered.values()) == {1}  # none delivered twice
            assert {r.status for r in results} == {"equivalent"}, [r.error_message for r in results]
            rows = store.results()
            assert sorted(r.key for r in rows) == sorted(j.key for j in jobs)
            assert store.summary()["pending"] == 0
    finally:
        if ray.is_initialized():
            ray.shutdown()
        leftovers = _marked(run)
        for process in leftovers:
            try:
                process.kill()
            except psutil.Error:
                continue
        _gone, alive = psutil.wait_procs(leftovers, timeout=15)
        shutil.rmtree(temp, ignore_errors=True)
    assert alive == [] and _marked(run) == []  # nothing of the cluster survives
    for job in jobs:
        written = api.load(job.output or "")
        assert api.verify_either_order(api.load(job.input).model, written.model).equivalent
