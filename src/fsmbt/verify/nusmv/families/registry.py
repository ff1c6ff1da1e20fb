"""The NuSMV rules by name, the one table ``encode_bt`` dispatches on (docs/semantics.md,
"Node families"; docs/nusmv.md): the built-in families' tables (``BUILTIN_FAMILIES``, one module
per family, named as in ``fsmbt.semantics.families``, each exporting ``RULES`` and ``TRAITS``),
and any rule added at run time with ``register_nusmv_rule`` for a kind whose declaration names
it in its ``nusmv`` field. ``rule_traits(name)`` is what the encoder's whole-tree checks read of
a rule (``contract.RuleTraits``; ``NO_TRAITS`` for a rule its family does not describe).

Rules: a family's ``TRAITS`` names only rules of its own ``RULES`` (checked when the table is
built).

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
from fsmbt.verify.nusmv.families.contract import NO_TRAITS, NusmvRule, RuleTraits

#: The built-in family modules, each exporting ``RULES`` (rule name -> ``NusmvRule``) and
#: ``TRAITS`` (rule name -> ``RuleTraits``).
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


def _builtin_traits() -> dict[str, RuleTraits]:
    traits: dict[str, RuleTraits] = {}
    for module in BUILTIN_FAMILIES:
        extra = set(module.TRAITS) - set(module.RULES)
        if extra:
            raise ValueError(f"{module.__name__}: TRAITS of rules it does not define: {extra}")
        traits.update(module.TRAITS)
    return traits


_TRAITS: dict[str, RuleTraits] = _builtin_traits()


def nusmv_rules() -> dict[str, NusmvRule]:
    """Every registered rule, by name (read-only: use ``register_nusmv_rule``)."""
    return _TABLE.rules


def rule_traits(name: str) -> RuleTraits:
    """What the encoder's whole-tree checks read of rule ``name`` (``NO_TRAITS`` if none)."""
    return _TRAITS.get(name, NO_TRAITS)


def register_nusmv_rule(name: str, rule: NusmvRule, traits: RuleTraits = NO_TRAITS) -> None:
    """Add the NuSMV rule ``name`` (the ``nusmv`` field of the kinds it encodes) with its
    ``traits`` (``contract.RuleTraits``; the defaults refuse a child that may skip).

    Raises:
        ValueError: ``name`` already has a rule.
    """
    _TABLE.register(name, rule)
    if traits is not NO_TRAITS:
        _TRAITS[name] = traits


def unregister_nusmv_rule(name: str) -> None:
    """Remove a rule added with ``register_nusmv_rule``.

    Raises:
        ValueError: ``name`` is built in or not registered.
    """
    _TABLE.unregister(name)
    _TRAITS.pop(name, None)
