"""Fragments and the small node shapes the structuring composes (docs/conversion.md,
"The structured style").

A *fragment* is what "run from this state until the region is left" becomes: a node, or a
``Term`` - the region is left at once with a status, after a Script that reports a container's
outcome when the parent dispatches on it. Composition rules (``then``, ``branch``) pick the
smallest built-in shape for a state whose two statuses lead to two fragments; ``sequence`` and
``fallback`` flatten nested nodes of their own kind, so a pipeline of 1 000 states is one
``Sequence`` of depth 2. ``switch_chain`` dispatches on a blackboard entry with ``Switch2`` ..
``Switch6``, chaining through the default child past six cases.

Costs: every helper is O(children).
"""

from __future__ import annotations

from dataclasses import dataclass

from fsmbt.convert.structured.builder import always, control, decorator, script
from fsmbt.model.bt import BTNode
from fsmbt.semantics.outcome_rules import FAILURE, SUCCESS

#: Most cases one Switch node takes (BehaviorTree.CPP 4.8.2 registers Switch2 .. Switch6).
MAX_CASES = 6


@dataclass(frozen=True)
class Term:
    """Leaving the region with ``status``; ``report``: ``(entry, value)`` written first."""

    status: str
    report: tuple[str, str] | None = None

    @property
    def pure(self) -> bool:
        return self.report is None

    def node(self) -> BTNode:
        """A fresh node doing it (terminal leaves may appear more than once in a tree)."""
        if self.report is None:
            return always(self.status == SUCCESS)
        node = script(*self.report)
        return node if self.status == SUCCESS else decorator("ForceFailure", node)


Fragment = BTNode | Term


def as_node(fragment: Fragment) -> BTNode:
    return fragment.node() if isinstance(fragment, Term) else fragment


def _flat(kind: str, parts: tuple[BTNode, ...]) -> BTNode:
    children: list[BTNode] = []
    for part in parts:
        if part.type == kind and part.name is None and not part.attrs:
            children.extend(part.children)
        else:
            children.append(part)
    return control(kind, *children)


def sequence(*parts: BTNode) -> BTNode:
    """``Sequence`` over the parts, nested plain Sequences merged."""
    return _flat("Sequence", parts)


def fallback(*parts: BTNode) -> BTNode:
    """``Fallback`` over the parts, nested plain Fallbacks merged."""
    return _flat("Fallback", parts)


def forced(node: BTNode, status: str) -> BTNode:
    return decorator("ForceSuccess" if status == SUCCESS else "ForceFailure", node)


def then(x: BTNode, x_status: str, rest: Fragment) -> BTNode:
    """``x`` always returns ``x_status`` (or RUNNING), then the region goes on with ``rest``."""
    if isinstance(rest, Term) and rest.pure:
        return x if rest.status == x_status else forced(x, rest.status)
    first = x if x_status == SUCCESS else forced(x, SUCCESS)
    return sequence(first, as_node(rest))


def branch(x: BTNode, on_success: Fragment, on_failure: Fragment) -> BTNode:
    """``x``'s SUCCESS leads to ``on_success``, its FAILURE to ``on_failure``."""
    a_pure = isinstance(on_success, Term) and on_success.pure
    b_pure = isinstance(on_failure, Term) and on_failure.pure
    if a_pure and b_pure:
        a, b = on_success.status, on_failure.status  # type: ignore[union-attr]
        if (a, b) == (SUCCESS, FAILURE):
            return x
        if a == b:
            return forced(x, a)
        return decorator("Inverter", x)
    if b_pure:
        if on_failure.status == FAILURE:  # type: ignore[union-attr]
            return sequence(x, as_node(on_success))
        return control("IfThenElse", x, as_node(on_success), always(True))
    if a_pure:
        if on_success.status == SUCCESS:  # type: ignore[union-attr]
            return fallback(x, as_node(on_failure))
        return sequence(decorator("Inverter", x), as_node(on_failure))
    return control("IfThenElse", x, as_node(on_success), as_node(on_failure))


def _chunks(count: int) -> list[int]:
    """Case counts per Switch: at most six, never one (a Switch has at least two cases)."""
    sizes: list[int] = []
    left = count
    while left > 0:
        size = MAX_CASES if left > MAX_CASES else left
        if left - size == 1:
            size -= 1
        sizes.append(size)
        left -= size
    return sizes


def switch_chain(key: str, cases: list[tuple[str, BTNode]], default: BTNode) -> BTNode:
    """Dispatch on entry ``key``: the child of the first case equal to its value, else
    ``default``. One case is padded with a case no value equals (the empty string)."""
    if len(cases) == 1:
        cases = [*cases, ("", always(False))]
    sizes = _chunks(len(cases))
    groups: list[list[tuple[str, BTNode]]] = []
    start = 0
    for size in sizes:
        groups.append(cases[start : start + size])
        start += size
    node = default
    for group in reversed(groups):
        attrs = {"variable": "{" + key + "}"}
        attrs.update({f"case_{i}": value for i, (value, _child) in enumerate(group, 1)})
        node = control(f"Switch{len(group)}", *(child for _v, child in group), node, **attrs)
    return node
