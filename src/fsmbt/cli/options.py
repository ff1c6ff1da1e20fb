"""Options several commands share, declared once so they read and behave the same everywhere."""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

import typer

#: ``--node-models FILE`` (repeatable): BehaviorTree.CPP ``<TreeNodesModel>`` files (Nav2's
#: ``nav2_tree_nodes.xml``, a Groot palette) that declare the custom nodes a tree uses.
NODE_MODELS_HELP = (
    "a file with <TreeNodesModel> declarations of custom BT nodes (e.g. Nav2's "
    "nav2_tree_nodes.xml); repeatable"
)
#: ``--nodes PROFILE|FILE`` (repeatable, comma lists allowed): node libraries
#: (``fsmbt.model.nodes.library``, docs/semantics.md §10).
NODES_HELP = (
    "node library: a profile (nav2, moveit_pro) or a YAML/JSON file declaring custom "
    "nodes as aliases, exact semantics or abstractions; repeatable, comma lists allowed"
)
#: ``--abstract FAMILIES``: abstraction families (``time``, ``blackboard``).
ABSTRACT_HELP = (
    "model these node families as abstractions whose input the environment "
    "chooses: time (Sleep, Delay, Timeout), blackboard (Precondition, "
    "ScriptCondition, BlackboardCheck*, ...); comma list"
)


#: ``--trees PATH`` (repeatable): files (or folders of .xml files) whose ``<BehaviorTree>`` s the
#: SubTrees may name, as BehaviorTree.CPP's ``registerBehaviorTreeFromFile`` (docs/cli.md).
TREES_HELP = (
    "a BehaviorTree.CPP file, or a folder of them, whose trees SubTrees may refer to (as "
    "registerBehaviorTreeFromFile); repeatable. Without it, a SubTree ID found nowhere else is "
    "looked up in the other .xml files of the referencing file's folder"
)
#: ``--include-root DIR``: ``<include path>`` may resolve anywhere under DIR (docs/security.md).
INCLUDE_ROOT_HELP = (
    "BehaviorTree.CPP <include path=...> may resolve anywhere under DIR (default: the folder "
    "of the file read, and its subfolders)"
)


def trees_option() -> list[Path]:
    """The ``--trees`` option (a fresh ``typer.Option`` per command)."""
    return typer.Option([], "--trees", help=TREES_HELP)  # type: ignore[no-any-return]


def include_root_option() -> Path | None:
    """The ``--include-root`` option (a fresh ``typer.Option`` per command)."""
    return typer.Option(  # type: ignore[no-any-return]
        None, "--include-root", help=INCLUDE_ROOT_HELP, file_okay=False
    )


def node_models_option() -> list[Path]:
    """The ``--node-models`` option (a fresh ``typer.Option`` per command)."""
    return typer.Option([], "--node-models", help=NODE_MODELS_HELP, exists=False)  # type: ignore[no-any-return]


def nodes_option() -> list[str]:
    """The ``--nodes`` option (a fresh ``typer.Option`` per command)."""
    return typer.Option([], "--nodes", help=NODES_HELP)  # type: ignore[no-any-return]


def abstract_option() -> list[str]:
    """The ``--abstract`` option (a fresh ``typer.Option`` per command)."""
    return typer.Option([], "--abstract", help=ABSTRACT_HELP)  # type: ignore[no-any-return]


def reader_options(
    node_models: list[Path] | None,
    nodes: list[str] | None = None,
    abstract: list[str] | None = None,
    trees: list[Path] | None = None,
    include_root: Path | None = None,
) -> dict[str, object] | None:
    """The reader options for ``fsmbt.api.load`` from the shared CLI options.

    Args:
        node_models: ``--node-models`` files.
        nodes: ``--nodes`` profiles and files.
        abstract: ``--abstract`` families.
        trees: ``--trees`` files and folders.
        include_root: ``--include-root`` folder.

    Returns:
        The options dict, or ``None`` when none was given.
    """
    options: dict[str, object] = {}
    if node_models:
        options["node_models"] = [str(path) for path in node_models]
    if nodes:
        options["nodes"] = list(nodes)
    if abstract:
        options["abstract"] = list(abstract)
    if trees:
        options["trees"] = [str(path) for path in trees]
    if include_root is not None:
        options["include_root"] = str(include_root)
    return options or None


#: ``--max-states N``: one state limit for the native checker and for BT -> FSM exploration.
MAX_STATES_HELP = (
    "most reachable states explored (BT->FSM regions, the native checker, its "
    "product); default: FSMBT_MAX_CONVERSION_STATES / FSMBT_MAX_CHECKER_STATES "
    "(200000 / 2000000)"
)


def max_states_option() -> int | None:
    """The ``--max-states`` option (``None``: the limits in force, ``fsmbt.limits``)."""
    return typer.Option(None, "--max-states", min=1, help=MAX_STATES_HELP)  # type: ignore[no-any-return]


def timeout_option() -> float | None:
    """``--timeout SECONDS``: the wall-time cap of the native checker and of each NuSMV run
    (``fsmbt.limits``: ``checker_max_seconds`` and ``nusmv_max_seconds``)."""
    return typer.Option(
        None,
        "--timeout",
        min=0.001,
        help="seconds the checker, and each NuSMV run, may take; past it: exit 4",  # type: ignore[no-any-return]
    )


def nusmv_memory_option() -> int | None:
    """``--nusmv-memory MIB``: NuSMV's address-space cap (``nusmv_max_memory_mb``)."""
    return typer.Option(
        None,
        "--nusmv-memory",
        min=1,
        help="MiB of memory NuSMV may use "  # type: ignore[no-any-return]
        "(RLIMIT_AS); past it: exit 4",
    )


def apply_engine_caps(timeout: float | None, nusmv_memory: int | None) -> None:
    """Install ``--timeout`` / ``--nusmv-memory`` as the process's limits (``fsmbt.limits``)."""
    from fsmbt import limits

    changes: dict[str, int | float] = {}
    if timeout is not None:
        changes["nusmv_max_seconds"] = timeout
        changes["checker_max_seconds"] = timeout
    if nusmv_memory is not None:
        changes["nusmv_max_memory_mb"] = nusmv_memory
    if changes:
        limits.use(limits.current().with_changes(**changes))


# -- the reader options, declared once for every command that reads a model -------------------

#: ``--from FORMAT``: the input's format (detected from content and name when omitted).
FROM_HELP = "input format (default: detected from the content, then the extension)"
#: ``--data inputs``: SCXML conditions on data the file cannot compute are environment inputs.
DATA_HELP = (
    "SCXML: 'inputs' reads conditions on data the machine cannot compute as environment "
    "inputs (docs/formats/scxml.md)"
)

#: The reader parameters ``reads_models`` adds: (name, annotation, a fresh typer.Option).
_READ_PARAMETERS: tuple[tuple[str, Any, Callable[[], Any]], ...] = (
    ("source_format", str | None, lambda: typer.Option(None, "--from", help=FROM_HELP)),
    ("node_models", list[Path], node_models_option),
    ("nodes", list[str], nodes_option),
    ("abstract", list[str], abstract_option),
    ("trees", list[Path], trees_option),
    ("include_root", Path | None, include_root_option),
    ("data", str | None, lambda: typer.Option(None, "--data", help=DATA_HELP)),
    (
        "machine",
        str | None,
        lambda: typer.Option(None, "--machine", help="SMACH: the top-level container to read"),
    ),
    (
        "behaviour",
        str | None,
        lambda: typer.Option(None, "--behaviour", help="FlexBE: the Behavior class to read"),
    ),
    (
        "strict",
        bool,
        lambda: typer.Option(
            False,
            "--strict",
            help="refuse what a reader would read as an approximation with a warning (FlexBE: "
            "an embedded behaviour whose file is not found); validate: warnings are errors",
        ),
    ),
    (
        "no_profiles",
        bool,
        lambda: typer.Option(
            False,
            "--no-profiles",
            help="BT: do not apply the profiles fsmbt finds by itself (a known project's "
            "nodes, a *_tree_nodes.xml beside the file or in its package)",
        ),
    ),
    (
        "initial",
        str | None,
        lambda: typer.Option(
            None, "--initial", help="tables: the initial state (default: the first row's source)"
        ),
    ),
)
#: Every CLI flag of the reader options (the vocabulary test walks the commands for them).
READ_FLAGS = (
    "--from",
    "--node-models",
    "--nodes",
    "--abstract",
    "--trees",
    "--include-root",
    "--data",
    "--strict",
    "--no-profiles",
)


def reads_models(command: Callable[..., Any]) -> Callable[..., Any]:
    """Give a command every reader option, under one name each, as one ``read: ReadOptions``.

    Why: each option a reader takes must be offered by every command that reads models, with
    the same flag and meaning (issue "one vocabulary"). The command declares a parameter
    ``read`` (a ``fsmbt.api_types.ReadOptions``) instead of the flags; this decorator puts the
    flags into the signature typer reads and builds the validated ``ReadOptions`` (an invalid
    value is the located ``InputError`` of ``fsmbt.api_types``: exit 2).
    """
    from fsmbt.api_types import read_options

    signature = inspect.signature(command, eval_str=True)
    kept = [p for name, p in signature.parameters.items() if name != "read"]
    added = [
        inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=make(), annotation=kind)
        for name, kind, make in _READ_PARAMETERS
    ]
    names = [name for name, _kind, _make in _READ_PARAMETERS]

    @functools.wraps(command)
    def wrapper(**kwargs: Any) -> Any:
        given = {name: kwargs.pop(name) for name in names}
        fields: dict[str, Any] = {
            key: [str(v) for v in value] if isinstance(value, list) else value
            for key, value in given.items()
            if key != "source_format" and value not in (None, [], False)
        }
        if isinstance(fields.get("include_root"), Path):
            fields["include_root"] = str(fields["include_root"])
        read = read_options(format=given["source_format"], **fields)
        return command(read=read, **kwargs)

    parameters = [
        p.replace(kind=inspect.Parameter.KEYWORD_ONLY)
        if p.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
        else p
        for p in kept
    ] + added
    wrapper.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    wrapper.__annotations__ = {p.name: p.annotation for p in parameters}
    del wrapper.__wrapped__  # typer must read the new signature, not the command's
    return wrapper
