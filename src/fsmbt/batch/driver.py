"""The batch driver: what to run, where, and the store as the single source of truth.

Rules (docs/batch.md, "Resume"):

- A job whose key has a finished, non-retryable row in the store is skipped, except a
  ``timeout`` or ``limit`` row when this run's limit is larger than the one it hit, and a row
  one of whose other files (``JobResult.dependencies``: an included file, a SubTree or node
  file, an invoked machine) has changed, appeared or gone since (the key hashes the input
  only: which other files a model needs is known once it is read).
- Before a job is handed out its output is checked: when it exists, replacing it was not asked
  for and it is not this batch's own (no ``pending`` claim in the store, and not the file a
  finished row of this job wrote, unchanged since: ``stats["output_hash"]``), the row says
  ``refused`` (``DestinationExists``) and nothing runs. Otherwise the job is claimed in the
  store and runs allowed to replace its output, which from then on can only be its own work
  (an earlier attempt, a worker that died, a driver that was killed after the write).
- A claimed job whose earlier attempt was interrupted mid-write has its stale temporary file
  removed before it runs again.
- Each result is stored the moment it reaches the driver, then handed to ``on_result``; the
  results that arrive together (one chunk) are stored in one transaction.
- LLM engines run on at most ``llm_concurrency`` workers (requests at once) and under the
  per-minute limit of ``fsmbt.batch.ratelimit``.

Costs: one store lookup per job, then the executor's.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from glob import escape as glob_escape
from pathlib import Path
from typing import Any, Literal

from fsmbt import api
from fsmbt.api_types import checker_limit
from fsmbt.batch.jobs import LIMIT_OPTIONS, Job, content_hash, public_options
from fsmbt.batch.result import LIMIT, REFUSED, TIMEOUT, JobResult
from fsmbt.batch.store import ResultStore
from fsmbt.model.errors import InputError, SourceLocation

OnResult = Callable[[JobResult], None]
#: LLM requests at once when nothing else is said.
DEFAULT_LLM_CONCURRENCY = 4


def _limit_value(options: dict[str, Any], name: str) -> float:
    value = options.get(name)
    if value is None:
        # unset: the limits in force (FSMBT_MAX_CHECKER_STATES), the one the worker uses too
        return float("inf") if name == "timeout_s" else float(checker_limit(None))
    return float(value)


def needs_run(store: ResultStore | None, job: Job) -> bool:
    """Whether ``job`` runs (see the module text).

    Args:
        store: the store, or ``None`` (everything runs).
        job: the job.

    Returns:
        ``False`` when the store holds its finished result for good.
    """
    if store is None or not store.done(job.key):
        return True
    previous = store.get(job.key)
    if previous is None or changed_dependency(previous) is not None:
        return True
    hit = {TIMEOUT: "timeout_s", LIMIT: "max_states"}.get(previous.status)
    if hit is None:
        return False
    return _limit_value(job.options, hit) > _limit_value(previous.options, hit)


def changed_dependency(previous: JobResult) -> str | None:
    """The first of a stored row's other files whose content is not what the row was made
    from (see the module text), or ``None``: one hash per dependency, in the recorded order."""
    for path, digest in previous.dependencies.items():
        if content_hash(path) != digest:
            return path
    return None


def refused_destination(job: Job) -> JobResult:
    """The row of a job whose output exists and may not be replaced."""
    error = api.DestinationExists(SourceLocation(str(job.output)))
    return JobResult(
        job.key,
        job.input,
        REFUSED,
        error_class="DestinationExists",
        error_message=" ".join(str(error).split()),
        engine=job.engine,
        verify_engine=job.verify_engine,
        options=public_options(job.options),
        retry=True,
    )


def remove_stale_temporaries(output: Path) -> int:
    """Delete the temporary files an interrupted atomic write of ``output`` left behind.

    ``fsmbt.api.write_text`` writes ``.<name>.<random>.tmp`` beside the output and renames it;
    a worker killed between the two leaves it. Only called for a job this batch claimed.

    Returns:
        How many files were removed.
    """
    removed = 0
    try:
        for stale in output.parent.glob(f".{glob_escape(output.name)}.*.tmp"):
            try:
                stale.unlink()
                removed += 1
            except OSError:
                continue
    except OSError:
        return removed
    return removed


def _own_output(store: ResultStore, job: Job) -> bool:
    """Whether the file at ``job.output`` is, byte for byte, what this batch wrote there for
    this job (a finished row re-run after a larger limit or a changed dependency replaces its
    own output; a file someone changed since is theirs)."""
    previous = store.get(job.key)
    if previous is None or previous.output is None or job.output is None:
        return False
    if Path(previous.output) != Path(job.output):
        return False
    return previous.stats.get("output_hash") == content_hash(job.output)


def _prepare(store: ResultStore | None, job: Job) -> Job | JobResult:
    """The job as it runs (allowed to replace its own output), or the refusal row."""
    if job.output is None or job.overwrite:
        return job
    output = Path(job.output)
    ours = store is not None and (store.pending_output(job.key) or _own_output(store, job))
    if ours:
        remove_stale_temporaries(output)
    if output.exists() and not ours:
        if output.is_dir():
            return dataclasses.replace(job)  # the worker's row names the problem
        return refused_destination(job)
    return dataclasses.replace(job, overwrite=True)


def run_jobs(
    jobs: Sequence[Job],
    *,
    store: ResultStore | None = None,
    executor: Literal["local", "ray"] | str = "local",
    workers: int = 1,
    ray_address: str | None = None,
    on_result: OnResult | None = None,
    collect: bool = True,
    llm_concurrency: int | None = None,
    max_attempts: int = 3,
    chunk_size: int | None = None,
) -> list[JobResult]:
    """Run the jobs that are not done, store each result as it arrives.

    Args:
        jobs: the jobs (from ``make_jobs`` or built by hand).
        store: the results store (``None``: nothing is remembered, everything runs).
        executor: ``local`` (a process pool) or ``ray``.
        workers: worker processes, or Ray tasks out at once.
        ray_address: the Ray cluster to join (``auto``, ``HOST:PORT``); ``None`` starts a
            private local Ray.
        on_result: called with each result after it is stored (a progress display).
        collect: return the results (``False`` for very large batches: read the store).
        llm_concurrency: at most this many LLM jobs at once (default 4).
        max_attempts: worker deaths a job may see before its row says so.
        chunk_size: jobs per Ray task (the local executor sizes its chunks itself).

    Returns:
        The results of this run, in the order they arrived (empty when ``collect`` is off).

    Raises:
        InputError: an unknown executor, or Ray cannot be started or reached.
    """
    if executor not in ("local", "ray"):
        raise InputError(f"unknown executor {executor!r} (known: local, ray)")
    collected: list[JobResult] = []

    def deliver(results: list[JobResult]) -> None:
        if store is not None:
            store.put_many(results)  # the results that arrived together: one transaction
        for result in results:
            if collect:
                collected.append(result)
            if on_result is not None:
                on_result(result)

    todo: list[Job] = []
    for job in jobs:
        if not needs_run(store, job):
            continue
        prepared = _prepare(store, job)
        if isinstance(prepared, JobResult):
            deliver([prepared])
        else:
            todo.append(prepared)
    if not todo:
        return collected
    if any(job.engine in api.LLM_ENGINES for job in todo):
        workers = min(workers, llm_concurrency or DEFAULT_LLM_CONCURRENCY)

    def claim(batch: list[Job]) -> None:
        if store is not None:
            store.claim(batch)

    runner: Any
    if executor == "ray":
        from fsmbt.batch.ray_executor import DEFAULT_CHUNK, RayExecutor

        runner = RayExecutor(
            workers,
            address=ray_address,
            chunk_size=chunk_size or DEFAULT_CHUNK,
            max_retries=max(0, max_attempts - 1),
        )
    else:
        from fsmbt.batch.local import LocalExecutor

        runner = LocalExecutor(workers, max_attempts=max_attempts)
    runner.run(todo, deliver, claim)
    return collected


__all__ = ["LIMIT_OPTIONS", "needs_run", "run_jobs"]
