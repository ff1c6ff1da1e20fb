"""Nav2 control families: PipelineSequence, RecoveryNode, RoundRobin (nav2_behavior_tree
pipeline_sequence.cpp, recovery_node.cpp, round_robin_node.cpp; docs/semantics.md "Project
nodes").

Contract: PipelineSequence re-ticks every earlier child on each tick up to the furthest one
reached (memory ``(last,)``). RecoveryNode: main child 0, recovery child 1, at most
``number_of_retries`` recoveries (memory ``(child, tries)``). RoundRobin resumes at the child
after the last one ticked (memory ``(index, failures)``), with ``wrap_around``.
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.bt import BTNode
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
from fsmbt.semantics.families.contract import (
    PLAIN_READS,
    CanonicalReads,
    FamilyRule,
    Interp,
)
from fsmbt.semantics.families.ports import bool_param, int_param


def recovery_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(number_of_retries,)``, 1 by default."""
    return (int_param(node, "number_of_retries", 1),)


def round_robin_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(wrap_around,)``, false by default."""
    return (bool_param(node, "wrap_around", False),)


def tick_pipeline(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Nav2 PipelineSequence (pipeline_sequence.cpp)."""
    (last,) = ip.mem(w, node)
    n = len(node.children)
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        i, skipped = 0, 0
    else:
        i, skipped = frame[2], frame[3]
        if result == FAILURE:
            ip.reset_children(w, node, hook)
            ip.set_mem(w, node, (0,))
            return ("ret", FAILURE)
        if result == SKIPPED:
            skipped += 1
        elif result == RUNNING:
            if i >= last:
                ip.set_mem(w, node, (i,))
                return ("ret", RUNNING)
        elif result != SUCCESS:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
        i += 1
    if i < n:
        return ("call", node.children[i], (node.id, 1, i, skipped))
    ip.reset_children(w, node, hook)
    ip.set_mem(w, node, (0,))
    return ("ret", SKIPPED if skipped == n else SUCCESS)


def tick_recovery(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Nav2 RecoveryNode (recovery_node.cpp): main child 0, recovery child 1."""
    (retries,) = node.params
    idx, tries = ip.mem(w, node)
    main, recovery = node.children
    if frame[1] == 0:
        w.st[node.id] = RUNNING
    elif idx == 0:
        if result == RUNNING:
            return ("ret", RUNNING)
        if result in (SUCCESS, SKIPPED):
            ip.reset_children(w, node, hook)  # haltChild(1), then halt()
            ip.set_mem(w, node, (0, 0))
            return ("ret", result)
        if result != FAILURE:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
        if tries >= retries:
            ip.reset_children(w, node, hook)
            ip.set_mem(w, node, (0, 0))
            return ("ret", FAILURE)
        ip.reset_child(w, main, hook)
        idx = 1
    else:
        if result == RUNNING:
            return ("ret", RUNNING)
        if result == SKIPPED:  # no recovery possible; not a retry
            ip.reset_child(w, recovery, hook)
            ip.set_mem(w, node, (0, tries))
            return ("ret", FAILURE)
        if result == FAILURE:
            ip.reset_children(w, node, hook)
            ip.set_mem(w, node, (0, 0))
            return ("ret", FAILURE)
        if result != SUCCESS:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
        ip.reset_child(w, recovery, hook)
        idx, tries = 0, tries + 1
    if tries <= retries:
        ip.set_mem(w, node, (idx, tries))
        return ("call", node.children[idx], (node.id, 1))
    ip.reset_children(w, node, hook)
    ip.set_mem(w, node, (0, 0))
    return ("ret", FAILURE)


def tick_round_robin(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Nav2 RoundRobin (round_robin_node.cpp), with its ``wrap_around`` port."""
    (wrap,) = node.params
    n = len(node.children)
    idx, failed = ip.mem(w, node)
    ended = False
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        skipped = 0
    else:
        skipped = frame[2]
        if result not in (SUCCESS, FAILURE, RUNNING, SKIPPED):
            raise BTRuntimeError("a child returned IDLE", element=node.label)
        if result != RUNNING:
            idx += 1
            if idx == n:
                if wrap:
                    idx = 0
                else:  # the end of the list: counted, then the loop stops
                    skipped += result == SKIPPED
                    failed += result == FAILURE
                    ended = True
        if not ended:
            if result == SUCCESS:
                ip.reset_children(w, node, hook)
                ip.set_mem(w, node, (idx, 0))
                return ("ret", SUCCESS)
            if result == RUNNING:
                ip.set_mem(w, node, (idx, failed))
                return ("ret", RUNNING)
            if result == FAILURE:
                failed += 1
            else:
                skipped += 1
    if not ended and failed + skipped < n:
        ip.set_mem(w, node, (idx, failed))
        return ("call", node.children[idx], (node.id, 1, skipped))
    ip.reset_children(w, node, hook)
    ip.set_mem(w, node, (0, 0))
    return ("ret", SKIPPED if skipped == n else FAILURE)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "pipeline": FamilyRule(
        tick_pipeline, canonical=CanonicalReads(keeps_finished=True, furthest_index=True)
    ),
    "recovery": FamilyRule(tick_recovery, params=recovery_params, canonical=PLAIN_READS),
    "round_robin": FamilyRule(tick_round_robin, params=round_robin_params, canonical=PLAIN_READS),
}
