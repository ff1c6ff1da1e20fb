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
from fsmbt.semantics.nodes import FALLBACK_TYPES, PLAIN_CONTROLS
from fsmbt.semantics.status import LeafOutcome, RootResult

ROOT = 0  # the compiled root's id (ids are pre-order indices)
#: Negative targets in the exit tables: the root returned this result.
ROOT_SUCCESS, ROOT_FAILURE = -1, -2
ROOT_RESULT_NAMES: dict[int, str] = {ROOT_SUCCESS: RootResult.SUCCESS.value,
                                     ROOT_FAILURE: RootResult.FAILURE.value}
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
            if node.type != "SubTree" or len(node.children) != 1:
                return False
        elif not node.is_env_leaf:  # decorators, internal built-in leaves
            return False
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
        # Forward pass: a node's exits need only its parent's, and parents come first.
        for node in nodes:
            kids = node.children
            if not kids:
                continue
            parent_success, parent_failure = on_success[node.id], on_failure[node.id]
            last = len(kids) - 1
            if node.kind is NodeKind.CONTROL and node.type not in FALLBACK_TYPES:  # Sequence
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
            return leaf
        raise ValueError(f"unknown outcome {outcome!r}")
