"""Conditional family: IfThenElse, WhileDoElse (if_then_else_node.cpp,
while_do_else_node.cpp; docs/semantics.md "Control nodes").

Contract: child 0 is the condition, child 1 the then-branch, child 2 (optional) the else-branch
(declared child counts 2 or 3). IfThenElse evaluates the condition once and keeps the chosen
branch in its memory ``(branch,)`` while it runs; WhileDoElse re-evaluates it on every tick and
halts the other branch. A SKIPPED condition throws in BehaviorTree.CPP: a ``BTRuntimeError``.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import (
    FAILURE,
    RUNNING,
    SUCCESS,
    BTRuntimeError,
    CompiledNode,
    Frame,
    HaltHook,
    TickAction,
    Work,
)
from fsmbt.semantics.families.contract import FamilyRule, Interp


def tick_if_then_else(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """IfThenElse (if_then_else_node.cpp): the condition is not re-evaluated while a branch
    runs."""
    (child_idx,) = ip.mem(w, node)
    n = len(node.children)
    pc = frame[1]
    if pc == 0:
        w.st[node.id] = RUNNING
        if child_idx == 0:
            return ("call", node.children[0], (node.id, 1))
    elif pc == 1:
        if result == RUNNING:
            return ("ret", RUNNING)
        if result == SUCCESS:
            child_idx = 1
        elif result == FAILURE:
            if n == 3:
                child_idx = 2
            else:
                return ("ret", FAILURE)
        else:
            raise BTRuntimeError(
                "IfThenElse: the condition was skipped (BehaviorTree.CPP throws a logic_error)",
                element=node.label,
            )
        ip.set_mem(w, node, (child_idx,))
    else:  # pc == 2: the branch returned
        if result == RUNNING:
            return ("ret", RUNNING)
        ip.reset_children(w, node, hook)
        ip.set_mem(w, node, (0,))
        return ("ret", result)
    return ("call", node.children[child_idx], (node.id, 2))


def tick_while_do_else(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """WhileDoElse (while_do_else_node.cpp): the condition is re-evaluated every tick."""
    n = len(node.children)
    pc = frame[1]
    if pc == 0:
        w.st[node.id] = RUNNING
        return ("call", node.children[0], (node.id, 1))
    if pc == 1:
        if result == RUNNING:
            return ("ret", RUNNING)
        if result == SUCCESS:
            if n == 3:
                ip.reset_child(w, node.children[2], hook)
            return ("call", node.children[1], (node.id, 2))
        if result == FAILURE:
            if n == 3:
                ip.reset_child(w, node.children[1], hook)
                return ("call", node.children[2], (node.id, 2))
            status = FAILURE
        else:
            raise BTRuntimeError(
                "WhileDoElse: the condition was skipped (the node would return IDLE)",
                element=node.label,
            )
    else:
        assert result is not None  # pc == 2: the branch returned
        status = result
    if status == RUNNING:
        return ("ret", RUNNING)
    ip.reset_children(w, node, hook)
    return ("ret", status)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "if_then_else": FamilyRule(tick_if_then_else),
    "while_do_else": FamilyRule(tick_while_do_else),
}
