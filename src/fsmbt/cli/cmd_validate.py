"""``fsmbt validate``: structural checks of a model file with located findings.

Findings are printed in the compiler form by default (``file:line:col: severity: message
[code]``, one per line, docs/cli.md "Diagnostics"), or as JSON, SARIF 2.1.0 or a rich table
(``--format``). Errors are models fsmbt cannot give a meaning to; what a valid model holds that
conversion would refuse ("fsmbt cannot convert it yet") is a warning ``[cannot-convert]``.
Undeclared leaf types are one warning for all of them, as ``convert`` words it.

Exit 0 when there is no error (warnings allowed unless ``--strict``, which makes every warning,
``cannot-convert`` included, an error), 2 on errors or when the file cannot be read; on failure
stderr gets exactly one line naming the first error, so scripts and people see the cause.
"""

from __future__ import annotations

import json
import sys
from enum import Enum
from pathlib import Path

import typer

from fsmbt import api
from fsmbt.api_types import ReadOptions
from fsmbt.cli import EXIT_BAD_INPUT, EXIT_OK
from fsmbt.cli.diagnostics import (
    as_json,
    as_sarif,
    print_compiler,
    print_table,
    reader_warning,
)
from fsmbt.cli.options import (
    reads_models,
)
from fsmbt.model import Model
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import SourceLocation
from fsmbt.model.undeclared import summary as undeclared_summary
from fsmbt.model.undeclared import undeclared_leaf_types
from fsmbt.model.validate import Issue, collapse_repeated_warnings, validate


class OutputFormat(str, Enum):
    text = "text"
    json = "json"
    sarif = "sarif"
    table = "table"


def register(app: typer.Typer) -> None:
    @app.command("validate")
    @reads_models
    def validate_command(
        model: Path = typer.Argument(..., help="Model file (FSM or BT, any format fsmbt reads)."),
        output_format: OutputFormat = typer.Option(
            OutputFormat.text,
            "--format",
            help="text: file:line:col: severity: message [code], one per line; json; sarif "
            "(SARIF 2.1.0, for GitHub code scanning); table (a rich table).",
        ),
        as_json_flag: bool = typer.Option(False, "--json", help="Same as --format json."),
        *,
        read: ReadOptions,
    ) -> None:
        """Check a model: unknown nodes, wrong child counts, missing SubTrees, unknown or
        duplicate states, nondeterminism, empty models; warn about unreachable states,
        dead ends not marked final and parts fsmbt cannot convert yet."""
        chosen = OutputFormat.json if as_json_flag else output_format
        strict = read.strict  # warnings (cannot-convert included) are errors
        loaded = api.load(
            model,
            read.format,
            options=read,
        )
        issues = findings(model, loaded.model, loaded.warnings)
        failing = [i for i in issues if i.severity == "error"] + (
            [i for i in issues if i.severity == "warning"] if strict else []
        )
        kind = loaded.kind
        if chosen is OutputFormat.json:
            print(as_json(model, kind, issues, not failing))
        elif chosen is OutputFormat.sarif:
            print(json.dumps(as_sarif(model, issues, strict=strict), indent=2, ensure_ascii=False))
        elif chosen is OutputFormat.table:
            print_table(model, kind, issues)
        else:
            print_compiler(model, kind, issues)
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


def findings(model: Path, loaded: Model, warnings: list[str]) -> list[Issue]:
    """Every finding of a loaded model, in order: the reader's warnings, the structural
    checks, the LEBT port checks, then what conversion would refuse that the checks did not
    already report (an error when the tree is invalid, else a ``cannot-convert`` warning);
    undeclared leaf types grouped into one warning, a warning repeated at several nodes given
    once with its count, in file order."""
    issues = [reader_warning(w, model) for w in warnings]
    issues += [_with_file(i, model) for i in validate(loaded)]
    issues += [_with_file(i, model) for i in api.lebt_port_issues(loaded)]
    located = {(i.location, i.message) for i in issues if i.severity == "error"}
    # places the structural checks already report (an error, or a node of unknown semantics)
    reported_at = {
        i.location
        for i in issues
        if i.location and (i.severity == "error" or i.code == "unknown-semantics")
    }
    for blocker in api.conversion_blockers(loaded):
        if blocker.location in reported_at or (blocker.location, blocker.message) in located:
            continue  # already reported by the structural checks
        if blocker.unsupported:
            issue = Issue(
                "warning",
                f"fsmbt cannot convert this yet: {blocker.message}",
                blocker.location,
                blocker.element,
                "cannot-convert",
            )
        else:
            issue = Issue(
                "error",
                f"conversion would refuse: {blocker.message}",
                blocker.location,
                blocker.element,
                "invalid-tree",
            )
        issues.append(_with_file(issue, model))
    if isinstance(loaded, BTDocument):
        issues = _group_undeclared(issues, loaded)
    # one warning per repeated message, with the count; then in file order
    issues = collapse_repeated_warnings(issues)
    return sorted(issues, key=_place)


def _place(issue: Issue) -> tuple[str, int]:
    loc = issue.location
    return (loc.file or "", loc.line or 0) if loc is not None else ("", 0)


def _group_undeclared(issues: list[Issue], doc: BTDocument) -> list[Issue]:
    """One ``undeclared-leaf`` warning for every undeclared type, at the first one's place,
    worded as ``convert`` and ``info`` word it."""
    grouped: list[Issue] = []
    done = False
    for issue in issues:
        if issue.code != "undeclared-leaf":
            grouped.append(issue)
        elif not done:
            done = True
            line = undeclared_summary(undeclared_leaf_types(doc))
            grouped.append(
                Issue(
                    "warning",
                    f"{line}; declare them with --node-models FILE (the first is here)",
                    issue.location,
                    None,
                    "undeclared-leaf",
                )
            )
    return grouped


def _with_file(issue: Issue, model: Path) -> Issue:
    """The issue located in ``model`` when the reader gave no file (e.g. JSON input)."""
    loc = issue.location
    if loc is not None and loc.file is not None:
        return issue
    located = SourceLocation(str(model), loc.line if loc else None, loc.column if loc else None)
    return Issue(issue.severity, issue.message, located, issue.element, issue.code)
