"""Run the planned jobs on the batch runner, store each result as it arrives, report progress.

Rules: results go to ``<report>/results.sqlite`` (the batch runner's ``ResultStore``) one row
per job as it finishes, so a run killed at any point resumes where it stopped: ``run_jobs``
skips every key the store holds, and a key is stored once (a primary key), so nothing is lost
or counted twice. Progress is reported to an optional ``on_progress(label, done, total)`` hook,
once per method label before the run (with what the store already holds) and after each
result; drawing it (the per-method bars of ``fsmbt evaluate``) is the CLI's business
(``fsmbt.cli.progress.MethodBars``), this layer prints nothing.

Cost: the jobs' own cost divided by ``workers``; one SQLite commit per result.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from pathlib import Path

from fsmbt.evaluate.plan import Planned
from fsmbt.evaluate.runner import JobResult, ResultStore, run_jobs

STORE_FILE = "results.sqlite"

#: ``on_progress(label, done, total)``: a method label (``rules``, ``bsd+nusmv``, ...), its
#: results stored so far and its jobs in all.
ProgressHook = Callable[[str, int, int], None]


def _label(planned: Planned) -> str:
    return planned.method if planned.verifier == "native" else f"{planned.method}+nusmv"


def run(
    planned: Sequence[Planned],
    store_path: Path,
    *,
    workers: int,
    executor: str = "local",
    ray_address: str | None = None,
    on_progress: ProgressHook | None = None,
) -> dict[str, int]:
    """Run what the store does not hold yet.

    Args:
        planned: the jobs.
        store_path: the SQLite file.
        workers: worker processes.
        executor: ``local`` or ``ray``.
        ray_address: the Ray cluster, or ``None``.
        on_progress: told each method's progress (``ProgressHook``), or ``None``.

    Returns:
        ``{"before": rows stored before, "ran": results this run, "after": rows after}``.
    """
    store = ResultStore(store_path)
    try:
        label_of = {p.job.key: _label(p) for p in planned}
        totals = Counter(label_of.values())
        done = Counter(label_of[p.job.key] for p in planned if store.done(p.job.key))
        before = sum(done.values())
        todo = [p.job for p in planned if not store.done(p.job.key)]
        if on_progress is not None and todo:
            for label, total in totals.items():
                on_progress(label, done[label], total)
        ran = 0

        def on_result(result: JobResult) -> None:
            nonlocal ran
            ran += 1
            label = label_of[result.key]
            done[label] += 1
            if on_progress is not None:
                on_progress(label, done[label], totals[label])

        run_jobs(
            todo,
            store=store,
            executor=executor,
            workers=workers,
            ray_address=ray_address,
            on_result=on_result,
        )
        after = sum(1 for p in planned if store.done(p.job.key))
        return {"before": before, "ran": ran, "after": after}
    finally:
        close = getattr(store, "close", None)
        if close is not None:
            close()
