"""``fsmbt render``: draw a model with Graphviz (SVG, PNG, PDF, or the DOT source)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from fsmbt import api
from fsmbt.cli import EXIT_INTERNAL, fail
from fsmbt.cli.options import (
    abstract_option,
    node_models_option,
    nodes_option,
    reader_options,
)
from fsmbt.render import DEFAULT_MAX_NODES, GraphvizError, render_model


def register(app: typer.Typer) -> None:
    @app.command("render")
    def render_command(
        model: Path = typer.Argument(..., help="Model file (FSM or BT, any format fsmbt reads)."),
        output: Path = typer.Option(..., "-o", "--output",
                                    help="Picture to write: .svg, .png, .pdf, or .dot (source)."),
        from_format: Optional[str] = typer.Option(None, "--from",
                                                  help="Input format (default: detected)."),
        node_models: list[Path] = node_models_option(),
        nodes: list[str] = nodes_option(),
        abstract: list[str] = abstract_option(),
        force: bool = typer.Option(False, "--force", help="Overwrite OUTPUT if it exists."),
        expand_subtrees: bool = typer.Option(
            False, "--expand-subtrees",
            help="BT: draw the main tree with each SubTree's tree inlined below it."),
        max_nodes: int = typer.Option(DEFAULT_MAX_NODES, "--max-nodes", min=1,
                                      help="Refuse models with more states/nodes than this."),
    ) -> None:
        """Draw MODEL: FSMs as state diagrams, behavior trees top-down with the usual symbols."""
        loaded = api.load(model, from_format, options=reader_options(node_models, nodes, abstract)).model
        try:
            written = render_model(loaded, output, overwrite=force,
                                   expand_subtrees=expand_subtrees, max_nodes=max_nodes)
        except GraphvizError as exc:
            raise fail(str(exc), EXIT_INTERNAL) from None
        print(f"wrote {written}")
        for blocker in api.conversion_blockers(loaded):
            print(f"note: conversion would refuse: {blocker}")
