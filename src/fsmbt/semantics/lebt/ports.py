"""The LEBT leaves' redundant ports checked against the tree's structure (docs/semantics.md §5).

An LEBT's behaviour comes from the ``pairs`` of each ``LebtGuard`` and the ``state``/``exits``
of each ``LebtState``; two ports repeat what the structure already says, so an edited tree can
contradict itself and still verify (the checkers never read the redundant copy):

- a guard's ``target`` ("the state this guard enters", TreeNodesModel) must name the state its
  selector enters: the guard's next sibling, or that sibling's first child when it is a chain
  (``Sequence``) - a ``LebtState`` (its ``state`` port) or, for a composite state, a
  ``SubTree`` (its name, else its ``ID``);
- a guard pair ``source/event`` whose source is a ``LebtState`` must be one of that state's
  ``exits`` (``onRunning`` clears any other event, so the transition would never fire), and
  every exit of a state must be the event of some guard pair leaving it (else the event ends
  the tick with no guard to take it).

``lebt_port_issues(doc)`` lists every contradiction as an error ``Issue`` naming the leaf and
its line; a document without LEBT leaves has none. Cost: O(N + P) for N nodes and P pairs, one
pass with an explicit stack, no recursion.
"""

from __future__ import annotations

from dataclasses import dataclass

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import canonical_type
from fsmbt.model.nodes import SEQUENCE_TYPES, SUBTREE_TYPE
from fsmbt.model.validate import Issue
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE, GuardSpec, StateSpec


@dataclass(frozen=True)
class _Guard:
    node: BTNode
    tree: str
    spec: GuardSpec
    guarded: BTNode | None


def _label(node: BTNode) -> str:
    return f"{node.type} '{node.label}'" if node.name else node.type


def _guarded_name(node: BTNode) -> str | None:
    """The state name a guarded element stands for (``None``: not a state)."""
    if node.type == STATE_TYPE:
        return StateSpec.from_attrs(node.attrs).state
    if node.type == SUBTREE_TYPE:
        return node.name or node.attrs.get("ID")
    return None


def _guarded(parent: BTNode, index: int) -> BTNode | None:
    """The element the guard at ``parent.children[index]`` leads into."""
    if index + 1 >= len(parent.children):
        return None
    after = parent.children[index + 1]
    if canonical_type(after.type) in SEQUENCE_TYPES and after.children:  # the guarded body
        return after.children[0]
    return after


def lebt_port_issues(doc: BTDocument) -> list[Issue]:
    """Every LEBT leaf whose redundant ports contradict the structure (see the module doc).

    Args:
        doc: the BT document (all trees are read).

    Returns:
        Error ``Issue`` s in document order, each located at the leaf and naming it by tree and
        label; empty when the document has no LEBT leaves or none contradicts itself.
    """
    guards: list[_Guard] = []
    states: dict[str, tuple[BTNode, StateSpec]] = {}
    for tree in doc.trees.values():
        if tree.root is None:
            continue
        stack = [tree.root]
        while stack:
            node = stack.pop()
            for index, child in enumerate(node.children):
                if child.type == GUARD_TYPE:
                    guards.append(
                        _Guard(
                            child, tree.id, GuardSpec.from_attrs(child.attrs), _guarded(node, index)
                        )
                    )
            if node.type == STATE_TYPE:
                spec = StateSpec.from_attrs(node.attrs)
                states.setdefault(spec.state, (node, spec))
            stack.extend(reversed(node.children))
    issues: list[Issue] = []
    for guard in guards:
        where = f"tree '{guard.tree}', {_label(guard.node)}"
        guarded = guard.guarded
        name = _guarded_name(guarded) if guarded is not None else None
        if name is None:
            issues.append(
                Issue(
                    "error",
                    f"{GUARD_TYPE} is not followed by the state it "
                    "enters (a LebtState or SubTree, alone or first in a chain)",
                    guard.node.location,
                    where,
                    code="lebt-port",
                )
            )
        elif guard.spec.target != name:
            line = guarded.location.line if guarded is not None and guarded.location else None
            at = f" (line {line})" if line is not None else ""
            issues.append(
                Issue(
                    "error",
                    f"port target='{guard.spec.target}' but the guard "
                    f"enters state '{name}'{at}; the target port must name the "
                    "state the guard enters",
                    guard.node.location,
                    where,
                    code="lebt-port",
                )
            )
        for source, event in guard.spec.pairs:
            known = states.get(source)
            if known is not None and event and event not in known[1].exits:
                issues.append(
                    Issue(
                        "error",
                        f"pair '{source}/{event}': state '{source}' does "
                        f"not list '{event}' in its exits port, so this transition "
                        "never fires",
                        guard.node.location,
                        where,
                        code="lebt-port",
                    )
                )
    left: set[tuple[str, str]] = {pair for guard in guards for pair in guard.spec.pairs}
    for name, (node, spec) in states.items():
        for event in spec.exits:
            if (name, event) not in left:
                issues.append(
                    Issue(
                        "error",
                        f"exits port lists '{event}' but no LebtGuard "
                        f"has the pair '{name}/{event}'",
                        node.location,
                        f"{STATE_TYPE} '{node.label}'",
                        code="lebt-port",
                    )
                )
    return issues
