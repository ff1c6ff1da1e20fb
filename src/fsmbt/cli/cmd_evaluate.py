"""``fsmbt evaluate``: the paper's evaluation in one command (docs/evaluation.md).

Builds the seeded dataset and its manifest, runs every engine on every model on the batch
runner (results stored as they arrive; a killed run resumes), then writes the report folder.
"""

from __future__ import annotations

import os
import shlex
import sys
from pathlib import Path

import typer


def register(app: typer.Typer) -> None:
    """Add ``evaluate`` to the app."""

    @app.command("evaluate")
    def evaluate_command(
        output: Path = typer.Option(
            Path("evaluation"),
            "-o",
            "--output",
            help="report folder (created; a second run resumes in it)",
        ),
        quick: bool = typer.Option(
            False, "--quick", help="a CI subset: 10 models per scenario and kind"
        ),
        seed: int = typer.Option(0, "--seed", help="the dataset's base seed"),
        count: int | None = typer.Option(
            None,
            "--count",
            help="generated models per scenario and kind (default 200, 10 with --quick)",
        ),
        nusmv: int = typer.Option(
            30,
            "--nusmv",
            help="generated models NuSMV also checks, besides the robot BT and predator FSM "
            "examples (0: no NuSMV at all)",
        ),
        workers: int = typer.Option(2, "--workers", help="worker processes"),
        executor: str = typer.Option("local", "--executor", help="local or ray"),
        ray_address: str | None = typer.Option(None, "--ray-address"),
        llm_model: list[str] = typer.Option(
            [], "--llm-model", help="an LLM model to evaluate (repeatable)"
        ),
        corpus: Path | None = typer.Option(
            None,
            "--corpus",
            help="the corpus folder (default: $FSMBT_CORPUS, else ../shared/corpus)",
        ),
        examples: Path = typer.Option(Path("examples"), "--examples"),
        no_report: bool = typer.Option(False, "--no-report", help="run only, write no report"),
        quiet: bool = typer.Option(False, "--quiet", help="no progress bars"),
    ) -> None:
        """Build the dataset, run every engine on every model, verify, and write the report."""
        from fsmbt.cli.progress import MethodBars
        from fsmbt.evaluate import EvaluationSettings, evaluate

        chosen_corpus = corpus or Path(os.environ.get("FSMBT_CORPUS", "../shared/corpus"))
        settings = EvaluationSettings(
            output=output,
            quick=quick,
            seed=seed,
            count=count,
            nusmv_sample=nusmv,
            workers=workers,
            executor=executor,
            ray_address=ray_address,
            llm_models=list(llm_model),
            corpus=chosen_corpus,
            examples=examples,
            command="fsmbt " + " ".join(shlex.quote(a) for a in sys.argv[1:]),
        )
        with MethodBars(quiet=quiet) as bars:
            summary = evaluate(settings, report=not no_report, on_progress=bars)
        print(
            f"dataset: {summary['models']} models; jobs: {summary['jobs']} "
            f"(stored before {summary['before']}, run now {summary['ran']}, "
            f"stored after {summary['after']}); {summary['seconds']:.1f} s"
        )
        if summary.get("report"):
            print(f"report: {summary['report']}")
