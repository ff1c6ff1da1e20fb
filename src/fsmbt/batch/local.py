"""The local executor: a pool of worker processes on this machine.

Rules:

- ``concurrent.futures.ProcessPoolExecutor`` with the ``spawn`` start method (a clean
  interpreter per worker, nothing of the driver's state inherited) and ``max_tasks_per_child``,
  so a worker whose memory grew on a large model is replaced after a bounded number of jobs.
- Chunks: a task is several jobs (``worker.run_chunk``), ``waiting / (4 * workers)`` of them
  between 1 and ``MAX_CHUNK`` (16): one pickled round trip, one wake-up of the driver and one
  store transaction per chunk instead of per job, and single jobs at the end so no worker
  idles while another finishes a long chunk. Each job keeps its own time limit and row.
- Back-pressure: at most ``2 * workers`` chunks are out at once; the rest wait in the driver as
  ``Job`` values (small), so memory stays bounded for any number of inputs.
- Worker death (SIGKILL, the OOM killer, a crash in C code): the pool breaks; every job that was
  out goes back to the queue with one more attempt, a new pool starts, and a job that was out at
  ``max_attempts`` deaths becomes an ``error`` row of class ``WorkerDied`` (run again on resume).
  A job that went back runs alone from then on (one input that kills its worker cannot use up
  the attempts of the jobs it shared a chunk with more than once).
- Watchdog: a chunk out longer than twice its jobs' time limits plus ``WATCHDOG_GRACE_S`` (a
  model stuck where ``SIGALRM`` cannot reach) is stopped: a single job gets a ``timeout`` row,
  the jobs of a longer chunk go back to run alone; the pool's processes are killed and the
  other jobs go back to the queue without losing an attempt.
- End: once every result is in, the idle workers are killed, not left to tear their
  interpreters down (a second or more of wall time after a few hundred jobs).

- Stop (SIGINT, or SIGTERM turned into one by ``fsmbt.cli.stopping``): the workers ignore
  SIGINT (the driver decides); the driver gives the jobs that are out ``STOP_GRACE_S`` to
  finish and stores those results, then kills the workers. Jobs still out stay ``pending`` in
  the store (interrupted): the next run resumes them. Nothing outlives the driver.

Costs: one process start per worker (and per ``max_tasks_per_child`` jobs); one pickled task
and one store transaction per chunk.
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
from fsmbt.batch.worker import run_chunk, warm_up

#: Seconds a job may run past twice its time limit before the watchdog kills its worker.
WATCHDOG_GRACE_S = 30.0
#: Seconds the jobs that are out get to finish when the run is stopped (SIGINT / SIGTERM).
STOP_GRACE_S = 3.0
#: Jobs a worker process runs before it is replaced.
MAX_TASKS_PER_CHILD = 500

#: Jobs per pool task at most (``LocalExecutor.chunk_size``).
MAX_CHUNK = 16

Deliver = Callable[[list[JobResult]], None]
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


def _hard_deadline(chunk: list[tuple[Job, int]]) -> float | None:
    """Seconds a chunk may be out: twice the sum of its jobs' limits plus the grace (``None``
    when a job has no limit)."""
    limits = [job.options.get("timeout_s") for job, _ in chunk]
    if not all(limits):
        return None
    return 2.0 * sum(float(limit) for limit in limits if limit) + WATCHDOG_GRACE_S


class LocalExecutor:
    """Runs jobs on a process pool (see the module text).

    Args:
        workers: worker processes (at least 1).
        max_attempts: worker deaths a job may see before its row says so.
        max_tasks_per_child: jobs per worker process before it is replaced (at most; counted
            in full chunks).
        max_chunk: jobs per task at most (1: one job per task).
    """

    def __init__(
        self,
        workers: int = 1,
        *,
        max_attempts: int = 3,
        max_tasks_per_child: int = MAX_TASKS_PER_CHILD,
        max_chunk: int = MAX_CHUNK,
    ) -> None:
        self.workers = max(1, workers)
        self.max_attempts = max(1, max_attempts)
        self.max_chunk = max(1, max_chunk)
        self.max_tasks_per_child = max(1, max_tasks_per_child // self.max_chunk)
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

    def chunk_size(self, waiting: int) -> int:
        """Jobs in the next task: ``waiting / (4 * workers)``, between 1 and ``self.max_chunk``
        (large chunks while much is left, single jobs at the end so no worker idles)."""
        return max(1, min(self.max_chunk, waiting // (4 * self.workers)))

    def run(self, jobs: Iterable[Job], deliver: Deliver, claim: Claim) -> None:
        """Run every job; ``deliver`` each chunk's results as they arrive.

        Args:
            jobs: the jobs to run.
            deliver: called in this process with the results of each chunk (the driver
                stores them, one transaction per call).
            claim: called with each group of jobs just before they are handed out.
        """
        # (job, attempts so far, alone): a job that was out when a worker died or a chunk
        # overran runs alone from then on, so one bad input cannot take its chunk mates down
        queue: deque[tuple[Job, int, bool]] = deque((job, 0, False) for job in jobs)
        out: dict[Future[list[JobResult]], tuple[list[tuple[Job, int]], float]] = {}
        limit = 2 * self.workers
        pool = self._pool()
        try:
            while queue or out:
                batch: list[list[tuple[Job, int]]] = []
                while queue and len(out) + len(batch) < limit:
                    batch.append(self._next_chunk(queue))
                if batch:
                    claim([job for chunk in batch for job, _ in chunk])
                    for chunk in batch:
                        future = pool.submit(run_chunk, [job for job, _ in chunk])
                        out[future] = ([(job, n + 1) for job, n in chunk], time.monotonic())
                finished, _ = wait(list(out), timeout=0.5, return_when=FIRST_COMPLETED)
                broken = False
                for future in finished:
                    chunk, _started = out.pop(future)
                    try:
                        results = future.result()
                    except BrokenProcessPool:
                        broken = True
                        self._requeue(queue, deliver, chunk)
                        continue
                    for result, (_job, attempts) in zip(results, chunk):
                        result.attempts = attempts
                    deliver(results)
                now = time.monotonic()
                overdue = [
                    future
                    for future, (chunk, started) in out.items()
                    if (deadline := _hard_deadline(chunk)) is not None and now - started > deadline
                ]
                for future in overdue:
                    chunk, started = out.pop(future)
                    if len(chunk) == 1:
                        deliver([overran(chunk[0][0], now - started)])
                    else:  # which job is stuck is not known: each runs alone, same attempts
                        queue.extendleft((job, n - 1, True) for job, n in reversed(chunk))
                if broken or overdue:
                    victims = list(out.values())
                    out.clear()
                    for chunk, _ in reversed(victims):
                        if broken:
                            self._requeue(queue, deliver, chunk)
                        else:
                            queue.extendleft((job, n - 1, False) for job, n in reversed(chunk))
                    self._kill(pool)
                    pool = self._pool()
                else:
                    self._pool_pids()
        except BaseException:
            self._stop(pool, out, deliver)
            raise
        # every result is in: the idle workers are killed rather than left to tear their
        # interpreters down (a second or more after a few hundred jobs, all of it wall time)
        self._kill(pool)

    def _next_chunk(self, queue: deque[tuple[Job, int, bool]]) -> list[tuple[Job, int]]:
        """The next task's jobs: one job that must run alone, or up to ``chunk_size`` others."""
        job, attempts, alone = queue.popleft()
        chunk = [(job, attempts)]
        if alone:
            return chunk
        size = self.chunk_size(len(queue) + 1)
        while queue and len(chunk) < size and not queue[0][2]:
            following, n, _alone = queue.popleft()
            chunk.append((following, n))
        return chunk

    def _stop(
        self,
        pool: ProcessPoolExecutor,
        out: dict[Future[list[JobResult]], tuple[list[tuple[Job, int]], float]],
        deliver: Deliver,
    ) -> None:
        """The run is stopped: store what finishes within ``STOP_GRACE_S``, kill the workers.
        A second signal during the grace ends the grace, not the cleanup."""
        try:
            finished, _ = wait(list(out), timeout=STOP_GRACE_S)
            for future in finished:
                chunk, _started = out.pop(future)
                try:
                    results = future.result()
                except BaseException:  # noqa: BLE001 - a broken pool: the rows stay pending
                    continue
                for result, (_job, attempts) in zip(results, chunk):
                    result.attempts = attempts
                deliver(results)
        except BaseException:  # noqa: BLE001 - a second Ctrl-C: go straight to the kill
            pass
        finally:
            self._kill(pool)

    def _requeue(
        self,
        queue: deque[tuple[Job, int, bool]],
        deliver: Deliver,
        chunk: list[tuple[Job, int]],
    ) -> None:
        """A chunk whose worker died: each job back to the queue, alone, or its row when it
        has seen ``max_attempts`` deaths."""
        died = [worker_died(job, n) for job, n in chunk if n >= self.max_attempts]
        if died:
            deliver(died)
        queue.extendleft((job, n, True) for job, n in reversed(chunk) if n < self.max_attempts)
