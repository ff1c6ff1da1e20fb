"""The NuSMV rules by name, the one table ``encode_bt`` dispatches on (docs/semantics.md,
"Node families"; docs/nusmv.md): the built-in families' tables (``BUILTIN_FAMILIES``, one module
per family, named as in ``fsmbt.semantics.families``, each exporting ``RULES``), and any rule
added at run time with ``register_nusmv_rule`` for a kind whose declaration names it in its
``nusmv`` field.

Costs: dict reads; registering is O(1).
"""

from __future__ import annotations

from types import ModuleType

from fsmbt.semantics.families.rule_table import RuleTable
from fsmbt.verify.nusmv.families import (
    conditional,
    gates,
    loops,
    manual,
    nav2,
    once,
    parallel,
    reactive,
    sequence,
    status_map,
    wrappers,
)
from fsmbt.verify.nusmv.families.contract import NusmvRule

#: The built-in family modules, each exporting ``RULES`` (rule name -> ``NusmvRule``).
BUILTIN_FAMILIES: tuple[ModuleType, ...] = (
    sequence,
    reactive,
    parallel,
    conditional,
    status_map,
    loops,
    once,
    wrappers,
    manual,
    nav2,
    gates,
)


_TABLE: RuleTable[NusmvRule] = RuleTable("NuSMV rule", BUILTIN_FAMILIES)


def nusmv_rules() -> dict[str, NusmvRule]:
    """Every registered rule, by name (read-only: use ``register_nusmv_rule``)."""
    return _TABLE.rules


def register_nusmv_rule(name: str, rule: NusmvRule) -> None:
    """Add the NuSMV rule ``name`` (the ``nusmv`` field of the kinds it encodes).

    Raises:
        ValueError: ``name`` already has a rule.
    """
    _TABLE.register(name, rule)


def unregister_nusmv_rule(name: str) -> None:
    """Remove a rule added with ``register_nusmv_rule``.

    Raises:
        ValueError: ``name`` is built in or not registered.
    """
    _TABLE.unregister(name)
