"""Loop families: Repeat, RetryUntilSuccessful (repeat_node.cpp, retry_node.cpp), MoveIt Pro
RepeatUnlessFailureEachTick, and the blackboard loops LoopInt/LoopBool/LoopDouble/LoopString
(loop_node.h; docs/semantics.md "Decorators", "Project nodes", §10).

Contract: Repeat / Retry tick the child again, in the same tick, while it returns the repeated
result, at most ``num_cycles`` / ``num_attempts`` times (-1: no bound, the count then stays 0);
memory ``(count,)``; after a synchronous child they return RUNNING with a wake-up.
RepeatUnlessFailureEachTick: one cycle per tick, no wake-up. Loop*: memory ``(elements left,
child running)``; a literal queue is read at build time (its element type checked as
BehaviorTree.CPP's convertFromString does), a {blackboard} queue is an abstraction whose gate
says whether an element is left.
"""

from __future__ import annotations

import re
from typing import Any

from fsmbt.model.bt import BTNode
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.nodes import canonical_type
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
from fsmbt.semantics.families.ports import int_param, status_param, where


def repeat_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(num_cycles,)``, required."""
    return (int_param(node, "num_cycles", None),)


def retry_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(num_attempts,)``, required."""
    return (int_param(node, "num_attempts", None),)


def repeat_each_tick_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(num_cycles,)``, -1 (no bound) by default."""
    return (int_param(node, "num_cycles", -1),)


#: How BehaviorTree.CPP 4.8 reads one element of a literal Loop queue (convertFromString<T>):
#: int: std::from_chars (a leading '-' and digits; the rest is ignored; int32 bounds), double:
#: std::stod (leading spaces, then a number, inf or nan), bool: the six spellings it accepts.
_INT_ELEMENT = re.compile(r"-?\d+")
_DOUBLE_ELEMENT = re.compile(r"\s*[+-]?(\d|\.\d|inf|nan)", re.IGNORECASE)
_BOOL_ELEMENTS = frozenset({"0", "1", "true", "TRUE", "True", "false", "FALSE", "False"})


def _queue_elements(text: str) -> list[str]:
    """BehaviorTree.CPP's ``splitString(queue, ';')``: "" has no element, a trailing ';'
    adds none, ";;" in the middle adds an empty one."""
    parts: list[str] = []
    pos = 0
    while pos < len(text):
        end = text.find(";", pos)
        end = len(text) if end < 0 else end
        parts.append(text[pos:end])
        pos = end + 1
    return parts


def _element_ok(ctype: str, element: str) -> bool:
    if ctype == "LoopInt":
        match = _INT_ELEMENT.match(element)
        return match is not None and -(2**31) <= int(match.group()) < 2**31
    if ctype == "LoopDouble":
        return _DOUBLE_ELEMENT.match(element) is not None
    if ctype == "LoopBool":
        return element in _BOOL_ELEMENTS
    return True  # LoopString: any text


def loop_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(if_empty status, queue length)`` of a Loop node; length ``-1``: a {blackboard}
    queue (an abstraction, its gate says whether an element is left)."""
    if_empty = status_param(node, "if_empty", "SUCCESS")
    raw = node.attrs.get("queue")
    if raw is None:
        raise InputError(f"{ctype}: missing port 'queue'", **where(node))
    if not exact:
        return (if_empty, -1)
    if canonical_type(node.type) != ctype:
        raise UnsupportedError(
            f"{node.type} (read as {ctype}) has a literal queue {raw!r}: how many elements it "
            "holds depends on the element type's own convertFromString; give the queue as a "
            f"{{blackboard}} entry (an abstraction) or use {ctype} itself",
            **where(node),
        )
    elements = _queue_elements(raw)
    for element in elements:
        if not _element_ok(ctype, element):
            raise InputError(
                f"{ctype}: queue element {element!r} of {raw!r} is not a valid "
                f"{ctype[4:].lower()} (BehaviorTree.CPP refuses to build the tree)",
                **where(node),
            )
    return (if_empty, len(elements))


def tick_repeat(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Repeat num_cycles (repeat_node.cpp); -1 repeats forever."""
    return loop_decorator(ip, w, node, frame, result, hook, again_on=SUCCESS)


def tick_retry(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """RetryUntilSuccessful num_attempts (retry_node.cpp); -1 retries forever."""
    return loop_decorator(ip, w, node, frame, result, hook, again_on=FAILURE)


def loop_decorator(
    ip: Interp,
    w: Work,
    node: CompiledNode,
    frame: Frame,
    result: int | None,
    hook: HaltHook | None,
    *,
    again_on: int,
) -> TickAction:
    """Repeat and RetryUntilSuccessful are mirror images in BehaviorTree.CPP: the child is
    ticked again while it returns ``again_on``, at most ``node.params[0]`` times (-1: no
    bound); the other result ends the loop at once. A loop that goes on in the same tick
    after a synchronous child asks for a wake-up and returns RUNNING, as v4 does."""
    (limit,) = node.params
    (count,) = ip.mem(w, node)
    child = node.children[0]
    stop_on = FAILURE if again_on == SUCCESS else SUCCESS
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        do_loop = count < limit or limit == -1
    else:
        prev = frame[2]
        if result == again_on:
            # with -1 the count is never read: keep it 0 so states stay finite
            count = count + 1 if limit != -1 else 0
            do_loop = count < limit or limit == -1
            ip.reset_child(w, child, hook)
            if prev == IDLE and do_loop:
                w.wake = True
                ip.set_mem(w, node, (count,))
                return ("ret", RUNNING)
        elif result == stop_on:
            ip.set_mem(w, node, (0,))
            ip.reset_child(w, child, hook)
            return ("ret", stop_on)
        elif result == RUNNING:
            return ("ret", RUNNING)
        elif result == SKIPPED:
            ip.reset_child(w, child, hook)
            return ("ret", SKIPPED)
        else:
            raise BTRuntimeError("a child returned IDLE", element=node.label)
    if do_loop:
        ip.set_mem(w, node, (count,))
        return ("call", child, (node.id, 1, w.st.get(child, IDLE)))
    ip.set_mem(w, node, (0,))
    return ("ret", again_on)


def tick_repeat_each_tick(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """MoveIt Pro RepeatUnlessFailureEachTick: one cycle per tick, no wake-up."""
    (limit,) = node.params
    (count,) = ip.mem(w, node)
    child = node.children[0]
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        return ("call", child, (node.id, 1))
    if result == RUNNING:
        return ("ret", RUNNING)
    ip.reset_child(w, child, hook)
    if result == SUCCESS:
        if limit != -1:  # with -1 the count is never read: keep it 0 (finite states)
            count += 1
            if count >= limit:
                ip.set_mem(w, node, (0,))
                return ("ret", SUCCESS)
        ip.set_mem(w, node, (count,))
        return ("ret", RUNNING)
    if result == FAILURE:
        ip.set_mem(w, node, (0,))
        return ("ret", FAILURE)
    return ("ret", SKIPPED)


def tick_loop_queue(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """LoopInt / LoopBool / LoopDouble / LoopString (loop_node.h, docs/semantics.md).

    ``params = (if_empty, length)``. A literal queue of ``length`` elements is reloaded when
    the node is ticked while IDLE; its memory is how many elements are left and whether the
    child returned RUNNING on its last tick (``child_running_``). ``length = -1``
    (a {blackboard} queue, an abstraction): the gate, the last child, says whether the
    queue still has an element. An element is popped only while the child is not RUNNING;
    no element left returns ``if_empty`` without setting RUNNING (a SKIPPED result leaves
    the stored status as it was, as ``executeTick`` does)."""
    if_empty, length = node.params
    child = node.children[0]
    pc = frame[1]
    left, child_running = ip.mem(w, node)
    if pc == 0:
        if w.st.get(node.id, IDLE) == IDLE:
            left, child_running = length, False  # the static queue is copied afresh
        if length < 0:
            if child_running:
                w.st[node.id] = RUNNING
                return ("call", child, (node.id, 2))
            return ("call", node.children[-1], (node.id, 1))
        if not child_running:
            if left == 0:
                ip.set_mem(w, node, (0, False))
                return ("ret", if_empty)
            left -= 1  # pop_front, written to the 'value' port
        ip.set_mem(w, node, (left, child_running))
        w.st[node.id] = RUNNING
        return ("call", child, (node.id, 2))
    if pc == 1:  # the gate answered: does the blackboard queue have an element?
        w.st.pop(node.children[-1], None)
        if result == SUCCESS:
            w.st[node.id] = RUNNING
            return ("call", child, (node.id, 2))
        ip.set_mem(w, node, (0, False))
        return ("ret", if_empty)
    # child_running_ is the node's own flag, not the child's stored status: a child that
    # returned SKIPPED keeps its old (possibly RUNNING) status but clears the flag
    ip.set_mem(w, node, (max(left, 0), result == RUNNING))
    if result in (SUCCESS, FAILURE):
        ip.reset_child(w, child, hook)
    return ("ret", FAILURE if result == FAILURE else RUNNING)


def _loops_again(node: CompiledNode) -> bool:
    """Repeat/Retry: a child's completion may be followed by another cycle in the same
    activation, so the wake-up test reads the child's status before the call."""
    (limit,) = node.params
    return bool(limit == -1 or limit >= 2)


#: Repeat and Retry in the canonical class: their frames hold ``prev``, read when the loop may
#: go round again (``CanonicalReads``).
_COUNTED_READS = CanonicalReads(prev_frame=True, reads_prev=_loops_again)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "repeat": FamilyRule(tick_repeat, params=repeat_params, canonical=_COUNTED_READS),
    "retry": FamilyRule(tick_retry, params=retry_params, canonical=_COUNTED_READS),
    "repeat_each_tick": FamilyRule(tick_repeat_each_tick, params=repeat_each_tick_params),
    "loop_queue": FamilyRule(tick_loop_queue, params=loop_params),
}
