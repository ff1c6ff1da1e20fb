"""Where BehaviorTree.CPP 3.8 ticks otherwise than 4.8.2 (docs/semantics.md section 1, v3):
4.8.2's ``SequenceWithMemory``, ``Repeat`` and ``RetryUntilSuccessful`` return RUNNING (with a
wake-up) after a child that completed at once, 3.8's go on within the same tick, and 3.8's
``SequenceStar`` restarts from its first child when halted where v4's keeps its place (read
from the 3.8.7 and 4.8.2 sources). At ``tickOnce`` granularity that shows only through an
ancestor that ticks something else, or halts, between two ticks of a RUNNING child.

Used by the ``btcpp3`` writer (refused, or a named loss) and by the reader of v3 files (a
warning: fsmbt reads them with v4's rule). One pass with an explicit stack, O(n * depth).
"""

from __future__ import annotations

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind, builtin_spec
from fsmbt.model.nodes import Family


def where(tree_id: str, node: BTNode) -> str:
    """``tree 'T', node 'N', line L``: where a node is, for one-line messages."""
    line = f", line {node.location.line}" if node.location and node.location.line else ""
    return f"tree '{tree_id}', node '{node.label}'{line}"


#: v4 nodes whose v3 counterpart ticks otherwise between ticks: after a child that completed
#: synchronously, v4 returns RUNNING (with a wake-up) where 3.8 goes on in the same tick, and
#: v4's SequenceWithMemory keeps its place when halted where 3.8's SequenceStar restarts.
_GRANULAR = {
    "SequenceWithMemory": "v3's SequenceStar goes on in the same tick after a child that "
    "succeeded at once (v4 returns RUNNING) and restarts from its first child when halted "
    "(v4 keeps its place)",
    "Repeat": "v3's Repeat runs its cycles within one tick (v4 returns RUNNING between them)",
    "RetryUntilSuccessful": "v3's RetryUntilSuccessful retries within one tick (v4 returns "
    "RUNNING between attempts)",
}


def _interrupts(node: BTNode) -> bool | None:
    """Whether an ancestor ticks something else, or halts, between two ticks of a RUNNING
    child: ``True`` for the reactive built-ins, Parallel, PipelineSequence, WhileDoElse and
    Timeout; ``None`` (cannot tell) for another project's or user's control or decorator;
    ``False`` for the rest (Sequence, Fallback, the status decorators...)."""
    spec = builtin_spec(node.type)
    if spec is not None and (
        spec.reactive
        or spec.family in (Family.PARALLEL, Family.PIPELINE)
        or spec.name in ("WhileDoElse", "Timeout")
    ):
        return True
    if node.kind not in (NodeKind.CONTROL, NodeKind.DECORATOR):
        return False
    if spec is not None and spec.library == "BehaviorTree.CPP":
        return False
    return None


def granularity(doc: BTDocument) -> tuple[list[tuple[str, BTNode, str]], list[str]]:
    """The SequenceWithMemory / Repeat / RetryUntilSuccessful nodes whose v3 counterpart would
    behave otherwise: under an ancestor that interrupts (refused), or under a control fsmbt
    cannot tell about (a named loss). One pass with an explicit stack, O(n * depth)."""
    refused: list[tuple[str, BTNode, str]] = []
    losses: list[str] = []
    for tree_id, tree in doc.trees.items():
        if tree.root is None:
            continue
        stack: list[tuple[BTNode, tuple[BTNode, ...]]] = [(tree.root, ())]
        while stack:
            node, ancestors = stack.pop()
            why = _GRANULAR.get(node.type)
            if why is not None and not _one_step(node):
                verdicts = [(a, _interrupts(a)) for a in reversed(ancestors)]  # nearest first
                sure = next((a for a, v in verdicts if v), None)
                unsure = next((a for a, v in verdicts if v is None), None)
                if sure is not None:
                    refused.append(
                        (
                            tree_id,
                            node,
                            f"{why}, and its ancestor {_label(sure)} ticks or halts "
                            "in between: the tree would behave otherwise in v3",
                        )
                    )
                elif unsure is not None:
                    losses.append(
                        f"{where(tree_id, node)}: {why}; the same in v3 unless its ancestor "
                        f"{_label(unsure)} ticks or halts in between (fsmbt cannot tell)"
                    )
            stack.extend((child, (*ancestors, node)) for child in reversed(node.children))
    return refused, losses


def _one_step(node: BTNode) -> bool:
    """No v4 RUNNING in between and nothing to restart: a SequenceWithMemory of one child, a
    Repeat / RetryUntilSuccessful of one cycle or attempt (a literal ``0`` or ``1``)."""
    if node.type == "SequenceWithMemory":
        return len(node.children) <= 1
    count = node.attrs.get("num_cycles" if node.type == "Repeat" else "num_attempts", "")
    return count.strip() in ("0", "1")


def _label(node: BTNode) -> str:
    line = f", line {node.location.line}" if node.location and node.location.line else ""
    return f"{node.type} '{node.label}'{line}" if node.name else f"{node.type}{line}"


__all__ = ["granularity", "where"]
