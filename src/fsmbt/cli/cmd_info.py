"""``fsmbt info``: the structure of a model at a glance (a table), or as JSON for scripts."""

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
from fsmbt.model.bt import BTDocument
from fsmbt.model.stats import BTStats, FSMStats, model_stats
from fsmbt.model.undeclared import summary as undeclared_summary
from fsmbt.model.undeclared import undeclared_leaf_types

#: Lists longer than this are cut in the table (``--json`` always has them all).
MAX_LISTED = 12


def register(app: typer.Typer) -> None:
    @app.command("info")
    @reads_models
    def info_command(
        model: Path = typer.Argument(..., help="Model file (FSM or BT, any format fsmbt reads)."),
        as_json: bool = typer.Option(False, "--json", help="Print the figures as JSON."),
        *,
        read: ReadOptions,
    ) -> None:
        """Structure at a glance: states, events, entry/loop states; BT nodes, depth, breadth.

        FSM: states, transitions, events, initial and final states, the entry state and the
        loop states of the LEBT structure (docs/conversion.md), hierarchy. BT: nodes by kind and type, depth, breadth,
        leaves, trees and SubTree references.
        """
        loaded = api.load(
            model,
            read.format,
            options=read,
        )
        stats = model_stats(loaded.model)
        undeclared = (
            undeclared_leaf_types(loaded.model) if isinstance(loaded.model, BTDocument) else None
        )
        blockers = [str(b) for b in api.conversion_blockers(loaded.model)]
        if as_json:
            extra = {} if undeclared is None else {"undeclared_leaf_types": dict(undeclared)}
            print(
                json.dumps(
                    {
                        "file": str(model),
                        **stats.to_dict(),
                        **extra,
                        "conversion_blockers": blockers,
                    },
                    indent=2,
                    ensure_ascii=False,
                )
            )
            return
        table = _fsm_table(stats) if isinstance(stats, FSMStats) else _bt_table(stats)
        table.title = escape(str(model))
        console = Console()
        console.print(table)
        if isinstance(stats, BTStats) and len(stats.per_tree) > 1:
            console.print(_per_tree_table(stats))
        if undeclared:
            print(f"note: {undeclared_summary(undeclared)}; declare them with --node-models FILE")
        if blockers:
            console.print(f"conversion would refuse ({len(blockers)}):")
            for text in blockers:
                console.print(f"  - {escape(text)}")


def _listed(items: list[str]) -> str:
    if not items:
        return "-"
    shown = ", ".join(items[:MAX_LISTED])
    more = len(items) - MAX_LISTED
    return escape(shown + (f", … (+{more})" if more > 0 else ""))


def _table() -> Table:
    table = Table(show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("")
    return table


def _fsm_table(s: FSMStats) -> Table:
    table = _table()
    kind = "hierarchical FSM" if s.hierarchical else "FSM"
    table.add_row("model", f"{kind} {escape(s.name)}")
    table.add_row(
        "states", str(s.states) + (f" (all levels: {s.all_states})" if s.hierarchical else "")
    )
    table.add_row(
        "transitions",
        str(s.transitions)
        + (" + the initial one" if s.initial_event is not None else "")
        + (f" (all levels: {s.all_transitions})" if s.hierarchical else ""),
    )
    table.add_row("events", f"{len(s.events)}: {_listed(s.events)}")
    start = f"{escape(s.start)} --{escape(s.initial_event or '')}--> " if s.start else ""
    table.add_row("initial", f"{start}{escape(str(s.initial))}")
    table.add_row("entry state", escape(str(s.entry_state)))
    table.add_row("loop states", _listed(s.loop_states))
    table.add_row("final states", _listed(s.finals))
    table.add_row("unreachable", _listed(s.unreachable))
    if s.hierarchical:
        table.add_row("composite states", str(s.composite_states))
        table.add_row("parallel states", str(s.parallel_states))
        table.add_row("nesting depth", str(s.nesting_depth))
    return table


def _bt_table(s: BTStats) -> Table:
    table = _table()
    table.add_row("model", f"behavior tree, main tree {escape(str(s.main_tree))}")
    table.add_row("trees", str(s.trees))
    table.add_row("nodes", str(s.nodes))
    table.add_row("by kind", escape(", ".join(f"{k} {n}" for k, n in s.by_kind.items())) or "-")
    table.add_row("by type", _listed([f"{t} {n}" for t, n in s.by_type.items()]))
    table.add_row("leaves", f"{s.leaves} ({s.actions} actions, {s.conditions} conditions)")
    table.add_row("subtree references", str(s.subtree_references))
    table.add_row("depth (main tree)", str(s.depth))
    table.add_row("breadth (main tree)", str(s.breadth))
    table.add_row("most children", str(s.max_children))
    if s.subtree_references:
        expanded = "-" if s.expanded_depth is None else str(s.expanded_depth)
        table.add_row("depth, subtrees expanded", expanded)
    return table


def _per_tree_table(s: BTStats) -> Table:
    table = Table(
        "tree", "nodes", "depth", "breadth", "leaves", title="per tree", title_justify="left"
    )
    for t in s.per_tree:
        table.add_row(escape(t.id), str(t.nodes), str(t.depth), str(t.breadth), str(t.leaves))
    return table
