"""Preparing a BT for BT -> HFSM: SubTree inlining and depth compression (docs/conversion.md, 'BT -> FSM: depth compression and conversion units', steps 1-2).

Depth compression merges a child control node into its parent when both have the same type
and the node registry marks that type ``mergeable`` (``MERGEABLE_CONTROLS``):
``Sequence(a, Sequence(b, c), d) = Sequence(a, b, c, d)``, the same for ``Fallback``. Only the
plain (BehaviorTree.CPP v4, non-reactive, memoryless-across-ticks) ``Sequence`` and ``Fallback``
are merged: for them the nested and the flat form tick the same leaves in the same order, resume
the same running child and reset the same way. The reactive and WithMemory variants are left
alone (a ``SequenceWithMemory`` asks for a wake-up after each child's first success, so nesting
changes where ticks end, which a reactive ancestor can see); a child that carries attributes
(e.g. the v4 ``_skipIf`` / ``_successIf`` preconditions) or a name the user gave is merged too
only when it has no attributes - names are dropped with the node (they do not change behaviour).

Complexity: O(N) time and memory for N nodes, explicit stacks only.
"""

from __future__ import annotations

from dataclasses import dataclass

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.semantics.nodes import MERGEABLE_CONTROLS


def tree_depth(root: BTNode) -> int:
    """Levels on the longest root-to-leaf path (root = 1), iteratively."""
    deepest = 0
    stack = [(root, 1)]
    while stack:
        node, level = stack.pop()
        if level > deepest:
            deepest = level
        for child in node.children:
            stack.append((child, level + 1))
    return deepest


def _shallow_copy(node: BTNode) -> BTNode:
    return BTNode(
        type=node.type,
        kind=node.kind,
        name=node.name,
        attrs=dict(node.attrs),
        kind_declared=node.kind_declared,
        location=node.location,
        semantics=node.semantics,
    )


def inline_subtrees(doc: BTDocument) -> BTNode:
    """A copy of the main tree with every ``SubTree`` reference replaced by the tree it names.

    Raises ``InputError`` naming the node for a missing tree and for a tree that (directly or
    not) includes itself. O(N) in the size of the expanded tree.
    """
    root, chain = _resolved_main_root(doc)
    top = _shallow_copy(root)
    # (original node, its copy, chain of tree ids that led here)
    stack: list[tuple[BTNode, BTNode, tuple[str, ...]]] = [(root, top, chain)]
    while stack:
        original, copy, chain = stack.pop()
        for child in original.children:
            source, child_chain = _resolve(doc, child, chain)
            child_copy = _shallow_copy(source)
            copy.children.append(child_copy)
            stack.append((source, child_copy, child_chain))
    return top


def _resolved_main_root(doc: BTDocument) -> tuple[BTNode, tuple[str, ...]]:
    """The main tree's root with SubTree references at the top resolved, and the chain of
    tree ids that led there; the errors every converter entry point gives."""
    if not doc.trees:
        raise InputError("the document holds no behavior tree to convert (only node models?)")
    main = doc.main
    if main.root is None:
        raise InputError("the behavior tree is empty", element=main.id)
    return _resolve(doc, main.root, (main.id,))


def _resolve(
    doc: BTDocument, node: BTNode, chain: tuple[str, ...]
) -> tuple[BTNode, tuple[str, ...]]:
    """Follow ``SubTree`` references from ``node`` to a real node."""
    while node.kind is NodeKind.SUBTREE:
        ref = node.subtree_id
        if ref is None or ref not in doc.trees or doc.trees[ref].root is None:
            raise InputError(
                f"SubTree refers to unknown or empty tree '{ref}'",
                element=node.label,
                location=node.location,
            )
        if ref in chain:
            raise InputError(
                f"SubTree '{ref}' includes itself", element=node.label, location=node.location
            )
        chain = chain + (ref,)
        node = doc.trees[ref].root  # type: ignore[assignment]
    return node, chain


@dataclass
class Compression:
    root: BTNode
    depth_before: int
    depth_after: int
    merged: int  # control nodes merged into their parent


def _mergeable(parent: BTNode, child: BTNode) -> bool:
    return (
        child.type == parent.type
        and parent.type in MERGEABLE_CONTROLS
        and child.kind is NodeKind.CONTROL
        and not child.attrs
    )


def compress(root: BTNode) -> Compression:
    """Depth compression of a (SubTree-free) tree; returns a new tree, the input is untouched."""
    before = tree_depth(root)
    merged = 0
    top = _shallow_copy(root)
    work: list[tuple[BTNode, BTNode]] = [(root, top)]
    while work:
        original, copy = work.pop()
        pending = list(reversed(original.children))
        while pending:
            child = pending.pop()
            if _mergeable(copy, child):
                merged += 1
                pending.extend(reversed(child.children))
                continue
            child_copy = _shallow_copy(child)
            copy.children.append(child_copy)
            work.append((child, child_copy))
    return Compression(top, before, tree_depth(top), merged)


@dataclass
class Prepared:
    """``compress(inline_subtrees(doc))`` and its figures, made in one pass."""

    compression: Compression
    leaves: int  # leaves of the compressed tree


def inline_and_compress(doc: BTDocument) -> Prepared:
    """SubTree inlining and depth compression in one copy of the tree (what BT -> HFSM needs).

    Same result as ``compress(inline_subtrees(doc))`` (asserted in the tests), without building
    the intermediate inlined copy and without the two extra depth walks: the inlined tree's
    level of every node is carried along (a ``SubTree`` reference takes no level, as in
    ``inline_subtrees``). O(N) time for N nodes of the expanded tree, explicit stacks only.
    """
    root, chain = _resolved_main_root(doc)
    top = _shallow_copy(root)
    depth_before = depth_after = 1
    merged = 0
    leaves = 1 if top.is_leaf else 0
    # (original node, its copy, chain of tree ids, level of the original, level of the copy)
    work: list[tuple[BTNode, BTNode, tuple[str, ...], int, int]] = [(root, top, chain, 1, 1)]
    while work:
        original, copy, chain, level, copy_level = work.pop()
        # children still to place below ``copy``: (node, chain, level in the inlined tree)
        pending = [(child, chain, level + 1) for child in reversed(original.children)]
        while pending:
            child, child_chain, child_level = pending.pop()
            child, child_chain = _resolve(doc, child, child_chain)
            if child_level > depth_before:
                depth_before = child_level
            if _mergeable(copy, child):
                merged += 1
                pending.extend(
                    (grand, child_chain, child_level + 1) for grand in reversed(child.children)
                )
                continue
            child_copy = _shallow_copy(child)
            copy.children.append(child_copy)
            if child_copy.is_leaf:
                leaves += 1
            if copy_level + 1 > depth_after:
                depth_after = copy_level + 1
            work.append((child, child_copy, child_chain, child_level, copy_level + 1))
    return Prepared(Compression(top, depth_before, depth_after, merged), leaves)
