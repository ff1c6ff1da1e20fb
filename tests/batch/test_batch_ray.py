"""The Ray executor on a private local Ray (loopback, started inside the test): a worker killed
mid-run costs nothing but time, every input gets its result, the store is written once per key.
"""

from __future__ import annotations

import signal
from pathlib import Path

import psutil
import pytest

from fsmbt import api
from fsmbt.batch import JobResult, ResultStore, make_jobs, run_jobs
from support.batch_models import write_models

ray = pytest.importorskip("ray")
pytestmark = pytest.mark.slow


def _ray_workers() -> list[psutil.Process]:
    """Ray's Python worker processes under this test's process (busy ones first).

    A worker is a process titled ``ray::...`` or a Python running ``default_worker.py``. The
    raylet is not one, although its command line names ``default_worker.py`` (in
    ``--python_worker_command``): killing it, as this test once did under load, kills the node
    and every task on it, which is not what the test is about. Nor are its agents, titled
    ``ray::DashboardAgent`` and ``ray::RuntimeEnvAgent`` (killing one takes the raylet down:
    every job then "died 3 times", as the full suite under load once showed)."""
    found = []
    for process in psutil.Process().children(recursive=True):
        try:
            arguments = process.cmdline()
        except psutil.Error:
            continue
        if not arguments:
            continue
        command = " ".join(arguments)
        # a worker's title is ``ray::IDLE`` or its task's; ``ray::DashboardAgent`` and
        # ``ray::RuntimeEnvAgent`` are the raylet's agents, and the raylet dies with them
        titled = command.startswith("ray::") and not command.split()[0].endswith("Agent")
        python_worker = Path(arguments[0]).name.startswith("python") and any(
            argument.endswith("default_worker.py") for argument in arguments[1:3]
        )
        if titled or python_worker:
            found.append((0 if "run_chunk" in command else 1, process))
    return [process for _, process in sorted(found, key=lambda item: item[0])]


def test_a_killed_ray_worker_loses_no_result(tmp_path: Path) -> None:
    write_models(tmp_path / "in", 24)
    jobs = make_jobs([tmp_path / "in"], tmp_path / "out", options={"timeout_s": 60})
    killed: list[int] = []

    def kill_a_worker(result: JobResult) -> None:
        if killed:
            return
        for process in _ray_workers():
            try:
                process.send_signal(signal.SIGKILL)
            except psutil.Error:
                continue
            killed.append(process.pid)
            return

    ray.init(
        num_cpus=2,
        include_dashboard=False,
        _node_ip_address="127.0.0.1",
        logging_level="ERROR",
        log_to_driver=False,
    )
    try:
        with ResultStore(tmp_path / "out") as store:
            results = run_jobs(
                jobs, store=store, executor="ray", workers=2, chunk_size=2, on_result=kill_a_worker
            )
            assert killed, "no Ray worker process was found to kill"
            assert sorted(r.key for r in results) == sorted(j.key for j in jobs)
            assert {r.status for r in results} == {"equivalent"}, [r.error_message for r in results]
            assert len(store.results()) == len(jobs) and store.summary()["pending"] == 0
    finally:
        ray.shutdown()
    for job in jobs:
        written = api.load(job.output or "")
        assert api.verify_either_order(api.load(job.input).model, written.model).equivalent


def test_the_time_limit_holds_in_a_ray_worker(tmp_path: Path) -> None:
    write_models(tmp_path / "in", 2, max_states=30)
    jobs = make_jobs([tmp_path / "in"], tmp_path / "out", options={"timeout_s": 0.001})
    results = run_jobs(jobs, executor="ray", workers=1)  # a private Ray, started and stopped
    assert {r.status for r in results} == {"timeout"}
    assert not ray.is_initialized()
