"""``fsmbt conform MODEL LOG...``: do recorded executions follow the model?

Exit 0 every log conforms, 1 a log deviates (the first deviation of each log is printed), 2 a
model or log that cannot be read (one located line). The work is ``fsmbt.conform``
(docs/conform.md).
"""

from __future__ import annotations

import json
from pathlib import Path

import typer

from fsmbt import conform
from fsmbt.api_types import ReadOptions
from fsmbt.cli.options import reads_models


def register(app: typer.Typer) -> None:
    @app.command("conform")
    @reads_models
    def conform_command(
        model: Path = typer.Argument(..., help="The model (BT, or FSM through leaf <-> state)."),
        logs: list[Path] = typer.Argument(
            ..., help="BehaviorTree.CPP .btlog or .db3 files, or fsmbt py_trees traces (.jsonl)."
        ),
        as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
        *,
        read: ReadOptions,
    ) -> None:
        """Replay every transition of each log through the model's semantics; report the
        first deviation of each log and the coverage the logs reached."""
        report = conform.conform_files(model, list(logs), options=read)
        if as_json:
            print(json.dumps(_as_dict(report), indent=2))
        else:
            for result in report.results:
                if result.deviation is None:
                    print(
                        f"{result.path}: conforms ({result.transitions} transitions, "
                        f"{result.leaf_ticks} leaf ticks)"
                    )
                else:
                    print(f"{result.path}: DEVIATES at {result.deviation.text()}")
            print(report.coverage.text())
        raise typer.Exit(0 if report.conforms else 1)


def _as_dict(report: conform.ConformReport) -> dict[str, object]:
    cov = report.coverage
    return {
        "model": report.model,
        "conforms": report.conforms,
        "logs": [
            {
                "path": r.path,
                "format": r.format,
                "transitions": r.transitions,
                "leaf_ticks": r.leaf_ticks,
                "deviation": None
                if r.deviation is None
                else {
                    "index": r.deviation.index,
                    "time_us": r.deviation.time_us,
                    "absolute_us": r.deviation.absolute_us,
                    "node": r.deviation.node,
                    "happened": r.deviation.happened,
                    "allowed": r.deviation.allowed,
                },
            }
            for r in report.results
        ],
        "coverage": {
            "states": list(cov.states),
            "transitions": list(cov.transitions),
            "node_outcomes": None if cov.node_outcomes is None else list(cov.node_outcomes),
        },
    }
