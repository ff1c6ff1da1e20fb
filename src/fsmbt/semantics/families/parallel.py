"""Parallel family: Parallel, ParallelAll (parallel_node.cpp, parallel_all_node.cpp) and the
project kind stardust.RealParallel (docs/semantics.md "Control nodes", "Project nodes").

Contract: every child not completed in this run is ticked on every tick, in order.
Parallel: ``success_count`` / ``failure_count`` thresholds (negative: "all but"), checked after
each child's return, success first; memory ``(completed set, successes, failures)``.
ParallelAll: waits for every child, FAILURE when at least ``max_failures`` failed; memory
``(completed set, failures)``. RealParallel: no memory, ticks every child every tick and never
resets them. Checks at build time: a threshold above the number of children is an error.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from fsmbt.model.bt import BTNode
from fsmbt.model.errors import InputError
from fsmbt.model.nodes import canonical_type
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
from fsmbt.semantics.families.contract import FamilyRule, Interp
from fsmbt.semantics.families.ports import int_param, where


def parallel_threshold(value: int, count: int) -> int:
    """BehaviorTree.CPP's reading of a Parallel threshold: negative means "all but"."""
    return max(count + value + 1, 0) if value < 0 else value


def parallel_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(success_count, failure_count)``, both possible with this many children."""
    n = len(node.children)
    succ = int_param(node, "success_count", -1)
    fail = int_param(node, "failure_count", 1)
    if n < parallel_threshold(succ, n) or n < parallel_threshold(fail, n):
        raise InputError("Parallel threshold exceeds the number of children", **where(node))
    return (succ, fail)


def parallel_all_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(max_failures,)`` read as a count (negative: "all but"), at most the children."""
    n = len(node.children)
    fail = int_param(node, "max_failures", 1)
    if n < parallel_threshold(fail, n):
        raise InputError("ParallelAll max_failures exceeds the number of children", **where(node))
    return (parallel_threshold(fail, n),)


#: The kinds that end by counting their children's results (RealParallel never ends itself).
COUNTING_PARALLELS = ("Parallel", "ParallelAll")


@dataclass(frozen=True)
class ParallelCounts:
    """When a counting parallel ends, as counts of completed children (thresholds resolved).

    Attributes:
        waits_for_all: ParallelAll: it ends once every child completed, FAILURE when at least
            ``failures`` failed, else SUCCESS. Parallel: it ends as soon as ``successes``
            children succeeded (SUCCESS, checked first) or ``failures`` failed (FAILURE).
        successes: the success threshold (ParallelAll: 0, unused).
        failures: the failure threshold (ParallelAll: ``max_failures``).
    """

    waits_for_all: bool
    successes: int
    failures: int


def parallel_counts(node: BTNode) -> ParallelCounts | None:
    """The end rule of a counting parallel (``None``: ``node`` is not one), read with the
    interpreter's own checks.

    Raises:
        InputError: a threshold above the number of children.
    """
    kind = canonical_type(node.type)
    n = len(node.children)
    if kind == "Parallel":
        succ, fail = parallel_params(node, kind, True)
        return ParallelCounts(False, parallel_threshold(succ, n), parallel_threshold(fail, n))
    if kind == "ParallelAll":
        (fail,) = parallel_all_params(node, kind, True)
        return ParallelCounts(True, 0, fail)
    return None


def tick_parallel(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Parallel with success_count / failure_count (parallel_node.cpp)."""
    n = len(node.children)
    succ_param, fail_param = node.params
    need_s, need_f = parallel_threshold(succ_param, n), parallel_threshold(fail_param, n)
    completed, sc, fc = ip.mem(w, node)
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        i, skipped = 0, 0
        checked = False
    else:
        i, skipped = frame[2], frame[3]
        if result == SKIPPED:
            skipped += 1
        elif result == SUCCESS:
            completed, sc = completed | {i}, sc + 1
        elif result == FAILURE:
            completed, fc = completed | {i}, fc + 1
        elif result != RUNNING:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
        checked = True  # the child at i was ticked: run the checks for i below
    while i < n:
        if not checked and i not in completed:
            ip.set_mem(w, node, (completed, sc, fc))
            return ("call", node.children[i], (node.id, 1, i, skipped))
        checked = False
        if sc >= need_s or (succ_param < 0 and sc + skipped >= need_s):
            ip.set_mem(w, node, (frozenset(), 0, 0))
            ip.reset_children(w, node, hook)
            return ("ret", SUCCESS)
        if (n - fc) < need_s or fc == need_f:
            ip.set_mem(w, node, (frozenset(), 0, 0))
            ip.reset_children(w, node, hook)
            return ("ret", FAILURE)
        i += 1
    ip.set_mem(w, node, (completed, sc, fc))
    return ("ret", SKIPPED if skipped == n else RUNNING)


def tick_parallel_all(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """ParallelAll with max_failures (parallel_all_node.cpp)."""
    n = len(node.children)
    (need_f,) = node.params
    completed, fc = ip.mem(w, node)
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        i, skipped = 0, 0
    else:
        i, skipped = frame[2], frame[3]
        if result == SUCCESS:
            completed = completed | {i}
        elif result == FAILURE:
            completed, fc = completed | {i}, fc + 1
        elif result == SKIPPED:
            skipped += 1
        elif result != RUNNING:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
        i += 1
    while i < n and i in completed:
        i += 1
    if i < n:
        ip.set_mem(w, node, (completed, fc))
        return ("call", node.children[i], (node.id, 1, i, skipped))
    if skipped == n:
        ip.set_mem(w, node, (completed, fc))
        return ("ret", SKIPPED)
    if skipped + len(completed) >= n:
        ip.reset_children(w, node, hook)  # haltChildren()
        status = FAILURE if fc >= need_f else SUCCESS
        ip.set_mem(w, node, (frozenset(), 0))
        return ("ret", status)
    ip.set_mem(w, node, (completed, fc))
    return ("ret", RUNNING)


def tick_real_parallel(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """julienbayle/stardust RealParallel (docs/semantics.md, "Project nodes"): every child
    is ticked on every tick, in order, and never reset by the node (only its halt resets
    them); any RUNNING child: RUNNING, else any FAILURE: FAILURE, else SUCCESS. A SKIPPED
    child makes the project's node throw."""
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        return ("call", node.children[0], (node.id, 1, 0, False, False))
    i, running, failed = frame[2], frame[3], frame[4]
    if result == RUNNING:
        running = True
    elif result == FAILURE:
        failed = True
    elif result != SUCCESS:
        raise BTRuntimeError(
            "RealParallel: a child returned SKIPPED (the node throws on any status but "
            "SUCCESS, FAILURE and RUNNING)",
            element=node.label,
        )
    i += 1
    if i < len(node.children):
        return ("call", node.children[i], (node.id, 1, i, running, failed))
    return ("ret", RUNNING if running else FAILURE if failed else SUCCESS)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "parallel": FamilyRule(tick_parallel, params=parallel_params),
    "parallel_all": FamilyRule(tick_parallel_all, params=parallel_all_params),
    "real_parallel": FamilyRule(tick_real_parallel),
}
