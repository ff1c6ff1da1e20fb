"""The one table the interpreter dispatches on: handler name -> ``FamilyRule`` (the contract is
``fsmbt.semantics.families.contract``; docs/semantics.md, "Node families").

The built-in families are listed once, in ``BUILTIN_FAMILIES``; ``register_rule`` adds a rule at
run time (a tool's own node kind: declare it with ``fsmbt.model.nodes.register`` naming this
handler, then register its rule here), and the next ``BTInterpreter`` / ``CompiledTree`` built
uses it.

Costs: ``rules()`` is a dict read; registering is O(1).
"""

from __future__ import annotations

from types import ModuleType

from fsmbt.semantics.families import (
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
from fsmbt.semantics.families.contract import FamilyRule
from fsmbt.semantics.families.rule_table import RuleTable

#: The built-in family modules, each exporting ``RULES``.
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


_TABLE: RuleTable[FamilyRule] = RuleTable("tick rule", BUILTIN_FAMILIES)


def rules() -> dict[str, FamilyRule]:
    """Every registered rule, by handler name (read-only: use ``register_rule``)."""
    return _TABLE.rules


def rule(handler: str) -> FamilyRule | None:
    """The rule of ``handler``, ``None`` when none is registered."""
    return _TABLE.rules.get(handler)


def register_rule(handler: str, family_rule: FamilyRule) -> None:
    """Add the rule of a new handler name.

    Raises:
        ValueError: ``handler`` already has a rule.
    """
    _TABLE.register(handler, family_rule)


def unregister_rule(handler: str) -> None:
    """Remove a rule added with ``register_rule`` (a built-in one cannot be removed).

    Raises:
        ValueError: ``handler`` is a built-in rule or not registered.
    """
    _TABLE.unregister(handler)
