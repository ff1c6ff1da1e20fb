"""``fsmbt validate``: structural checks of a model file with located messages.

Exit 0 when there is no error (warnings allowed unless ``--strict``), 2 on errors or when the
file cannot be read. The issues go to stdout (a table, or JSON with ``--json``); on failure
stderr gets exactly one line naming the first error, so scripts and people see the cause.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from fsmbt import api
from fsmbt.api_types import ReadOptions
from fsmbt.cli import EXIT_BAD_INPUT, EXIT_OK
from fsmbt.cli.options import (
    reads_models,
)
from fsmbt.model.errors import SourceLocation
from fsmbt.model.validate import Issue, validate


def register(app: typer.Typer) -> None:
    @app.command("validate")
    @reads_models
    def validate_command(
        model: Path = typer.Argument(..., help="Model file (FSM or BT, any format fsmbt reads)."),
        as_json: bool = typer.Option(False, "--json", help="Print the issues as JSON."),
        strict: bool = typer.Option(False, "--strict", help="Treat warnings as errors."),
        *,
        read: ReadOptions,
    ) -> None:
        """Check a model: unknown nodes, wrong child counts, missing SubTrees, unknown or
        duplicate states, nondeterminism, empty models; warn about unreachable states,
        dead ends not marked final and parts fsmbt cannot model exactly."""
        loaded = api.load(
            model,
            read.format,
            options=read,
        )
        # reader warnings already start with their location; model issues get the file name
        issues = [Issue("warning", w) for w in loaded.warnings]
        issues += [_with_file(i, model) for i in validate(loaded.model)]
        issues += [_with_file(i, model) for i in api.lebt_port_issues(loaded.model)]
        # what conversion would refuse is an error too, so validate and convert agree
        located = {(i.location, i.message) for i in issues if i.severity == "error"}
        errors_at = {i.location for i in issues if i.severity == "error" and i.location}
        for blocker in api.conversion_blockers(loaded.model):
            if blocker.location in errors_at or (blocker.location, blocker.message) in located:
                continue  # already reported by the structural checks
            issues.append(
                _with_file(
                    Issue(
                        "error",
                        f"conversion would refuse: {blocker.message}",
                        blocker.location,
                        blocker.element,
                    ),
                    model,
                )
            )
        failing = [i for i in issues if i.severity == "error"] + (
            [i for i in issues if i.severity == "warning"] if strict else []
        )
        kind = loaded.kind
        if as_json:
            print(
                json.dumps(
                    {
                        "file": str(model),
                        "kind": kind,
                        "valid": not failing,
                        "errors": sum(i.severity == "error" for i in issues),
                        "warnings": sum(i.severity == "warning" for i in issues),
                        "issues": [i.to_dict() for i in issues],
                    },
                    indent=2,
                    ensure_ascii=False,
                )
            )
        else:
            _print_table(model, kind, issues)
        if failing:
            first = failing[0]
            more = f" (+{len(failing) - 1} more)" if len(failing) > 1 else ""
            label = "error" if first.severity == "error" else "error (--strict, a warning)"
            where = f"{first.location}: " if first.location is not None else ""
            element = f"{first.element}: " if first.element else ""
            text = f"{where}{element}{first.message}".replace("\n", " ")
            print(f"{label}: {text}{more}", file=sys.stderr)
            raise typer.Exit(EXIT_BAD_INPUT)
        raise typer.Exit(EXIT_OK)


def _with_file(issue: Issue, model: Path) -> Issue:
    """The issue located in ``model`` when the reader gave no file (e.g. JSON input)."""
    loc = issue.location
    if loc is not None and loc.file is not None:
        return issue
    located = SourceLocation(str(model), loc.line if loc else None, loc.column if loc else None)
    return Issue(issue.severity, issue.message, located, issue.element)


def _print_table(model: Path, kind: str, issues: list[Issue]) -> None:
    console = Console()
    if not issues:
        console.print(f"{escape(str(model))}: valid {kind.upper()}, no issues")
        return
    table = Table(
        "severity", "where", "element", "message", title=escape(str(model)), title_justify="left"
    )
    for issue in issues:
        style = "red" if issue.severity == "error" else "yellow"
        table.add_row(
            f"[{style}]{issue.severity}[/{style}]",
            escape(str(issue.location)) if issue.location else "-",
            escape(issue.element or "-"),
            escape(issue.message),
        )
    console.print(table)
    errors = sum(i.severity == "error" for i in issues)
    console.print(f"{errors} error(s), {len(issues) - errors} warning(s)")
