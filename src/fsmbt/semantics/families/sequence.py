"""Sequence and Fallback families: Sequence, Fallback, AsyncSequence, AsyncFallback,
SequenceWithMemory (BehaviorTree.CPP sequence_node.cpp, fallback_node.cpp,
sequence_with_memory_node.cpp; docs/semantics.md "Control nodes").

Contract: children are ticked in order; a Sequence stops at the first FAILURE, a Fallback at
the first SUCCESS (the declaration's ``is_fallback`` flag picks the pair). Memory
``(index, skipped)``: the running child and how many were SKIPPED. An asynchronous kind, or one
with memory, returns RUNNING with a wake-up after a child that completed synchronously (it was
IDLE). A kind with memory keeps its index on a child's FAILURE (resetting only the children
from there). All children SKIPPED: SKIPPED. Halt: forgets the memory except SequenceWithMemory
(declared ``halt_resets_memory``).
"""

from __future__ import annotations

from fsmbt.model.nodes import node_semantics
from fsmbt.semantics.compiled import (
    FAILURE,
    IDLE,
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
from fsmbt.semantics.families.contract import CanonicalReads, FamilyRule, Interp


def tick_sequence(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Sequence / Fallback / Async* / SequenceWithMemory (sequence_node.cpp & co)."""
    is_fallback, asynch, with_memory = ip.seq_flags[node.type]
    stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
    idx, skipped = ip.mem(w, node)
    n = len(node.children)
    if frame[1] == 0:
        if w.st.get(node.id, IDLE) == IDLE:  # !isStatusActive(status())
            skipped = 0
        w.st[node.id] = RUNNING
    else:
        prev = frame[2]
        if result == RUNNING:
            ip.set_mem(w, node, (idx, skipped))
            return ("ret", RUNNING)
        if result == stop:
            if with_memory:
                ip.reset_children(w, node, hook, first=idx)
            else:
                ip.reset_children(w, node, hook)
                idx = 0
            ip.set_mem(w, node, (idx, skipped))
            return ("ret", stop)
        if result == go_on:
            idx += 1
            if (asynch or with_memory) and prev == IDLE and idx < n:
                w.wake = True
                ip.set_mem(w, node, (idx, skipped))
                return ("ret", RUNNING)
        elif result == SKIPPED:
            idx += 1
            skipped += 1
        else:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
    if idx < n:
        child = node.children[idx]
        ip.set_mem(w, node, (idx, skipped))
        return ("call", child, (node.id, 1, w.st.get(child, IDLE)))
    all_skipped = skipped == n
    ip.reset_children(w, node, hook)
    ip.set_mem(w, node, (0, 0))
    return ("ret", SKIPPED if all_skipped else go_on)


def _wakes_up(node: CompiledNode) -> bool:
    """An asynchronous or WithMemory sequence reads its child's status before the call (the
    wake-up test; ``CanonicalReads.reads_prev``)."""
    spec = node_semantics(node.type)
    return spec is not None and (spec.asynchronous or spec.with_memory)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "sequence": FamilyRule(
        tick_sequence,
        canonical=CanonicalReads(
            prev_frame=True, reads_prev=_wakes_up, last_child_prev_unread=True
        ),
    ),
}
