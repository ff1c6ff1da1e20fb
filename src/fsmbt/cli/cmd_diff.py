"""``fsmbt diff OLD NEW``: every behavioural difference of two models, and the edit script.

Exit 0 same behaviour, 1 different, 2 bad input (or a pair that cannot be compared). Option
parsing and printing only; the work is ``fsmbt.diff`` (docs/diff.md).
"""

from __future__ import annotations

import json
from pathlib import Path

import typer

from fsmbt import api, diff
from fsmbt.api_types import ReadOptions
from fsmbt.cli.options import reads_models

EXIT_SAME = 0
EXIT_DIFFERENT = 1


def register(app: typer.Typer) -> None:
    @app.command("diff")
    @reads_models
    def diff_command(
        old: Path = typer.Argument(..., help="The old model (FSM or BT)."),
        new: Path = typer.Argument(..., help="The new model (FSM or BT)."),
        max_groups: int = typer.Option(
            diff.DEFAULT_MAX_GROUPS, "--max", min=1, help="Groups of distinguishing runs shown."
        ),
        markdown: Path | None = typer.Option(None, "--markdown", help="Write a review comment."),
        picture: Path | None = typer.Option(
            None, "--picture", help="Draw NEW with the changes marked (.svg, .png, .pdf, .dot)."
        ),
        junit: Path | None = typer.Option(None, "--junit", help="Write a JUnit XML report."),
        as_json: bool = typer.Option(False, "--json", help="Print the diff as JSON."),
        force: bool = typer.Option(False, "--force", help="Replace existing output files."),
        loop: bool = typer.Option(
            False, "--loop", help="BT side: tick the root again after it returns."
        ),
        *,
        read: ReadOptions,
    ) -> None:
        """Every way NEW behaves differently from OLD (grouped by where the runs part, each
        with a shortest witness) and the structural edits (added, removed, moved, re-typed)."""
        outputs = [p for p in (markdown, picture, junit) if p is not None]
        for path in outputs:
            api.check_destination(path, overwrite=force)
        first, second, report = diff.diff_files(
            old,
            new,
            max_groups=max_groups,
            loop=loop,
            options=read,
        )
        if picture is not None:
            diff.write_diff_picture(first.model, second.model, report, picture, overwrite=force)
        if markdown is not None:
            shown = picture.name if picture is not None else None
            api.write_text(diff.to_markdown(report, picture=shown), markdown, overwrite=force)
        if junit is not None:
            api.write_text(diff.to_junit(report), junit, overwrite=force)
        if as_json:
            print(json.dumps(report.to_dict(), indent=2, ensure_ascii=False))
        else:
            print(report.summary())
            for k, group in enumerate(report.behaviour.groups, start=1):
                print(diff.divergence_text(k, group))
            if report.behaviour.total_groups > len(report.behaviour.groups):
                print(
                    f"... {report.behaviour.total_groups - len(report.behaviour.groups)} more (--max)"
                )
            for op in report.script or []:
                print(f"edit: {op.text()}")
        raise typer.Exit(EXIT_SAME if report.same else EXIT_DIFFERENT)
