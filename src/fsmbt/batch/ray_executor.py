"""The Ray executor: the same jobs as Ray tasks, on this machine or on an existing cluster.

Rules:

- ``ray_address`` given (``auto``, ``HOST:PORT`` of a head started with ``ray start --head``,
  or ``ray://HOST:10001``): ``ray.init(address=...)`` joins that cluster, and ``workers`` is
  how many tasks are out at once per ... the whole batch (back-pressure, not a reservation).
  None given: a private local Ray with ``num_cpus=workers`` on 127.0.0.1, no dashboard, shut
  down at the end.
- One task per chunk of ``chunk_size`` jobs (fewer, larger tasks: Ray's per-task cost is about
  a millisecond). At most ``2 * workers`` chunks are out; ``ray.wait`` hands back each finished
  chunk, so the driver's memory is bounded by the chunks in flight.
- A worker that dies is Ray's to handle: each task has ``max_retries`` (Ray runs it again on
  another worker). A chunk whose retries are used up becomes ``WorkerDied`` rows (run again on
  resume). Results are stored by the driver only, as each chunk arrives.
- The code a worker runs is fsmbt's own ``run_job``, so every node needs the same fsmbt
  installed (docs/batch.md, "Ray cluster").

Costs: Ray's start (seconds, once per batch) and one task per chunk.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from typing import Any

from fsmbt.batch.jobs import Job
from fsmbt.batch.local import Claim, Deliver, worker_died
from fsmbt.batch.worker import run_chunk
from fsmbt.model.errors import InputError

#: Jobs per Ray task.
DEFAULT_CHUNK = 8


def _import_ray() -> Any:
    try:
        import ray
    except ImportError:  # pragma: no cover - ray is a dependency; a broken install says so
        raise InputError(
            "the Ray executor needs the 'ray' package (pip install 'fsmbt[ray]')"
        ) from None
    return ray


class RayExecutor:
    """Runs jobs as Ray tasks (see the module text).

    Args:
        workers: tasks out at once (and CPUs of a private local Ray).
        address: the cluster to join, or ``None`` for a private local Ray.
        chunk_size: jobs per task.
        max_retries: Ray's retries of a task whose worker died.
    """

    def __init__(
        self,
        workers: int = 1,
        *,
        address: str | None = None,
        chunk_size: int = DEFAULT_CHUNK,
        max_retries: int = 3,
    ) -> None:
        self.workers = max(1, workers)
        self.address = address
        self.chunk_size = max(1, chunk_size)
        self.max_retries = max(0, max_retries)

    def _start(self, ray: Any) -> bool:
        """Connect or start Ray; ``True`` when this executor started it (and stops it)."""
        if ray.is_initialized():
            return False
        quiet = {"logging_level": "ERROR", "log_to_driver": False}
        try:
            if self.address:
                ray.init(address=self.address, **quiet)
            else:
                ray.init(
                    num_cpus=self.workers,
                    include_dashboard=False,
                    _node_ip_address="127.0.0.1",
                    **quiet,
                )
        except (ConnectionError, RuntimeError, ValueError) as exc:
            where = self.address or "a local Ray"
            raise InputError(
                f"cannot start or reach Ray at {where}: {' '.join(str(exc).split())[:300]}"
            ) from None
        return True

    def run(self, jobs: Iterable[Job], deliver: Deliver, claim: Claim) -> None:
        """Run every job as Ray tasks; ``deliver`` each result as its chunk arrives.

        Args:
            jobs: the jobs.
            deliver: called in the driver with each result.
            claim: called with each chunk just before it is submitted.
        """
        ray = _import_ray()
        started_here = self._start(ray)
        task = ray.remote(num_cpus=1, max_retries=self.max_retries, retry_exceptions=False)(
            run_chunk
        )
        queue = deque(jobs)
        out: dict[Any, list[Job]] = {}
        try:
            while queue or out:
                while queue and len(out) < 2 * self.workers:
                    chunk = [queue.popleft() for _ in range(min(self.chunk_size, len(queue)))]
                    claim(chunk)
                    out[task.remote(chunk)] = chunk
                ready, _ = ray.wait(list(out), num_returns=1, timeout=1.0)
                for ref in ready:
                    chunk = out.pop(ref)
                    try:
                        results = ray.get(ref)
                    except ray.exceptions.RayError:
                        deliver([worker_died(job, self.max_retries + 1) for job in chunk])
                        continue
                    deliver(results)
        finally:
            for ref in out:
                ray.cancel(ref, force=True)
            if started_here:
                ray.shutdown()
