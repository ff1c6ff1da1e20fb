"""``fsmbt evaluate``: the reference paper's evaluation, run on measured and verified numbers.

One data flow: ``dataset`` (seeded models + examples + corpus, a manifest) -> ``plan`` (every
method on every model; NuSMV on a stated sample; LLM methods only with an endpoint) ->
``execute`` (the batch runner through ``runner``, an SQLite store, resumable) -> ``analysis``
(tables: accuracy with Wilson intervals, consistency, elements vs the paper's formulas,
edit distances of the add-behaviour ``cases``, input representations, cost) -> ``report``
(Markdown, self-contained HTML, PNG/SVG plots, CSV/JSON). The paper's own numbers are in
``paper``. docs/evaluation.md states every rule and the measured figures.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: Generated models per scenario and kind with ``--quick``, and how many corpus files.
QUICK_COUNT = 10
QUICK_CORPUS = 12


@dataclass
class EvaluationSettings:
    """What one ``fsmbt evaluate`` run does (the CLI's options)."""

    output: Path
    quick: bool = False
    seed: int = 0
    count: int | None = None
    nusmv_sample: int = 30
    workers: int = 2
    executor: str = "local"
    ray_address: str | None = None
    llm_models: list[str] = field(default_factory=list)
    corpus: Path | None = None
    examples: Path | None = Path("examples")
    command: str = "fsmbt evaluate"

    @property
    def per_kind(self) -> int:
        """Generated models per scenario and kind."""
        from fsmbt.evaluate.dataset import FULL_COUNT

        if self.count is not None:
            return self.count
        return QUICK_COUNT if self.quick else FULL_COUNT


#: One JSON line per invocation in the report folder: a killed and resumed run shows each part.
RUNS_FILE = "runs.jsonl"


def _log_invocation(path: Path, settings: EvaluationSettings, summary: dict[str, Any]) -> None:
    line = {
        "command": settings.command,
        "finished_at": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
        **{k: summary[k] for k in ("before", "ran", "after", "jobs")},
        "seconds": round(summary["run_seconds"], 1),
    }
    with open(path, "a", encoding="utf-8") as stream:
        stream.write(json.dumps(line) + "\n")


def evaluate(
    settings: EvaluationSettings,
    *,
    report: bool = True,
    on_progress: Callable[[str, int, int], None] | None = None,
) -> dict[str, Any]:
    """Build the dataset, run and verify every method, write the report.

    Args:
        settings: the run's settings.
        report: write the report folder after the run.
        on_progress: ``on_progress(method, done, total)`` as results arrive
            (``fsmbt.evaluate.execute.ProgressHook``), or ``None``.

    Returns:
        Counts: ``models``, ``jobs``, ``before`` / ``ran`` / ``after`` (stored rows), ``seconds``
        and ``report`` (the Markdown file) when written.
    """
    from fsmbt.evaluate import dataset, execute, plan

    started = time.perf_counter()
    out = settings.output
    out.mkdir(parents=True, exist_ok=True)
    corpus = settings.corpus if settings.corpus is not None and settings.corpus.is_dir() else None
    entries = dataset.build(
        out / "dataset",
        seed=settings.seed,
        count=settings.per_kind,
        examples=settings.examples,
        corpus=corpus,
        corpus_limit=QUICK_CORPUS if settings.quick else None,
    )
    llm_models, _reason = plan.endpoint_models(settings.llm_models)
    planned = plan.plan(
        entries, out, seed=settings.seed, nusmv_sample=settings.nusmv_sample, llm_models=llm_models
    )
    counts = execute.run(
        planned,
        out / execute.STORE_FILE,
        workers=settings.workers,
        executor=settings.executor,
        ray_address=settings.ray_address,
        on_progress=on_progress,
    )
    summary: dict[str, Any] = {
        "models": len(entries),
        "jobs": len(planned),
        **counts,
        "run_seconds": time.perf_counter() - started,
    }
    _log_invocation(out / RUNS_FILE, settings, summary)
    if report:
        from fsmbt.evaluate.report import write_report

        summary["report"] = str(write_report(settings, entries, planned, llm_models, summary))
    summary["seconds"] = time.perf_counter() - started
    return summary


__all__ = ["EvaluationSettings", "evaluate", "QUICK_COUNT"]
