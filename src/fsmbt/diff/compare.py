"""One diff of two models or two files: the behaviour, then the edit script (docs/diff.md)."""

from __future__ import annotations

from pathlib import Path

from fsmbt import api
from fsmbt.diff.behaviour import DEFAULT_MAX_GROUPS, behaviour_diff
from fsmbt.diff.report import DiffReport
from fsmbt.diff.structure import edit_script
from fsmbt.verify.native import DEFAULT_MAX_STATES


def diff_models(
    old: api.Model,
    new: api.Model,
    *,
    old_name: str = "OLD",
    new_name: str = "NEW",
    max_groups: int = DEFAULT_MAX_GROUPS,
    loop: bool = False,
    max_states: int = DEFAULT_MAX_STATES,
) -> DiffReport:
    """Compare two models (any kinds the verifier pairs).

    Raises:
        InputError: a pair that cannot be compared, or over the checker's limits.
    """
    behaviour = behaviour_diff(old, new, max_groups=max_groups, loop=loop, max_states=max_states)
    return DiffReport(
        old_name,
        new_name,
        api.model_kind(old),
        api.model_kind(new),
        behaviour,
        edit_script(old, new),
    )


def diff_files(
    old: str | Path,
    new: str | Path,
    *,
    max_groups: int = DEFAULT_MAX_GROUPS,
    loop: bool = False,
    options: dict[str, object] | api.ReadOptions | None = None,
) -> tuple[api.Loaded, api.Loaded, DiffReport]:
    """Read two model files and diff them; returns both loaded models and the report.

    Raises:
        InputError, UnsupportedError: unreadable models (located) or a pair that cannot be
        compared.
    """
    first = api.load(old, options=options)
    second = api.load(new, options=options)
    report = diff_models(
        first.model,
        second.model,
        old_name=str(old),
        new_name=str(new),
        max_groups=max_groups,
        loop=loop,
    )
    return first, second, report
