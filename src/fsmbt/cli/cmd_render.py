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
from fsmbt.render import DEFAULT_MAX_NODES, GraphvizError, render_model, render_pages


def _cli_words(note: str) -> str:
    """A library note with its option names as this command's flags."""
    return (
        note.replace("composite=NAME", "--composite NAME")
        .replace("level=N", "--level N")
        .replace("tree=ID", "--tree ID")
        .replace("focus=PATH", "--focus PATH")
        .replace("depth=N", "--depth N")
        .replace("pages=DIR", "--pages DIR")
    )


def register(app: typer.Typer) -> None:
    @app.command("render")
    @reads_models
    def render_command(
        model: Path = typer.Argument(..., help="Model file (FSM or BT, any format fsmbt reads)."),
        output: Path | None = typer.Option(
            None,
            "-o",
            "--output",
            help="Picture to write: .svg, .png, .pdf, or .dot (source); with --pages, its "
            "suffix is the pictures' format (default .svg).",
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
            "--depth",
            min=0,
            help="FSM: open composite states down to this nesting level (0: top machine "
            "only, composites drawn as closed boxes). BT: draw this many levels below the "
            "root (0: the root alone), deeper subtrees folded into '[k nodes]' boxes.",
        ),
        focus: str | None = typer.Option(
            None,
            "--focus",
            help="BT: draw only the subtree under this node: its path as a fold box shows it "
            "(0/2/1) or its name. FSM: draw only this composite state (path A/B, as "
            "--composite).",
        ),
        pages: Path | None = typer.Option(
            None,
            "--pages",
            help="FSM: write one picture per level into this folder: top.svg (composites "
            "closed) and one per composite state, data guards on the arrows. BT: one picture "
            "per BehaviorTree, the main tree first.",
        ),
        composite: str | None = typer.Option(
            None, "--composite", help="FSM: draw only this composite state (path A/B)."
        ),
        tree: str | None = typer.Option(None, "--tree", help="BT: draw only this tree."),
        *,
        read: ReadOptions,
    ) -> None:
        """Draw MODEL: FSMs as state diagrams, behavior trees top-down with the usual symbols.

        A picture is made to be read at 100 %: within 4096 x 4096 pixels, no side more than 4x
        the other; big behavior trees are folded (see --depth, --focus), big FSMs drawn by level.
        """
        loaded = api.load(
            model,
            read.format,
            options=read,
        ).model
        notes: list[str] = []
        if pages is not None:
            fmt = output.suffix.lstrip(".") if output is not None else "svg"
            try:
                drawn = render_pages(
                    loaded,
                    pages,
                    fmt=fmt or "svg",
                    overwrite=force,
                    max_nodes=max_nodes,
                    notes=notes,
                )
            except GraphvizError as exc:
                raise fail(str(exc), EXIT_INTERNAL) from None
            print(f"wrote {len(drawn)} pictures into {pages}: " + ", ".join(p.name for p in drawn))
            for note in notes:
                print(f"note: {_cli_words(note)}", file=sys.stderr)
            return
        if output is None:
            raise fail("missing option -o/--output (or --pages DIR)")
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
                focus=focus,
            )
        except GraphvizError as exc:
            raise fail(str(exc), EXIT_INTERNAL) from None
        print(f"wrote {written}")
        for note in notes:
            print(f"note: {_cli_words(note)}", file=sys.stderr)
        for blocker in api.conversion_blockers(loaded):
            print(f"note: conversion would refuse: {blocker}", file=sys.stderr)
