"""The local executor: a pool of worker processes on this machine.

Rules:

- ``concurrent.futures.ProcessPoolExecutor`` with the ``spawn`` start method (a clean
  interpreter per worker, nothing of the driver's state inherited) and ``max_tasks_per_child``,
  so a worker whose memory grew on a large model is replaced after a bounded number of jobs.
- Back-pressure: at most ``2 * workers`` jobs are out at once; the rest wait in the driver as
  ``Job`` values (small), so memory stays bounded for any number of inputs.
- Worker death (SIGKILL, the OOM killer, a crash in C code): the pool breaks; every job that was
  out goes back to the queue with one more attempt, a new pool starts, and a job that was out at
  ``max_attempts`` deaths becomes an ``error`` row of class ``WorkerDied`` (run again on resume).
- Watchdog: a job out longer than twice its time limit plus ``WATCHDOG_GRACE_S`` (a model stuck
  where ``SIGALRM`` cannot reach) gets a ``timeout`` row; the pool's processes are killed and
  the other jobs go back to the queue without losing an attempt.

- Stop (SIGINT, or SIGTERM turned into one by ``fsmbt.cli.stopping``): the workers ignore
  SIGINT (the driver decides); the driver gives the jobs that are out ``STOP_GRACE_S`` to
  finish and stores those results, then kills the workers. Jobs still out stay ``pending`` in
  the store (interrupted): the next run resumes them. Nothing outlives the driver.

Costs: one process start per worker (and per ``max_tasks_per_child`` jobs); one pickled job and
result per input.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
from collections import deque
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from fsmbt.batch.jobs import Job, public_options
from fsmbt.batch.result import ERROR, TIMEOUT, JobResult
from fsmbt.batch.worker import run_job, warm_up

#: Seconds a job may run past twice its time limit before the watchdog kills its worker.
WATCHDOG_GRACE_S = 30.0
#: Seconds the jobs that are out get to finish when the run is stopped (SIGINT / SIGTERM).
STOP_GRACE_S = 3.0
#: Jobs a worker process runs before it is replaced.
MAX_TASKS_PER_CHILD = 500

Deliver = Callable[[JobResult], None]
Claim = Callable[[list[Job]], None]


def worker_died(job: Job, attempts: int) -> JobResult:
    """The row of a job whose worker died ``attempts`` times."""
    return JobResult(
        job.key,
        job.input,
        ERROR,
        error_class="WorkerDied",
        error_message=f"{job.input}: the worker process died {attempts} time(s) "
        "while converting this input",
        engine=job.engine,
        verify_engine=job.verify_engine,
        options=public_options(job.options),
        attempts=attempts,
        retry=True,
    )


def overran(job: Job, seconds: float) -> JobResult:
    """The row of a job the watchdog stopped after ``seconds``."""
    return JobResult(
        job.key,
        job.input,
        TIMEOUT,
        error_class="JobTimeout",
        error_message=f"{job.input}: no result after {seconds:.0f} s; the worker was stopped",
        timings={"total": seconds},
        engine=job.engine,
        verify_engine=job.verify_engine,
        options=public_options(job.options),
    )


def descendants(pid: int) -> list[int]:
    """The processes started under ``pid`` (a worker's NuSMV or C++ child), read from Linux's
    ``/proc/PID/task/TID/children``; empty where that does not exist. An explicit work list,
    children before grandchildren. Read before the kill, so none is left orphaned."""
    found: list[int] = []
    todo = [pid]
    while todo:
        current = todo.pop()
        tasks = Path(f"/proc/{current}/task")
        try:
            entries = list(tasks.iterdir())
        except OSError:
            continue
        for task in entries:
            try:
                children = (task / "children").read_text().split()
            except OSError:
                continue
            for child in children:
                if child.isdigit():
                    found.append(int(child))
                    todo.append(int(child))
    return found


def _start_worker() -> None:
    """Worker start: ignore SIGINT (Ctrl-C reaches the whole process group; the driver stops
    the workers itself), then warm up."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    warm_up()


def _hard_deadline(job: Job) -> float | None:
    limit = job.options.get("timeout_s")
    return 2.0 * float(limit) + WATCHDOG_GRACE_S if limit else None


class LocalExecutor:
    """Runs jobs on a process pool (see the module text).

    Args:
        workers: worker processes (at least 1).
        max_attempts: worker deaths a job may see before its row says so.
        max_tasks_per_child: jobs per worker process before it is replaced.
    """

    def __init__(
        self,
        workers: int = 1,
        *,
        max_attempts: int = 3,
        max_tasks_per_child: int = MAX_TASKS_PER_CHILD,
    ) -> None:
        self.workers = max(1, workers)
        self.max_attempts = max(1, max_attempts)
        self.max_tasks_per_child = max_tasks_per_child
        self._context = multiprocessing.get_context("spawn")
        self._before = {p.pid for p in multiprocessing.active_children()}
        self.worker_pids: set[int] = set()

    def _pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=self._context,
            max_tasks_per_child=self.max_tasks_per_child,
            initializer=_start_worker,
        )

    def _pool_pids(self) -> list[int]:
        pids = [
            p.pid
            for p in multiprocessing.active_children()
            if p.pid is not None and p.pid not in self._before
        ]
        self.worker_pids.update(pids)
        return pids

    def _kill(self, pool: ProcessPoolExecutor) -> None:
        pids = self._pool_pids()
        for victim in [*pids, *(child for worker in pids for child in descendants(worker))]:
            try:
                os.kill(victim, signal.SIGKILL)
            except ProcessLookupError:
                pass
        pool.shutdown(wait=True, cancel_futures=True)

    def run(self, jobs: Iterable[Job], deliver: Deliver, claim: Claim) -> None:
        """Run every job; ``deliver`` each result as it arrives.

        Args:
            jobs: the jobs to run.
            deliver: called in this process with each result (the driver stores it).
            claim: called with each group of jobs just before they are handed out.
        """
        queue: deque[tuple[Job, int]] = deque((job, 0) for job in jobs)
        out: dict[Future[JobResult], tuple[Job, int, float]] = {}
        limit = 2 * self.workers
        pool = self._pool()
        try:
            while queue or out:
                batch: list[tuple[Job, int]] = []
                while queue and len(out) + len(batch) < limit:
                    batch.append(queue.popleft())
                if batch:
                    claim([job for job, _ in batch])
                    for job, attempts in batch:
                        out[pool.submit(run_job, job)] = (job, attempts + 1, time.monotonic())
                finished, _ = wait(list(out), timeout=0.5, return_when=FIRST_COMPLETED)
                broken = False
                for future in finished:
                    job, attempts, _started = out.pop(future)
                    try:
                        result = future.result()
                    except BrokenProcessPool:
                        broken = True
                        self._requeue(queue, deliver, job, attempts)
                        continue
                    result.attempts = attempts
                    deliver(result)
                now = time.monotonic()
                overdue = [
                    future
                    for future, (job, _, started) in out.items()
                    if (deadline := _hard_deadline(job)) is not None and now - started > deadline
                ]
                if overdue:
                    for future in overdue:
                        job, _, started = out.pop(future)
                        deliver(overran(job, now - started))
                if broken or overdue:
                    victims = list(out.values())
                    out.clear()
                    for job, attempts, _ in reversed(victims):
                        if broken:
                            self._requeue(queue, deliver, job, attempts)
                        else:
                            queue.appendleft((job, attempts - 1))
                    self._kill(pool)
                    pool = self._pool()
                else:
                    self._pool_pids()
        except BaseException:
            self._stop(pool, out, deliver)
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)

    def _stop(
        self,
        pool: ProcessPoolExecutor,
        out: dict[Future[JobResult], tuple[Job, int, float]],
        deliver: Deliver,
    ) -> None:
        """The run is stopped: store what finishes within ``STOP_GRACE_S``, kill the workers.
        A second signal during the grace ends the grace, not the cleanup."""
        try:
            finished, _ = wait(list(out), timeout=STOP_GRACE_S)
            for future in finished:
                job, attempts, _started = out.pop(future)
                try:
                    result = future.result()
                except BaseException:  # noqa: BLE001 - a broken pool: the row stays pending
                    continue
                result.attempts = attempts
                deliver(result)
        except BaseException:  # noqa: BLE001 - a second Ctrl-C: go straight to the kill
            pass
        finally:
            self._kill(pool)

    def _requeue(
        self, queue: deque[tuple[Job, int]], deliver: Deliver, job: Job, attempts: int
    ) -> None:
        if attempts >= self.max_attempts:
            deliver(worker_died(job, attempts))
        else:
            queue.appendleft((job, attempts))
