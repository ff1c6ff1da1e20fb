"""Run the planned jobs on the batch runner, store each result as it arrives, show progress.

Rules: results go to ``<report>/results.sqlite`` (the batch runner's ``ResultStore``) one row
per job as it finishes, so a run killed at any point resumes where it stopped: ``run_jobs``
skips every key the store holds, and a key is stored once (a primary key), so nothing is lost
or counted twice. The progress display (one bar per method, with ETA) is drawn on stderr and
only when stderr is a terminal.

Cost: the jobs' own cost divided by ``workers``; one SQLite commit per result.
"""

from __future__ import annotations

import sys
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from fsmbt.evaluate.plan import Planned
from fsmbt.evaluate.runner import JobResult, ResultStore, run_jobs

STORE_FILE = "results.sqlite"


def _label(planned: Planned) -> str:
    return planned.method if planned.verifier == "native" else f"{planned.method}+nusmv"


def run(
    planned: Sequence[Planned],
    store_path: Path,
    *,
    workers: int,
    executor: str = "local",
    ray_address: str | None = None,
    progress: bool = True,
) -> dict[str, int]:
    """Run what the store does not hold yet.

    Args:
        planned: the jobs.
        store_path: the SQLite file.
        workers: worker processes.
        executor: ``local`` or ``ray``.
        ray_address: the Ray cluster, or ``None``.
        progress: draw the bars (still only on a terminal).

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
        bars: Progress | None = None
        tasks: dict[str, TaskID] = {}
        if progress and sys.stderr.isatty() and todo:
            bars = Progress(
                TextColumn("{task.description:>24}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
            )
            for label, total in totals.items():
                tasks[label] = bars.add_task(label, total=total, completed=done[label])
            bars.start()
        ran = 0

        def on_result(result: JobResult) -> None:
            nonlocal ran
            ran += 1
            if bars is not None:
                bars.advance(tasks[label_of[result.key]])

        try:
            run_jobs(
                todo,
                store=store,
                executor=executor,
                workers=workers,
                ray_address=ray_address,
                on_result=on_result,
            )
        finally:
            if bars is not None:
                bars.stop()
        after = sum(1 for p in planned if store.done(p.job.key))
        return {"before": before, "ran": ran, "after": after}
    finally:
        close = getattr(store, "close", None)
        if close is not None:
            close()
