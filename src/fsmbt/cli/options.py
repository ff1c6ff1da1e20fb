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


def timeout_option() -> float | None:
    """``--timeout SECONDS``: the wall-time cap of each NuSMV run (``fsmbt.limits``
    ``nusmv_max_seconds``; the native checker is bounded by its state limit)."""
    return typer.Option(None, "--timeout", min=0.001, help="seconds NuSMV may run "  # type: ignore[no-any-return]
                        "(--engine nusmv|both); past it: exit 4")


def nusmv_memory_option() -> int | None:
    """``--nusmv-memory MIB``: NuSMV's address-space cap (``nusmv_max_memory_mb``)."""
    return typer.Option(None, "--nusmv-memory", min=1, help="MiB of memory NuSMV may use "  # type: ignore[no-any-return]
                        "(RLIMIT_AS); past it: exit 4")


def apply_engine_caps(timeout: float | None, nusmv_memory: int | None) -> None:
    """Install ``--timeout`` / ``--nusmv-memory`` as the process's limits (``fsmbt.limits``)."""
    from fsmbt import limits

    changes: dict[str, int | float] = {}
    if timeout is not None:
        changes["nusmv_max_seconds"] = timeout
    if nusmv_memory is not None:
        changes["nusmv_max_memory_mb"] = nusmv_memory
    if changes:
        limits.use(limits.current().with_changes(**changes))
