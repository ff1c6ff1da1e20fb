"""Options several commands share, declared once so they read and behave the same everywhere."""

from __future__ import annotations

from pathlib import Path

import typer

#: ``--node-models FILE`` (repeatable): BehaviorTree.CPP ``<TreeNodesModel>`` files (Nav2's
#: ``nav2_tree_nodes.xml``, a Groot palette) that declare the custom nodes a tree uses.
NODE_MODELS_HELP = ("a file with <TreeNodesModel> declarations of custom BT nodes (e.g. Nav2's "
                    "nav2_tree_nodes.xml); repeatable")


def node_models_option() -> list[Path]:
    """The ``--node-models`` option (a fresh ``typer.Option`` per command)."""
    return typer.Option([], "--node-models", help=NODE_MODELS_HELP, exists=False)  # type: ignore[no-any-return]


def reader_options(node_models: list[Path] | None) -> dict[str, object] | None:
    """The reader options for ``fsmbt.api.load`` from the shared CLI options."""
    if not node_models:
        return None
    return {"node_models": [str(path) for path in node_models]}


#: ``--max-states N``: one state limit for the native checker and for BT -> FSM exploration.
MAX_STATES_HELP = ("most reachable states explored (BT->FSM regions, the native checker, its "
                   "product); default: FSMBT_MAX_CONVERSION_STATES / FSMBT_MAX_CHECKER_STATES "
                   "(200000 / 2000000)")


def max_states_option() -> int | None:
    """The ``--max-states`` option (``None``: the limits in force, ``fsmbt.limits``)."""
    return typer.Option(None, "--max-states", min=1, help=MAX_STATES_HELP)  # type: ignore[no-any-return]
