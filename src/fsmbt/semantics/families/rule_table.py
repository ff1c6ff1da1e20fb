"""A table of rules by name: the built-in family modules' ``RULES`` merged once, plus rules a
tool registers at run time. One kernel for the two tables keyed by a node kind's rule name - the
interpreter's tick rules (``semantics.families.registry``) and the NuSMV encoder's
(``verify.nusmv.families.registry``) - so both refuse the same things with the same words.

Rules: a name defined by two built-in modules is an error when the table is built; registering a
name that has a rule is refused; only a registered (not built-in) rule can be removed.

Costs: building is O(rules); a lookup, ``register`` and ``unregister`` are O(1).
"""

from __future__ import annotations

from collections.abc import Iterable
from types import ModuleType
from typing import Generic, TypeVar

R = TypeVar("R")


class RuleTable(Generic[R]):
    """Rules by name (``what`` names them in errors: ``"tick rule"``, ``"NuSMV rule"``).

    Args:
        what: what a rule is called in error messages.
        modules: the built-in family modules, each exporting ``RULES`` (name -> rule).

    Raises:
        ValueError: two modules define the same name.
    """

    def __init__(self, what: str, modules: Iterable[ModuleType]) -> None:
        self.what = what
        builtin: dict[str, R] = {}
        for module in modules:
            for name, rule in module.RULES.items():
                if name in builtin:
                    raise ValueError(f"{what} {name!r} is defined twice ({module.__name__})")
                builtin[name] = rule
        self.builtin = frozenset(builtin)
        #: Every rule by name (read-only for callers: use ``register`` / ``unregister``).
        self.rules: dict[str, R] = builtin

    def register(self, name: str, rule: R) -> None:
        """Add the rule ``name``.

        Raises:
            ValueError: ``name`` already has a rule.
        """
        if name in self.rules:
            raise ValueError(f"{self.what} {name!r} is already registered")
        self.rules[name] = rule

    def unregister(self, name: str) -> None:
        """Remove a rule added with ``register`` (a built-in one cannot be removed).

        Raises:
            ValueError: ``name`` is built in or not registered.
        """
        if name not in self.rules or name in self.builtin:
            raise ValueError(f"{self.what} {name!r} is not a registered extra rule")
        del self.rules[name]


__all__ = ["RuleTable"]
