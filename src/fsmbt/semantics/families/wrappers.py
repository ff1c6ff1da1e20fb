"""Wrapper family: SubTree (subtree_node.cpp), Groot 1 ``Root``, Nav2 GoalUpdater
(docs/semantics.md "SubTree", "Project nodes").

Contract: one child whose status is the node's; SubTree and Root reset the child when it
completes, GoalUpdater does not (``return child_node_->executeTick()``). No memory. A SubTree's
child is its tree's root, expanded at compile time (port remapping is irrelevant to control
flow).
"""

from __future__ import annotations

from fsmbt.semantics.compiled import (
    FAILURE,
    IDLE,
    RUNNING,
    SUCCESS,
    CompiledNode,
    Frame,
    HaltHook,
    TickAction,
    Work,
)
from fsmbt.semantics.families.contract import (
    PLAIN_READS,
    CanonicalReads,
    FamilyRule,
    Interp,
)


def tick_subtree(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """SubTree (subtree_node.cpp): a transparent decorator; port remapping is irrelevant."""
    if frame[1] == 0:
        if w.st.get(node.id, IDLE) == IDLE:
            w.st[node.id] = RUNNING
        return ("call", node.children[0], (node.id, 1))
    if result in (SUCCESS, FAILURE):
        ip.reset_child(w, node.children[0], hook)
    return ("ret", result)


def tick_pass_through(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """A transparent wrapper (Groot 1 ``Root``): the child's status, child reset when done."""
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        return ("call", node.children[0], (node.id, 1))
    if result in (SUCCESS, FAILURE):
        ip.reset_child(w, node.children[0], hook)
    return ("ret", result)


def tick_pass_through_keep(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Nav2 GoalUpdater: ``return child_node_->executeTick()`` (the child is not reset)."""
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        return ("call", node.children[0], (node.id, 1))
    return ("ret", result)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "subtree": FamilyRule(tick_subtree),
    "pass_through": FamilyRule(tick_pass_through, canonical=PLAIN_READS),
    "pass_through_keep": FamilyRule(
        tick_pass_through_keep, canonical=CanonicalReads(keeps_finished=True)
    ),
}
