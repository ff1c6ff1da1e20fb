"""``fsmbt batch INPUTS... -o OUTDIR``: convert and verify many models, resumable.

Option parsing and printing around ``fsmbt.batch`` (``make_jobs``, ``run_jobs``,
``ResultStore``), which call the library's pipeline for each input. The options are
``convert``'s, plus the executor (``--workers``, ``--executor local|ray``, ``--ray-address``),
the per-model limits (``--timeout``, ``--max-states``) and the LLM limits
(``--llm-concurrency``, ``--llm-rate``). ``--report`` prints the summary again from the store
in OUTDIR without running anything; ``--json`` prints the summary and every row as JSON.

Display: a live bar on stderr (only on a terminal, not ``--quiet``) with the counts per status
and the ETA; at the end a table of the counts, the refused and failed inputs with their reasons
and the slowest inputs.

Exit codes (docs/batch.md, "Exit codes"): 0 when every input converted and verified
equivalent (or converted, with ``--no-verify``); 1 when any result is not equivalent; else 2
when any input was bad, refused, over a limit or failed.
"""

from __future__ import annotations

import json
import os
import sys
from collections import Counter
from collections.abc import Iterable
from pathlib import Path
from typing import Any, Literal

import typer

from fsmbt import api
from fsmbt.api_types import ReadOptions
from fsmbt.batch import STATUSES, STORE_NAME, JobResult, ResultStore, make_jobs, run_jobs
from fsmbt.batch.result import (
    BAD_INPUT,
    EQUIVALENT,
    ERROR,
    LIMIT,
    NOT_EQUIVALENT,
    NOT_VERIFIED,
    REFUSED,
    TIMEOUT,
)
from fsmbt.cli.hints import CLI_WORDING
from fsmbt.cli.options import (
    reads_models,
)
from fsmbt.llm.config import PROVIDERS
from fsmbt.model.errors import HINT_TEXT, InputError, SourceLocation

PROVIDER_NAMES = ", ".join(sorted(PROVIDERS))
#: How many refused / failed inputs the final table lists before "... and N more".
LISTED = 20
#: How many of the slowest inputs the final table lists.
SLOWEST = 5
FAILED = (BAD_INPUT, ERROR, TIMEOUT, LIMIT)


def exit_code(statuses: Iterable[str]) -> int:
    """0, 1 or 2 for a batch's statuses (see the module text).

    Args:
        statuses: the status of every input of the batch.

    Returns:
        1 when any is not equivalent; else 2 when any is not equivalent/verified-ok; else 0.
    """
    seen = set(statuses)
    if NOT_EQUIVALENT in seen:
        return 1
    if seen - {EQUIVALENT, NOT_VERIFIED}:
        return 2
    return 0


class BatchProgress:
    """A rich progress bar on stderr with counts per status and the ETA (a terminal only)."""

    def __init__(self, total: int, *, quiet: bool) -> None:
        self.enabled = not quiet and sys.stderr.isatty() and total > 0
        self.counts: Counter[str] = Counter()
        self._progress: Any = None
        self._task: Any = None
        self._total = total

    def __enter__(self) -> BatchProgress:
        if self.enabled:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self._progress = Progress(
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self._progress.start()
            self._task = self._progress.add_task(self._describe(), total=self._total)
        return self

    def _describe(self) -> str:
        shown = [
            f"{status.replace('_', ' ')} {self.counts[status]}"
            for status in STATUSES
            if self.counts[status]
        ]
        return ", ".join(shown) or "starting"

    def __call__(self, result: JobResult) -> None:
        self.counts[result.status] += 1
        if self._progress is not None:
            self._progress.update(self._task, advance=1, description=self._describe())

    def __exit__(self, *exc: object) -> None:
        if self._progress is not None:
            self._progress.stop()


def cli_reason(result: JobResult) -> str:
    """A row's reason with the library's hints worded as this CLI's flags (``cli/hints.py``)."""
    text = result.reason
    for hint, words in HINT_TEXT.items():
        text = text.replace(words, CLI_WORDING[hint])
    return text


def shown_path(path: str | None) -> str:
    """``path`` relative to the current folder when it lies inside it (shorter tables)."""
    if path is None:
        return ""
    try:
        return str(Path(path).resolve().relative_to(Path.cwd()))
    except (ValueError, OSError):
        return path


def print_table(results: list[JobResult], summary: dict[str, Any]) -> None:
    """The final table on stdout: counts, refused and failed inputs, the slowest inputs."""
    from rich.console import Console
    from rich.table import Table

    console = Console(soft_wrap=True, highlight=False)
    counts = Table(title="fsmbt batch", show_header=True)
    counts.add_column("status")
    counts.add_column("inputs", justify="right")
    for status in STATUSES:
        counts.add_row(status.replace("_", " "), str(summary["statuses"].get(status, 0)))
    if summary.get("pending"):
        counts.add_row("unfinished", str(summary["pending"]))
    console.print(counts)
    for title, wanted in (
        ("not equivalent", (NOT_EQUIVALENT,)),
        ("refused", (REFUSED,)),
        ("errors", FAILED),
    ):
        rows = [r for r in results if r.status in wanted]
        if not rows:
            continue
        table = Table(title=f"{title} ({len(rows)})", show_header=True)
        table.add_column("input", overflow="fold")
        table.add_column("status")
        table.add_column("reason", overflow="fold")
        for row in rows[:LISTED]:
            table.add_row(shown_path(row.input), row.status.replace("_", " "), cli_reason(row))
        console.print(table)
        if len(rows) > LISTED:
            console.print(f"... and {len(rows) - LISTED} more ({title}); --json lists all")
    timed = sorted((r for r in results if r.timings), key=lambda r: r.seconds, reverse=True)
    if timed:
        slow = Table(title="slowest inputs", show_header=True)
        slow.add_column("input", overflow="fold")
        slow.add_column("seconds", justify="right")
        slow.add_column("status")
        for row in timed[:SLOWEST]:
            slow.add_row(shown_path(row.input), f"{row.seconds:.3f}", row.status.replace("_", " "))
        console.print(slow)
    console.print(f"store: {summary['store']} ({summary['bytes']} bytes)")


def _report(outdir: Path, as_json: bool, keys: list[str] | None = None) -> int:
    store_file = outdir / STORE_NAME if outdir.is_dir() else outdir
    if not store_file.is_file():
        raise InputError(
            "no batch store here (run fsmbt batch INPUTS -o OUTDIR first)",
            location=SourceLocation(str(store_file)),
        )
    with ResultStore(store_file) as store:
        results = store.results()
        summary = store.summary()
    if keys is not None:  # this run's inputs only (the store may hold other runs' rows)
        wanted = set(keys)
        results = [r for r in results if r.key in wanted]
        counts = Counter(r.status for r in results)
        summary = {
            **summary,
            "statuses": {s: counts[s] for s in STATUSES},
            "pending": len(wanted) - len(results),
            "total": len(wanted),
        }
    if as_json:
        print(
            json.dumps(
                {"summary": summary, "results": [r.to_row() for r in results]},
                indent=2,
                default=str,
            )
        )
    else:
        print_table(results, summary)
    return exit_code(r.status for r in results)


def register(app: typer.Typer) -> None:
    @app.command("batch")
    @reads_models
    def batch_command(
        inputs: list[str] = typer.Argument(
            None, help="model files, folders (walked recursively) and glob patterns"
        ),
        outdir: Path = typer.Option(
            ...,
            "-o",
            "--output",
            help="the output folder (mirrors the inputs' layout; holds the results store)",
        ),
        to: str | None = typer.Option(
            None,
            "--to",
            help="output format (default: btcpp for a BT result, scxml for an FSM result)",
        ),
        engine: str = typer.Option("rules", "--engine", help="rules, or a registered engine"),
        style: str = typer.Option(
            "auto",
            "--style",
            help="FSM->BT: auto (structured for outcome-driven machines, else dispatch), "
            "structured, dispatch, lebt (paper is lebt)",
        ),
        loop: bool = typer.Option(
            False,
            "--loop",
            help="BT->FSM: the root is ticked again after it returns (checked in loop mode)",
        ),
        no_verify: bool = typer.Option(False, "--no-verify", help="skip the equivalence check"),
        verifier: Literal["native", "nusmv", "both"] = typer.Option(
            "native",
            "--verify-engine",
            "--verifier",
            help="native, nusmv, or both (both must agree)",
        ),
        force: bool = typer.Option(False, "--force", help="overwrite existing output files"),
        keep_failed: bool = typer.Option(
            False,
            "--keep-failed",
            help="write results even when they are not equivalent (default: not written)",
        ),
        as_json: bool = typer.Option(
            False, "--json", help="print the summary and every row as JSON on stdout"
        ),
        quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress bar on stderr"),
        report: bool = typer.Option(
            False, "--report", help="print the summary of OUTDIR's store again; runs nothing"
        ),
        hierarchy: Literal["subtrees", "flatten"] = typer.Option(
            "subtrees", "--hierarchy", help="FSM->BT of a hierarchical FSM: subtrees or flatten"
        ),
        workers: int = typer.Option(
            max(1, min(4, os.cpu_count() or 1)),
            "--workers",
            "-j",
            min=1,
            help="worker processes (or Ray tasks at once)",
        ),
        executor: Literal["local", "ray"] = typer.Option(
            "local", "--executor", help="local processes or Ray"
        ),
        ray_address: str | None = typer.Option(
            None,
            "--ray-address",
            help="Ray cluster to join: auto or HOST:PORT (default: a private local Ray)",
        ),
        timeout: float | None = typer.Option(
            None, "--timeout", min=0.01, help="seconds per model (a model over it is a timeout row)"
        ),
        max_states: int | None = typer.Option(
            None, "--max-states", min=1, help="the checker's state limit per model"
        ),
        chunk_size: int | None = typer.Option(
            None, "--chunk-size", min=1, help="Ray: models per task (8)"
        ),
        llm_base_url: str | None = typer.Option(
            None, "--llm-base-url", help=f"LLM engines: endpoint URL or provider ({PROVIDER_NAMES})"
        ),
        llm_model: str | None = typer.Option(None, "--llm-model", help="LLM engines: model name"),
        llm_concurrency: int = typer.Option(
            4, "--llm-concurrency", min=1, help="LLM engines: requests at once"
        ),
        llm_rate: int | None = typer.Option(
            None, "--llm-rate", min=1, help="LLM engines: requests per minute, over all workers"
        ),
        *,
        read: ReadOptions,
    ) -> None:
        """Convert and verify many models (files, folders, globs) into OUTDIR; a second run
        skips what is done, a killed run resumes."""
        if report:
            raise typer.Exit(_report(outdir, as_json))
        if not inputs:
            raise InputError("name at least one input file, folder or glob")
        if outdir.exists() and not outdir.is_dir():
            raise InputError(
                "is a file; -o names the output folder", location=SourceLocation(str(outdir))
            )
        outdir.mkdir(parents=True, exist_ok=True)
        options: dict[str, Any] = dict(read.reader_options() or {})
        options.update(style=style, loop=loop, hierarchy=hierarchy)
        if read.format:
            options["source_format"] = read.format
        if keep_failed:
            options["keep_not_equivalent"] = True
        if timeout is not None:
            options["timeout_s"] = timeout
        if max_states is not None:
            options["max_states"] = max_states
        runtime: dict[str, Any] = {}
        if engine in api.LLM_ENGINES:
            options.update(
                {k: v for k, v in (("llm_base_url", llm_base_url), ("llm_model", llm_model)) if v}
            )
            if llm_rate:
                runtime = {
                    "llm_rate_per_minute": llm_rate,
                    "llm_rate_file": str(outdir / ".fsmbt-llm-rate"),
                }
        jobs = make_jobs(
            inputs,
            outdir,
            engine=engine,
            verify_engine="none" if no_verify else verifier,
            options=options,
            to=to,
            overwrite=force,
            runtime=runtime,
        )
        if not jobs:
            raise InputError("no model files found in the inputs")
        with ResultStore(outdir) as store:
            with BatchProgress(len(jobs), quiet=quiet or as_json) as progress:
                run_jobs(
                    jobs,
                    store=store,
                    executor=executor,
                    workers=workers,
                    ray_address=ray_address,
                    on_result=progress,
                    collect=False,
                    llm_concurrency=llm_concurrency,
                    chunk_size=chunk_size,
                )
        raise typer.Exit(_report(outdir, as_json, [job.key for job in jobs]))
