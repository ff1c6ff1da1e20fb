"""A direct leaf-execution machine for plain Sequence/Fallback trees, without the interpreter.

Why: ``LeafMachine`` steps the generic BehaviorTree.CPP interpreter (~230 us per step), so
checking a 10 000-leaf tree against its HFSM takes ~15 s. For the *plain* class - every node of
the compiled tree is a ``Sequence`` or ``Fallback`` with >= 1 child, a transparent ``SubTree``
or an environment Action/Condition (no internal built-in leaf, no other decorator or control) -
the machine is static (derived from ``sequence_node.cpp``/``fallback_node.cpp``):

- nothing is ever halted while running and no node keeps memory past its own return, so the
  whole run-time configuration at a leaf request is the position of that leaf;
- ``running``: the tick ends; non-reactive parents resume the same leaf on the next tick, so the
  leaf is ticked (and output) again: a self-loop;
- ``success``/``failure`` leaving node ``N`` (a leaf or a finished control node): under a
  Sequence, success goes on to the first (leftmost) leaf of the next sibling, or leaves the
  Sequence with success when ``N`` was its last child; failure leaves the Sequence with failure.
  A Fallback is the mirror image. A SubTree passes its child's result on. Leaving the root ends
  the tick with the root's result (``"SUCCESS"``/``"FAILURE"``).

Widened class (``is_static_tree``, docs/semantics.md §4a): reactive Sequence/Fallback nodes
(registry flag ``reactive``) with no plain control below them, and status-mapping decorators
(registry ``result_map``; their child's exits are theirs rewired). Success/failure exits are the
same tables (a reactive node goes on or stops within the tick like a plain one); ``running``
leads to ``on_running[leaf]``: the leaf itself with no reactive ancestor, else the first leaf of
the topmost reactive ancestor, which restarts at child 0 on the next tick.

``exits[o][N]`` ("outcome ``o`` leaving ``N`` leads to leaf X or root result R") depends only on
``N``'s parent's entry, so one forward pass over the pre-order ids (parents before children)
fills the table: O(N) time and memory, no recursion (trees may be 100 000 deep). One step then
is O(1). States are the plain ``int`` id of the leaf about to be ticked (cheap to hash) or
``leaf_machine.RootResult``; ``LeafMachine`` decides which path to take
(``LeafMachine(..., generic=True)`` forces the interpreter) and keeps the loop rules.
"""

from __future__ import annotations

from typing import Final

from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.families.registry import rule as family_rule
from fsmbt.semantics.nodes import (
    FALLBACK_TYPES,
    PLAIN_CONTROLS,
    SUBTREE_TYPE,
    node_semantics,
    rewired,
)
from fsmbt.semantics.status import LeafOutcome, RootResult

ROOT = 0  # the compiled root's id (ids are pre-order indices)
#: Negative targets in the exit tables: the root returned this result.
ROOT_SUCCESS, ROOT_FAILURE = -1, -2
ROOT_RESULT_NAMES: dict[int, str] = {
    ROOT_SUCCESS: RootResult.SUCCESS.value,
    ROOT_FAILURE: RootResult.FAILURE.value,
}
_SUCCESS: Final[str] = LeafOutcome.SUCCESS.value
_FAILURE: Final[str] = LeafOutcome.FAILURE.value
_RUNNING: Final[str] = LeafOutcome.RUNNING.value


def is_plain_tree(tree: CompiledTree) -> bool:
    """Whether ``tree`` is in the plain class (see the module docstring). O(N)."""
    for node in tree.nodes:
        if node.kind is NodeKind.CONTROL:
            if node.type not in PLAIN_CONTROLS or not node.children:
                return False
        elif node.kind is NodeKind.SUBTREE:
            if node.type != SUBTREE_TYPE or len(node.children) != 1:
                return False
        elif not node.is_env_leaf:  # decorators, internal built-in leaves
            return False
    return True


def _restarts(handler: str | None) -> bool:
    """Whether the rule ``handler`` restarts at child 0 on every tick and keeps no memory
    (``FamilyRule.restarts``: the ``reactive`` rule)."""
    found = family_rule(handler) if handler is not None else None
    return found is not None and found.restarts


def is_static_tree(tree: CompiledTree) -> bool:
    """Whether ``tree`` has a static leaf table: the plain class, widened (docs/semantics.md §4a)
    with reactive Sequence/Fallback nodes (registry: ``reactive``; their family rule says it
    ``restarts``, ``FamilyRule``) whose subtrees hold no plain control, and status-mapping decorators (registry: ``result_map``). O(N).

    Why that shape: a reactive node restarts at child 0 every tick and keeps no memory, and the
    only other memory in the class is a plain node's running index, which is read only when no
    reactive ancestor restarts the path first. So the run-time configuration at a leaf request
    is again the leaf alone.
    """
    under_reactive = [False] * len(tree.nodes)
    for node in tree.nodes:  # pre-order: a parent is seen before its children
        below = under_reactive[node.id]
        if node.kind is NodeKind.CONTROL:
            spec = node_semantics(node.type)
            if (
                spec is None
                or not node.children
                or node.type not in PLAIN_CONTROLS
                and not (spec.reactive and _restarts(spec.handler))
            ):
                return False
            if node.type in PLAIN_CONTROLS and below:
                return False
            below = below or spec.reactive
        elif node.kind is NodeKind.DECORATOR:
            spec = node_semantics(node.type)
            if spec is None or spec.result_map is None:
                return False
        elif node.kind is NodeKind.SUBTREE:
            if node.type != SUBTREE_TYPE or len(node.children) != 1:
                return False
        elif not node.is_env_leaf:
            return False
        for kid in node.children:
            under_reactive[kid] = below
    return True


class PlainLeafTable:
    """The static leaf-execution machine of a plain tree: first leaf and exit tables.

    ``after(leaf, outcome)`` is the leaf ticked next or ``ROOT_SUCCESS``/``ROOT_FAILURE``.
    """

    def __init__(self, tree: CompiledTree) -> None:
        nodes = tree.nodes
        count = len(nodes)
        # first_leaf[n]: the leftmost leaf of n's subtree; children have larger ids, so a
        # reverse pass sees every child before its parent.
        first_leaf = list(range(count))
        for node in reversed(nodes):
            if node.children:
                first_leaf[node.id] = first_leaf[node.children[0]]
        on_success = [ROOT_SUCCESS] * count
        on_failure = [ROOT_FAILURE] * count
        # restart[n]: the first leaf of n's topmost reactive proper ancestor (it restarts at
        # child 0 on the next tick), -1 when there is none.
        restart = [-1] * count
        # Forward pass: a node's exits need only its parent's, and parents come first.
        for node in nodes:
            kids = node.children
            if not kids:
                continue
            parent_success, parent_failure = on_success[node.id], on_failure[node.id]
            top = restart[node.id]
            if top < 0 and node.kind is NodeKind.CONTROL:
                spec = node_semantics(node.type)
                if spec is not None and spec.reactive:
                    top = first_leaf[node.id]
            for kid in kids:
                restart[kid] = top
            last = len(kids) - 1
            if node.kind is NodeKind.DECORATOR:  # a status map: its child's exits rewired
                on_success[kids[0]], on_failure[kids[0]] = rewired(
                    node.type, parent_success, parent_failure
                )
            elif node.kind is NodeKind.CONTROL and node.type not in FALLBACK_TYPES:  # Sequence
                for i, kid in enumerate(kids):
                    on_success[kid] = first_leaf[kids[i + 1]] if i < last else parent_success
                    on_failure[kid] = parent_failure
            elif node.kind is NodeKind.CONTROL:  # Fallback
                for i, kid in enumerate(kids):
                    on_success[kid] = parent_success
                    on_failure[kid] = first_leaf[kids[i + 1]] if i < last else parent_failure
            else:  # SubTree: transparent
                on_success[kids[0]] = parent_success
                on_failure[kids[0]] = parent_failure
        self.tree = tree
        self.start_leaf = first_leaf[ROOT]
        self.on_success = on_success
        self.on_failure = on_failure
        #: on_running[leaf]: where RUNNING leads - the same leaf under non-reactive ancestors
        #: (resumed next tick), else the first leaf of the topmost reactive ancestor.
        self.on_running = [restart[n] if restart[n] >= 0 else n for n in range(count)]
        self.labels = [node.label for node in nodes]
        self.is_condition = [node.is_condition for node in nodes]

    def after(self, leaf: int, outcome: str) -> int:
        """Where ``outcome`` of ``leaf`` leads: the same leaf on ``running``, else the next leaf
        or a negative root result. O(1)."""
        if outcome == _SUCCESS:
            return self.on_success[leaf]
        if outcome == _FAILURE:
            return self.on_failure[leaf]
        if outcome == _RUNNING:
            return self.on_running[leaf]
        raise ValueError(f"unknown outcome {outcome!r}")
