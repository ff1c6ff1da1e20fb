"""The NuSMV rules registered by name, beside the ones ``encode_bt`` writes itself
(docs/semantics.md, "Node families"): the built-in loops and parallels of ``builtin_rules``,
and any rule added at run time with ``register_nusmv_rule`` for a kind whose declaration names
it in its ``nusmv`` field. ``encode_bt`` merges this table with its own into one dispatch table
per encoder.

Costs: dict reads; registering is O(1).
"""

from __future__ import annotations

from fsmbt.verify.nusmv.families import builtin_rules
from fsmbt.verify.nusmv.families.contract import NusmvRule

_BUILTIN: dict[str, NusmvRule] = dict(builtin_rules.RULE_TABLE)
_RULES: dict[str, NusmvRule] = dict(_BUILTIN)


def nusmv_rules() -> dict[str, NusmvRule]:
    """Every registered rule, by name (read-only: use ``register_nusmv_rule``)."""
    return _RULES


def register_nusmv_rule(name: str, rule: NusmvRule) -> None:
    """Add the NuSMV rule ``name`` (the ``nusmv`` field of the kinds it encodes).

    Raises:
        ValueError: ``name`` already has a rule.
    """
    if name in _RULES:
        raise ValueError(f"NuSMV rule {name!r} is already registered")
    _RULES[name] = rule


def unregister_nusmv_rule(name: str) -> None:
    """Remove a rule added with ``register_nusmv_rule``.

    Raises:
        ValueError: ``name`` is built in or not registered.
    """
    if name not in _RULES or name in _BUILTIN:
        raise ValueError(f"NuSMV rule {name!r} is not a registered extra rule")
    del _RULES[name]
