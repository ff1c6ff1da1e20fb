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
