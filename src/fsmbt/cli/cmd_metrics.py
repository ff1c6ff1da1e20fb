"""``fsmbt metrics MODEL [OTHER]``: the paper's size figures of a model, and the edit distance
between two models of the same kind (docs/metrics.md)."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from fsmbt import api
from fsmbt.api_types import ReadOptions
from fsmbt.cli.options import (
    reads_models,
)
from fsmbt.metrics import edit_distance, elements
from fsmbt.model.errors import InputError


def register(app: typer.Typer) -> None:
    @app.command("metrics")
    @reads_models
    def metrics_command(
        model: Path = typer.Argument(..., help="Model file (FSM or BT)."),
        other: Path | None = typer.Argument(
            None, help="A second model of the same kind: adds the edit distance."
        ),
        timeout: float = typer.Option(
            5.0, "--timeout", min=0.01, help="Seconds for the FSM graph edit distance search."
        ),
        as_json: bool = typer.Option(False, "--json", help="Print the figures as JSON."),
        *,
        read: ReadOptions,
    ) -> None:
        """Graphical and active elements, depth, node counts by type, sub-FSMs; with OTHER the
        tree edit distance (BTs) or graph edit distance (FSMs, an upper bound when cut)."""
        first = api.load(
            model,
            read.format,
            options=read,
        ).model
        figures = {"file": str(model), **elements(first).to_dict()}
        report: dict[str, object] = {"model": figures}
        if other is not None:
            second = api.load(
                other,
                read.format,
                options=read,
            ).model
            report["other"] = {"file": str(other), **elements(second).to_dict()}
            try:
                report["distance"] = edit_distance(first, second, timeout=timeout)
            except InputError as exc:
                raise InputError(exc.message, element=str(other)) from None
        if as_json:
            print(json.dumps(report, indent=2, ensure_ascii=False))
            return
        _print(report)


ROWS = (
    "kind",
    "graphical",
    "active",
    "depth",
    "nodes",
    "edges",
    "leaves",
    "states",
    "transitions",
    "machines",
    "sub_fsms",
)


def _print(report: dict) -> None:
    table = Table(title="metrics", title_justify="left")
    table.add_column("figure", style="bold")
    columns = [report["model"]] + ([report["other"]] if "other" in report else [])
    for column in columns:
        table.add_column(escape(Path(column["file"]).name))
    for row in ROWS:
        values = [column.get(row) for column in columns]
        if all(v in (0, None) for v in values) and row not in ("graphical", "active"):
            continue
        table.add_row(row, *(escape(str(v)) for v in values))
    table.add_row(
        "by type",
        *(escape(", ".join(f"{k}={v}" for k, v in c["by_type"].items())) for c in columns),
    )
    console = Console()
    console.print(table)
    distance = report.get("distance")
    if distance:
        console.print(
            f"{distance['type']}: {distance['value']:g} ({distance['kind']}, "
            f"{distance['method']}, {distance['seconds']:.3f} s)"
        )
