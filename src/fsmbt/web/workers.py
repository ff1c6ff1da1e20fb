"""Worker processes: every conversion, verification and drawing runs outside the server's loop.

Why processes: a conversion is CPU-bound Python; in a thread it would hold the interpreter and a
too-large model could not be stopped. A ``ProcessPoolExecutor`` of ``workers`` processes runs
the ``fsmbt.web.service`` functions. Calls wait (in the server's event loop, costing nothing) for
a free process, at most ``max_waiting`` of them (beyond: 503 "busy" at once), and each call's
wall-time limit starts when a process takes it, so a burst of requests queues instead of
timing out. Past the limit the request gets a
clear 408 answer naming the limit, with a hint to use the CLI, and the pool is replaced (its
processes killed), so
the worker is free for the next request instead of grinding on. Each worker also installs the
checker's own time bound (``fsmbt.limits``, ``checker_max_seconds``) at the same value, so the
native checker usually stops itself first, with its own message.

Each call also has a CPU-time limit (``cpu_seconds``): before the call the worker sets its
soft ``RLIMIT_CPU`` to the CPU time it has used so far plus the limit; the kernel's
``SIGXCPU`` then raises ``CpuLimitExceeded`` in the call, which is answered as a refusal naming
the limit, and the soft limit is lifted again after the call (the hard limit is never
touched, so the worker is not killed). A call that waits on a native library without Python
frames is stopped by the wall limit instead.

A call returns ``("ok", value)`` or ``("error", body)`` (an ``FsmbtError`` already turned into
the API's error JSON in the worker); any other exception is logged by the server and answered
as a 500 with one line, never a traceback.
"""

from __future__ import annotations

import asyncio
import logging
import multiprocessing
import resource
import signal
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from fsmbt import limits
from fsmbt.model.errors import FsmbtError, one_line

LOG = logging.getLogger("fsmbt.web")
#: Calls that may wait for a free worker before new ones are refused (503, "busy").
DEFAULT_MAX_WAITING = 1000


class WorkTimeout(Exception):
    """A call took longer than the per-request limit."""


class Busy(Exception):
    """Too many calls are already waiting for a worker."""


class CpuLimitExceeded(Exception):
    """Raised in a worker by ``SIGXCPU``: the call used more than its CPU-time limit."""


class CpuTimeout(Exception):
    """A call used more CPU time than the per-request limit (the worker stays usable)."""


class WorkerCrashed(Exception):
    """A call failed in a way that is not bad input (logged; answered with one line)."""


def _on_cpu_limit(signum: int, frame: Any) -> None:
    raise CpuLimitExceeded()


def _initialise(seconds: float) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the server handles Ctrl-C
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGXCPU, _on_cpu_limit)
    limits.use(limits.current().with_changes(checker_max_seconds=seconds))


def _cpu_used() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _set_cpu_soft_limit(seconds: float | None) -> None:
    """Soft ``RLIMIT_CPU`` at ``seconds`` from now (``None``: no soft limit)."""
    _, hard = resource.getrlimit(resource.RLIMIT_CPU)
    if seconds is None:
        soft = hard
    else:
        soft = int(_cpu_used() + seconds) + 1
        if hard != resource.RLIM_INFINITY:
            soft = min(soft, hard)
    resource.setrlimit(resource.RLIMIT_CPU, (soft, hard))


def _warm() -> None:
    """Import what the calls need, so the first request's time limit counts work only."""
    import fsmbt.web.service  # noqa: F401


def _call(
    function: Callable[[Any], Any], argument: Any, cpu_seconds: float | None = None
) -> tuple[str, Any]:
    from fsmbt.web.service import error_body

    try:
        if cpu_seconds is not None:
            _set_cpu_soft_limit(cpu_seconds)
        try:
            return "ok", function(argument)
        finally:
            if cpu_seconds is not None:
                _set_cpu_soft_limit(None)
    except CpuLimitExceeded:
        return "cpu", cpu_seconds
    except FsmbtError as exc:
        return "error", error_body(exc)
    except RecursionError:
        return "error", {"error": "the model is nested too deeply to handle", "where": None}
    except MemoryError:
        return "error", {
            "error": "the model needs more memory than the server allows; "
            "use the command line (fsmbt convert)",
            "where": None,
        }
    except Exception as exc:  # a bug: keep the cause for the log, not the browser
        return "crash", f"{type(exc).__name__}: {one_line(str(exc))}"[:500]


class Workers:
    """A pool of worker processes with a per-call wall-time limit.

    Args:
        count: how many processes.
        seconds: the wall-time limit of one call, counted from when a process takes it (a call
            waits for a free process first, so queueing under load is not charged to it).
        max_waiting: calls allowed to wait for a process; beyond, ``Busy`` at once.
        cpu_seconds: the CPU-time limit of one call (``None``: only the wall limit).
    """

    def __init__(
        self,
        count: int,
        seconds: float,
        max_waiting: int = DEFAULT_MAX_WAITING,
        cpu_seconds: float | None = None,
    ) -> None:
        self.count = max(1, count)
        self.seconds = seconds
        self.max_waiting = max_waiting
        self.cpu_seconds = cpu_seconds
        self._pool, self._warming = self._new_pool()
        self._slots: asyncio.Semaphore | None = None  # made in the server's loop
        self._waiting = 0

    def _new_pool(self) -> tuple[ProcessPoolExecutor, list[Future[None]]]:
        """A pool whose processes are started and have imported the service (one warm-up
        call per process, submitted at once)."""
        pool = ProcessPoolExecutor(
            max_workers=self.count,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_initialise,
            initargs=(self.seconds,),
        )
        return pool, [pool.submit(_warm) for _ in range(self.count)]

    async def run(self, function: Callable[[Any], Any], argument: Any) -> tuple[str, Any]:
        """Run ``function(argument)`` in a worker.

        Returns:
            ``("ok", value)`` or ``("error", error JSON)``.

        Raises:
            WorkTimeout: past the time limit (the pool has been replaced).
            CpuTimeout: past the CPU-time limit (the worker is kept).
            Busy: ``max_waiting`` calls are already waiting.
            WorkerCrashed: the function raised something other than an ``FsmbtError``.
        """
        if self._slots is None:
            self._slots = asyncio.Semaphore(self.count)
        if self._waiting >= self.max_waiting:
            raise Busy()
        self._waiting += 1
        try:
            await self._slots.acquire()
        finally:
            self._waiting -= 1
        try:
            return await self._run_now(function, argument)
        finally:
            self._slots.release()

    async def _run_now(self, function: Callable[[Any], Any], argument: Any) -> tuple[str, Any]:
        pool = self._pool
        loop = asyncio.get_running_loop()
        try:
            # start-up is not the request's time: wait for the processes to be ready first
            await asyncio.gather(*(asyncio.wrap_future(f) for f in self._warming))
            future = loop.run_in_executor(pool, _call, function, argument, self.cpu_seconds)
            status, value = await asyncio.wait_for(future, timeout=self.seconds)
        except TimeoutError:
            self._replace(pool)
            raise WorkTimeout() from None
        except BrokenProcessPool:
            self._replace(pool)
            raise WorkerCrashed("a worker process stopped; the workers were restarted") from None
        if status == "cpu":
            raise CpuTimeout()
        if status == "crash":
            LOG.error("worker failure in %s: %s", getattr(function, "__name__", function), value)
            raise WorkerCrashed(value)
        return status, value

    def _replace(self, pool: ProcessPoolExecutor) -> None:
        if pool is not self._pool:
            return  # another request already replaced it
        self._pool, self._warming = self._new_pool()
        processes = list(getattr(pool, "_processes", {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            if process.is_alive():
                process.kill()  # SIGKILL; a process that ended meanwhile is no error

    def close(self, grace_s: float = 3.0) -> None:
        """Stop the workers: queued calls are cancelled, running ones get ``grace_s`` seconds
        to finish, then every process still alive is killed, so none outlives the server
        (docs/web.md, 'Stopping')."""
        pool = self._pool
        processes = list(getattr(pool, "_processes", {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.join(timeout=grace_s)
            if process.is_alive():
                process.kill()  # SIGKILL; a process that ended meanwhile is no error
                process.join(timeout=1.0)
