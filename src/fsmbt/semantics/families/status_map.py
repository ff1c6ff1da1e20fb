"""Status-map family: Inverter, ForceSuccess, ForceFailure, KeepRunningUntilFailure
(inverter_node.cpp, force_*_node.h, keep_running_until_failure_node.h; docs/semantics.md
"Decorators").

Contract: one child; its SUCCESS and FAILURE become the declared ``result_map`` pair (the child
is reset when it completes); RUNNING and SKIPPED pass through. KeepRunningUntilFailure (no
``result_map``) returns RUNNING after a SUCCESS and FAILURE after a FAILURE. No memory.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import (
    FAILURE,
    RUNNING,
    SKIPPED,
    SUCCESS,
    CompiledNode,
    Frame,
    HaltHook,
    TickAction,
    Work,
)
from fsmbt.semantics.families.contract import PLAIN_READS, FamilyRule, Interp


def tick_simple_decorator(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Inverter, ForceSuccess, ForceFailure, KeepRunningUntilFailure."""
    child = node.children[0]
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        return ("call", child, (node.id, 1))
    mapped = ip.result_maps.get(node.type)
    if mapped is None:  # KeepRunningUntilFailure
        if result == FAILURE:
            ip.reset_child(w, child, hook)
            return ("ret", FAILURE)
        if result == SUCCESS:
            ip.reset_child(w, child, hook)
            return ("ret", RUNNING)
        return ("ret", RUNNING)  # RUNNING, or `return status()` (RUNNING) when skipped
    if result in (RUNNING, SKIPPED):
        return ("ret", result)
    ip.reset_child(w, child, hook)
    return ("ret", mapped[0] if result == SUCCESS else mapped[1])


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "simple_decorator": FamilyRule(tick_simple_decorator, canonical=PLAIN_READS),
}
