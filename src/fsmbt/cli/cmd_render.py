"""``fsmbt render``: draw a model with Graphviz (SVG, PNG, PDF, or the DOT source)."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from fsmbt import api
from fsmbt.api_types import ReadOptions
from fsmbt.cli import EXIT_INTERNAL, fail
from fsmbt.cli.options import (
    reads_models,
)
from fsmbt.render import DEFAULT_MAX_NODES, GraphvizError, render_model


def _cli_words(note: str) -> str:
    """A library note with its option names as this command's flags."""
    return (
        note.replace("composite=NAME", "--composite NAME")
        .replace("level=N", "--level N")
        .replace("tree=ID", "--tree ID")
    )


def register(app: typer.Typer) -> None:
    @app.command("render")
    @reads_models
    def render_command(
        model: Path = typer.Argument(..., help="Model file (FSM or BT, any format fsmbt reads)."),
        output: Path = typer.Option(
            ..., "-o", "--output", help="Picture to write: .svg, .png, .pdf, or .dot (source)."
        ),
        force: bool = typer.Option(False, "--force", help="Overwrite OUTPUT if it exists."),
        expand_subtrees: bool = typer.Option(
            False,
            "--expand-subtrees",
            help="BT: draw the main tree with each SubTree's tree inlined below it.",
        ),
        max_nodes: int = typer.Option(
            DEFAULT_MAX_NODES,
            "--max-nodes",
            min=1,
            help="Refuse models with more states/nodes than this.",
        ),
        level: int | None = typer.Option(
            None,
            "--level",
            min=0,
            help="FSM: open composite states down to this nesting level (0: top machine only).",
        ),
        composite: str | None = typer.Option(
            None, "--composite", help="FSM: draw only this composite state (path A/B)."
        ),
        tree: str | None = typer.Option(None, "--tree", help="BT: draw only this tree."),
        *,
        read: ReadOptions,
    ) -> None:
        """Draw MODEL: FSMs as state diagrams, behavior trees top-down with the usual symbols."""
        loaded = api.load(
            model,
            read.format,
            options=read,
        ).model
        notes: list[str] = []
        try:
            written = render_model(
                loaded,
                output,
                overwrite=force,
                expand_subtrees=expand_subtrees,
                max_nodes=max_nodes,
                level=level,
                composite=composite,
                tree=tree,
                notes=notes,
            )
        except GraphvizError as exc:
            raise fail(str(exc), EXIT_INTERNAL) from None
        print(f"wrote {written}")
        for note in notes:
            print(f"note: {_cli_words(note)}", file=sys.stderr)
        for blocker in api.conversion_blockers(loaded):
            print(f"note: conversion would refuse: {blocker}", file=sys.stderr)
