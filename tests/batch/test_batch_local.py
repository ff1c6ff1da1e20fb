"""The local executor and the driver: resume skips what is done, a killed worker loses nothing,
back-pressure bounds the jobs out, the limits re-run only what they cut short."""

from __future__ import annotations

import multiprocessing
import os
import signal
from pathlib import Path

from fsmbt import api
from fsmbt.batch import JobResult, ResultStore, make_jobs, run_jobs
from support.batch_models import write_models


def test_a_second_run_skips_every_finished_input(tmp_path: Path) -> None:
    write_models(tmp_path / "in", 6)
    jobs = make_jobs([tmp_path / "in"], tmp_path / "out")
    with ResultStore(tmp_path / "out") as store:
        first = run_jobs(jobs, store=store, workers=2)
        assert sorted(r.key for r in first) == sorted(j.key for j in jobs)
        assert {r.status for r in first} == {"equivalent"}
        assert run_jobs(jobs, store=store, workers=2) == []
        assert len(store.results()) == len(jobs)


def test_a_killed_worker_loses_no_result(tmp_path: Path) -> None:
    write_models(tmp_path / "in", 16)
    jobs = make_jobs([tmp_path / "in"], tmp_path / "out")
    before = {p.pid for p in multiprocessing.active_children()}
    killed: list[int] = []

    def kill_one(result: JobResult) -> None:
        if killed:
            return
        workers = [
            p.pid
            for p in multiprocessing.active_children()
            if p.pid is not None and p.pid not in before
        ]
        if workers:
            os.kill(workers[0], signal.SIGKILL)
            killed.append(workers[0])

    with ResultStore(tmp_path / "out") as store:
        results = run_jobs(jobs, store=store, workers=2, on_result=kill_one)
        assert killed, "no worker process was found to kill"
        assert sorted(r.key for r in results) == sorted(j.key for j in jobs)
        assert {r.status for r in results} == {"equivalent"}, [r.error_message for r in results]
        assert any(r.attempts > 1 for r in results)  # the jobs that were out ran again
        assert len(store.results()) == len(jobs) and store.summary()["pending"] == 0
    for job in jobs:
        assert api.load(job.output or "").kind in ("fsm", "bt")


def test_rows_cut_short_by_a_limit_run_again_only_with_a_larger_limit(tmp_path: Path) -> None:
    write_models(tmp_path / "in", 2, max_states=20)
    out = tmp_path / "out"
    with ResultStore(out) as store:
        tight = make_jobs([tmp_path / "in"], out, options={"max_states": 2})
        assert {r.status for r in run_jobs(tight, store=store)} == {"limit"}
        assert run_jobs(tight, store=store) == []  # the same limit: nothing to do again
        loose = make_jobs([tmp_path / "in"], out, options={"max_states": 100_000})
        assert [j.key for j in loose] == [j.key for j in tight]
        assert {r.status for r in run_jobs(loose, store=store)} == {"equivalent"}
        assert len(store.results()) == 2


def test_an_existing_output_is_a_refused_row_and_force_replaces_it(tmp_path: Path) -> None:
    write_models(tmp_path / "in", 2, nested=False)
    out = tmp_path / "out"
    jobs = make_jobs([tmp_path / "in"], out)
    taken = Path(jobs[0].output or "")
    taken.parent.mkdir(parents=True)
    taken.write_text("the user's file", encoding="utf-8")
    with ResultStore(out) as store:
        results = {r.key: r for r in run_jobs(jobs, store=store)}
        assert results[jobs[0].key].status == "refused"
        assert results[jobs[0].key].error_class == "DestinationExists"
        assert taken.read_text(encoding="utf-8") == "the user's file"
        assert results[jobs[1].key].status == "equivalent"
        forced = make_jobs([tmp_path / "in"], out, overwrite=True)
        again = run_jobs(forced, store=store)  # the refused row is retryable, the other done
        assert [r.key for r in again] == [jobs[0].key] and again[0].status == "equivalent"
        source = api.load(jobs[0].input).model
        assert api.verify_either_order(source, api.load(taken).model).equivalent


def test_a_claimed_job_replaces_its_own_output_and_stale_temporaries(tmp_path: Path) -> None:
    """The driver died after the worker wrote (or half-wrote) and before the row was stored."""
    write_models(tmp_path / "in", 1, nested=False)
    out = tmp_path / "out"
    [job] = make_jobs([tmp_path / "in"], out)
    output = Path(job.output or "")
    output.parent.mkdir(parents=True)
    output.write_text("left by the killed run", encoding="utf-8")
    stale = output.parent / f".{output.name}.abc123.tmp"
    stale.write_text("half a fi", encoding="utf-8")
    with ResultStore(out) as store:
        store.claim([job])  # what the killed run had committed
        [result] = run_jobs([job], store=store)
        assert result.status == "equivalent" and len(store.results()) == 1
    assert not stale.exists()
    source = api.load(job.input).model
    assert api.verify_either_order(source, api.load(output).model).equivalent
