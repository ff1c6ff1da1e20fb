"""Reactive family: ReactiveSequence, ReactiveFallback (reactive_sequence.cpp,
reactive_fallback.cpp; docs/semantics.md "Control nodes").

Contract: every tick starts again at child 0 (earlier children are re-ticked); a RUNNING child
halts every other child and the node returns RUNNING; the stop status (FAILURE for a sequence,
SUCCESS for a fallback) resets every child. No memory: the frame holds the index and whether
every child so far was SKIPPED.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import (
    FAILURE,
    RUNNING,
    SKIPPED,
    SUCCESS,
    BTRuntimeError,
    CompiledNode,
    Frame,
    HaltHook,
    TickAction,
    Work,
)
from fsmbt.semantics.families.contract import PLAIN_READS, FamilyRule, Interp


def tick_reactive(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """ReactiveSequence / ReactiveFallback (reactive_sequence.cpp, reactive_fallback.cpp)."""
    is_fallback = node.type in ip.reactive_fallbacks
    stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        index, all_skipped = 0, True
    else:
        index, all_skipped = frame[2], frame[3]
        all_skipped = all_skipped and result == SKIPPED
        if result == RUNNING:
            for i, child in enumerate(node.children):
                if i != index:
                    ip.reset_child(w, child, hook)
            return ("ret", RUNNING)
        if result == stop:
            ip.reset_children(w, node, hook)
            return ("ret", stop)
        if result == SKIPPED:
            ip.reset_child(w, node.children[index], hook)
        elif result != go_on:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
        index += 1
    if index < len(node.children):
        return ("call", node.children[index], (node.id, 1, index, all_skipped))
    ip.reset_children(w, node, hook)
    return ("ret", SKIPPED if all_skipped else go_on)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "reactive": FamilyRule(tick_reactive, restarts=True, canonical=PLAIN_READS),
}
