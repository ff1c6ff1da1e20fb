"""Once family: RunOnce (run_once_node.h) and Nav2 SingleTrigger (docs/semantics.md
"Decorators", "Project nodes").

Contract: RunOnce ticks its child until it completes once, then returns that result (or SKIPPED
with ``then_skip``, the default) without ticking it; memory ``(ticked, result)`` survives halts.
SingleTrigger runs the child to completion once per activation (the node IDLE again), FAILURE
otherwise; memory ``(triggered,)``.
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.bt import BTNode
from fsmbt.semantics.compiled import (
    FAILURE,
    IDLE,
    RUNNING,
    SKIPPED,
    SUCCESS,
    CompiledNode,
    Frame,
    HaltHook,
    TickAction,
    Work,
)
from fsmbt.semantics.families.contract import FamilyRule, Interp
from fsmbt.semantics.families.ports import bool_param


def run_once_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(then_skip,)``, true by default."""
    return (bool_param(node, "then_skip", True),)


def tick_run_once(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """RunOnce then_skip (run_once_node.h): memory survives halts."""
    (then_skip,) = node.params
    ticked, returned = ip.mem(w, node)
    if frame[1] == 0:
        if ticked:
            return ("ret", SKIPPED if then_skip else returned)
        w.st[node.id] = RUNNING
        return ("call", node.children[0], (node.id, 1))
    if result in (SUCCESS, FAILURE):
        ip.set_mem(w, node, (True, result))
        ip.reset_child(w, node.children[0], hook)
    return ("ret", result)


def tick_single_trigger(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Nav2 SingleTrigger: the child runs to completion once per activation."""
    child = node.children[0]
    if frame[1] == 0:
        (triggered,) = ip.mem(w, node)
        if w.st.get(node.id, IDLE) == IDLE:
            triggered = False
            ip.set_mem(w, node, (False,))
        w.st[node.id] = RUNNING
        if triggered:
            return ("ret", FAILURE)
        return ("call", child, (node.id, 1))
    if result in (SUCCESS, FAILURE):
        ip.set_mem(w, node, (True,))
    return ("ret", result)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "run_once": FamilyRule(tick_run_once, params=run_once_params),
    "single_trigger": FamilyRule(tick_single_trigger),
}
