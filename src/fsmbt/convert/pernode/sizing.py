"""Before the converter chooses a region's form: can it be written per node, and how large
would exploring it be (``fsmbt.convert.pernode``; docs/conversion.md, "Per-node conversion")."""

from __future__ import annotations

import math

from fsmbt.convert.pernode.kernel import LOOP_AGAIN_ON, PARALLEL_HANDLERS
from fsmbt.convert.pernode.registry import RULES, SUPPORTED_HANDLERS
from fsmbt.model.bt import BTNode
from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import canonical_type
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.nodes import runtime_tables

#: The default form of a region (``bt_to_hfsm``): below this estimate (bits, ``pernode_estimate``,
#: a loose upper bound of the explored configurations) the compact form, as before; at or above
#: it, per node when the region has ``PERNODE_SURE_NODES`` nodes or more, or when exploring it
#: passes ``PERNODE_TRY_STATES`` states (a region that fits keeps the compact form, byte for
#: byte: every tree of the tests and examples that converted before converts the same).
PERNODE_MIN_LOG2 = 12.0
PERNODE_SURE_NODES = 150
PERNODE_TRY_STATES = 4_000


def refusal(tree: CompiledTree) -> str | None:
    """Why the region ``tree`` cannot be written per node (``None``: it can). O(N)."""
    handlers = runtime_tables().handlers
    for node in tree.nodes:
        if any(key.startswith("_") for key in node.source.attrs):
            return f"{node.type} '{node.label}' has a pre-condition or an internal port"
        if node.is_env_leaf and not node.children:
            continue
        if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
            return f"{node.type} '{node.label}' is a built-in leaf"
        rule = RULES.get(handlers.get(node.type) or "")
        if rule is None:
            return f"{node.type} '{node.label}' has no per-node rule"
        why = rule.refuse(node)
        if why is not None:
            return why
        if not node.children:
            return f"{node.type} '{node.label}' has no children"
    return None


def memory_log2(tree: CompiledTree) -> float:
    """A cheap upper estimate (log2) of the explored region's configurations: the product of
    the index and count ranges of its nodes, and of its leaves (O(N)); the caller writes the
    region per node past a threshold."""
    tables = runtime_tables()
    total = math.log2(max(1, sum(1 for n in tree.nodes if n.is_env_leaf)))
    for node in tree.nodes:
        rule = tables.handlers.get(node.type)
        if rule == "sequence" and len(node.children) > 1:
            total += math.log2(len(node.children)) + 1
        elif rule in LOOP_AGAIN_ON and node.params and isinstance(node.params[0], int):
            total += math.log2(max(2, node.params[0])) + 1
    return total


def region_size(node: BTNode) -> int:
    """Nodes of ``node``'s subtree (iterative)."""
    count, stack = 0, [node]
    while stack:
        x = stack.pop()
        count += 1
        stack.extend(x.children)
    return count


def pernode_estimate(node: BTNode) -> float:
    """``memory_log2`` of ``node``'s subtree without compiling it (O(N), iterative): the
    converter's cheap test before choosing the form."""
    tables = runtime_tables()
    total, leaves = 0.0, 0
    stack = [node]
    while stack:
        x = stack.pop()
        stack.extend(x.children)
        if not x.children:
            leaves += 1
            continue
        rule = tables.handlers.get(x.semantics or canonical_type(x.type))
        if rule == "sequence" and len(x.children) > 1:
            total += math.log2(len(x.children)) + 1
        elif rule in LOOP_AGAIN_ON:
            total += 2.0
        elif rule in PARALLEL_HANDLERS:
            total += len(x.children) + 2 * math.log2(len(x.children) + 1)
        elif rule is not None and rule not in SUPPORTED_HANDLERS:
            total += math.log2(len(x.children) + 1) + 1
    return total + math.log2(max(1, leaves))
