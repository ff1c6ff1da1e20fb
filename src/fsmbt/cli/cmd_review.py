"""``fsmbt review BASE [HEAD]``: diff every model file changed between two git revisions
(or BASE and the working tree); what the GitHub Action and the pre-commit hook run.

Exit 0 no behaviour changed, 1 some behaviour changed (only with ``--fail-on-change``; else 0),
2 a changed model does not load or git fails. The work is ``fsmbt.diff.changes`` (docs/diff.md).
"""

from __future__ import annotations

from pathlib import Path

import typer

from fsmbt import api, diff
from fsmbt.diff.changes import DEFAULT_PATTERNS

EXIT_BAD = 2


def register(app: typer.Typer) -> None:
    @app.command("review")
    def review_command(
        base: str = typer.Argument(..., help="The base revision (e.g. origin/main, HEAD)."),
        head: str | None = typer.Argument(None, help="The head revision (default: working tree)."),
        repo: Path = typer.Option(Path("."), "--repo", help="The git repository."),
        pattern: list[str] = typer.Option(
            list(DEFAULT_PATTERNS), "--pattern", help="Model file names (glob; repeat)."
        ),
        markdown: Path | None = typer.Option(None, "--markdown", help="Write the review comment."),
        fail_on_change: bool = typer.Option(
            False, "--fail-on-change", help="Exit 1 when any model's behaviour changed."
        ),
        force: bool = typer.Option(False, "--force", help="Replace an existing --markdown file."),
        max_groups: int = typer.Option(
            diff.DEFAULT_MAX_GROUPS, "--max", min=1, help="Groups shown per file."
        ),
    ) -> None:
        """Diff each changed model file against its BASE version; print one line per file."""
        if markdown is not None:
            api.check_destination(markdown, overwrite=force)
        changes = diff.diff_changes(
            repo, base, head, patterns=tuple(pattern), max_groups=max_groups
        )
        for item in changes.files:
            if item.error is not None:
                print(f"{item.path}: error: {item.error}")
            elif item.report is not None:
                print(f"{item.path}: {item.report.summary()}")
            else:
                print(f"{item.path}: {item.status}")
        if not changes.files:
            print("no model file changed")
        if markdown is not None:
            api.write_text(changes.markdown(), markdown, overwrite=force)
        if changes.bad:
            raise typer.Exit(EXIT_BAD)
        raise typer.Exit(1 if fail_on_change and changes.changed_behaviour else 0)
