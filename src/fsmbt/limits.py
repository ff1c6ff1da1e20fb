"""Resource bounds: the one place where every default limit lives (docs/security.md).

fsmbt reads files from anywhere and runs unattended (batch, web), so every resource an input can
make it spend is bounded, and going past a bound is an ``InputError`` naming the input, the
limit and how to raise it - never a hang, a crash or an exhausted machine.

Each limit has a default here, an environment variable ``FSMBT_MAX_<NAME>`` (read when
:func:`current` is first called after :func:`reset`, i.e. once per process by default) and a
programmatic override: ``limits.current().with_changes(max_states=10)`` gives a copy, and
:func:`use` installs a copy for the process (:func:`changed`: for one ``with`` block) (a CLI flag is one ``use(current().with_changes(...))``
line). Readers call ``current()`` at each read, so an override applies to the next read.

This module imports nothing from fsmbt: ``model/`` and ``formats/`` use it without pulling in
higher layers. Cost: a dataclass copy per override; reading a limit is an attribute access.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, fields

ENV_PREFIX = "FSMBT_"


@dataclass(frozen=True)
class Limits:
    """Every bound fsmbt enforces, with its default.

    Attributes:
        max_input_bytes: largest model file (or text) a reader accepts, includes counted one by
            one; refused before any parser sees it. ``FSMBT_MAX_INPUT_BYTES``.
        max_xml_depth: deepest XML element nesting (the root is level 1); generated trees are
            deep, so this is high. ``FSMBT_MAX_XML_DEPTH``.
        max_json_depth: deepest JSON nesting (objects and arrays); the parser itself stops near
            Python's recursion limit, whichever is lower wins. ``FSMBT_MAX_JSON_DEPTH``.
        max_yaml_depth: deepest YAML nesting; libyaml's scanner is quadratic in flow depth, so
            this is lower than XML's. ``FSMBT_MAX_YAML_DEPTH``.
        max_states: most states (all levels) a read FSM may have. ``FSMBT_MAX_STATES``.
        max_nodes: most nodes (all trees) a read BT document may have. ``FSMBT_MAX_NODES``.
        max_include_depth: longest chain of BehaviorTree.CPP ``<include>`` files.
            ``FSMBT_MAX_INCLUDE_DEPTH``.
        max_tree_files: most ``.xml`` files one BehaviorTree.CPP read opens to find the trees
            its SubTrees name (a ``--trees`` folder, or the lookup in the file's own folder).
            ``FSMBT_MAX_TREE_FILES``.
        checker_max_states: reachable states the native checker explores per machine and in the
            product before it stops. ``FSMBT_MAX_CHECKER_STATES``.
        conversion_max_states: reachable states BT -> FSM conversion explores for one region of
            a reactive or stateful subtree (docs/conversion.md), with or without verification.
            ``FSMBT_MAX_CONVERSION_STATES``.
        max_data_values: most distinct values one SCXML data-model variable may take while
            its document is explored (an unbounded counter stops here, in a fraction of a second,
            instead of filling ``conversion_max_states``). ``FSMBT_MAX_DATA_VALUES``.
        checker_max_seconds: wall seconds the native checker may run. ``FSMBT_MAX_CHECKER_SECONDS``.
        nusmv_max_seconds: wall seconds one NuSMV run may take. ``FSMBT_MAX_NUSMV_SECONDS``.
        nusmv_max_memory_mb: address space of the NuSMV process (``RLIMIT_AS``), MiB.
            ``FSMBT_MAX_NUSMV_MEMORY_MB``.
        shortest_max_labels: most (state, passes) labels one stage's pass-count search
            settles for the coupled lower bound on a counterexample's length
            (``verify/coupling.py``; fifty times as many for one tree's searches together):
            past it the bound is weaker, never wrong, and the verdict may say "not known to be
            shortest". ``FSMBT_MAX_SHORTEST_LABELS``.
        llm_max_response_bytes: largest HTTP response body accepted from an LLM endpoint; the
            download stops at this size and the attempt fails. ``FSMBT_MAX_LLM_RESPONSE_BYTES``.
    """

    max_input_bytes: int = 64 * 1024 * 1024
    max_xml_depth: int = 10_000
    max_json_depth: int = 10_000
    max_yaml_depth: int = 3_000
    max_states: int = 1_000_000
    max_nodes: int = 2_000_000
    max_include_depth: int = 64
    max_tree_files: int = 1_000
    checker_max_states: int = 2_000_000
    conversion_max_states: int = 200_000
    max_data_values: int = 1_000
    checker_max_seconds: float = 600.0
    nusmv_max_seconds: float = 300.0
    nusmv_max_memory_mb: int = 4096
    shortest_max_labels: int = 40_000
    llm_max_response_bytes: int = 4 * 1024 * 1024

    def with_changes(self, **changes: int | float) -> Limits:
        """A copy with some limits changed (``with_changes(max_states=10)``).

        Raises:
            ValueError: an unknown limit name, or a value that is not positive.
        """
        known = {f.name for f in fields(self)}
        for name, value in changes.items():
            if name not in known:
                raise ValueError(f"unknown limit '{name}' (known: {', '.join(sorted(known))})")
            if not value > 0:
                raise ValueError(f"limit {name} must be positive, not {value!r}")
        return dataclasses.replace(self, **changes)  # type: ignore[arg-type]


def env_name(field_name: str) -> str:
    """The environment variable of a limit: ``max_states`` -> ``FSMBT_MAX_STATES``,
    ``checker_max_states`` -> ``FSMBT_MAX_CHECKER_STATES``."""
    name = field_name.upper()
    if not name.startswith("MAX_"):
        head, _, tail = name.partition("_MAX_")
        name = f"MAX_{head}_{tail}"
    return ENV_PREFIX + name


def from_environment(base: Limits | None = None, environ: dict[str, str] | None = None) -> Limits:
    """``base`` (the defaults) with every ``FSMBT_MAX_...`` variable that is set applied.

    Raises:
        ValueError: a variable that is not a positive number (named in the message).
    """
    base = base or Limits()
    environ = dict(os.environ) if environ is None else environ
    changes: dict[str, int | float] = {}
    for f in fields(base):
        raw = environ.get(env_name(f.name))
        if raw is None or not raw.strip():
            continue
        try:
            value: int | float = int(raw) if f.type in ("int", int) else float(raw)
        except ValueError:
            raise ValueError(f"{env_name(f.name)}={raw!r} is not a number") from None
        if not value > 0:
            raise ValueError(f"{env_name(f.name)}={raw!r} must be positive")
        changes[f.name] = value
    return base.with_changes(**changes) if changes else base


_current: Limits | None = None


def current() -> Limits:
    """The limits in force: the last :func:`use`, else the defaults plus the environment."""
    global _current
    if _current is None:
        _current = from_environment()
    return _current


def use(limits: Limits) -> Limits:
    """Install ``limits`` for this process; returns the previous ones (to restore them)."""
    global _current
    previous = current()
    _current = limits
    return previous


@contextmanager
def changed(**changes: int | float) -> Iterator[Limits]:
    """Within the block, the limits in force with ``changes`` (``max_states=10``); after it,
    the ones before, whatever the block raised - for a script or a test that needs other
    bounds for one call.

    Yields:
        The limits in force inside the block.
    """
    inside = current().with_changes(**changes)
    previous = use(inside)
    try:
        yield inside
    finally:
        use(previous)


def reset() -> None:
    """Forget overrides: the next :func:`current` reads the environment again."""
    global _current
    _current = None


def exceeded(what: str, limit_name: str, limit: int | float) -> str:
    """The standard wording of a limit error: what went past which limit, how to raise it.

    ``exceeded("the input's 70000000 bytes", "max_input_bytes", 67108864)``.
    """
    return f"{what} exceed(s) the limit of {limit} (raise it with {env_name(limit_name)})"
