"""Gated abstractions: Nav2's controllers, Delay, Precondition, BlackboardCheck*, Timeout,
Sleep, MoveIt Pro ForEach (docs/semantics.md §10, "Abstractions").

Contract: the kind declares a ``Gate`` (``fsmbt.model.nodes.registry``); the interpreter adds
the gate, a condition the environment answers, as the node's last child. ``gated``: the gate
decides whether the child is ticked (else the declared closed status, read from the declared
``closed_port``); ``timeout``: the gate is the timer firing (FAILURE, child halted); ``sleep``:
RUNNING until the gate says the time is up; ``for_each``: the gate says whether the vector has
another element, one element per tick. No memory.
"""

from __future__ import annotations

from fsmbt.model.nodes import node_semantics
from fsmbt.model.nodes.registry import Gate
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
from fsmbt.semantics.families.contract import CanonicalReads, FamilyRule, Interp


def gate_of(node: CompiledNode) -> Gate:
    """The node's declared gate."""
    spec = node_semantics(node.type)
    assert spec is not None and spec.gate is not None
    return spec.gate


def tick_gated(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """An abstraction whose gate (the last child, a condition the environment answers)
    decides whether the child is ticked: Nav2's controllers, Delay, Precondition,
    BlackboardCheck* (docs/semantics.md §10)."""
    gate_rule = gate_of(node)
    child, gate = node.children[0], node.children[-1]
    (closed,) = node.params
    pc = frame[1]
    if pc == 0:
        prev = w.st.get(node.id, IDLE)
        w.st[node.id] = RUNNING
        child_status = w.st.get(child, IDLE)
        if (gate_rule.free_when_idle and prev == IDLE) or (
            gate_rule.free_when_running and child_status == RUNNING
        ):
            return ("call", child, (node.id, 2))
        return ("call", gate, (node.id, 1))
    if pc == 1:
        w.st.pop(gate, None)  # a gate keeps no status: it is asked afresh each time
        if result == SUCCESS:
            return ("call", child, (node.id, 2))
        if gate_rule.halt_on_closed and w.st.get(child, IDLE) == RUNNING:
            ip.reset_child(w, child, hook)
        return ("ret", closed)
    if gate_rule.reset_on_done and result in (SUCCESS, FAILURE):
        ip.reset_child(w, child, hook)
    return ("ret", result)


def tick_timeout(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Timeout as an abstraction: the timer (the gate) may fire on any tick after the
    first; fired, the child is halted and the node returns FAILURE."""
    child, gate = node.children[0], node.children[-1]
    pc = frame[1]
    if pc == 0:
        started = w.st.get(node.id, IDLE) == RUNNING
        w.st[node.id] = RUNNING
        if not started:
            return ("call", child, (node.id, 2))
        return ("call", gate, (node.id, 1))
    if pc == 1:
        w.st.pop(gate, None)
        if result == SUCCESS:  # fired
            ip.reset_child(w, child, hook)
            return ("ret", FAILURE)
        return ("call", child, (node.id, 2))
    if result in (SUCCESS, FAILURE):
        ip.reset_child(w, child, hook)
    return ("ret", result)


def tick_sleep(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """Sleep as an abstraction: RUNNING until the timer (the gate) says the time is up."""
    gate = node.children[-1]
    if frame[1] == 0:
        w.st[node.id] = RUNNING
        return ("call", gate, (node.id, 1))
    w.st.pop(gate, None)
    return ("ret", SUCCESS if result == SUCCESS else RUNNING)


def tick_for_each(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """MoveIt Pro ForEach / ForEachUntilSuccess as an abstraction: the gate says whether
    the vector has another element; one element per tick."""
    (no_more,) = node.params
    stop = FAILURE if no_more == SUCCESS else SUCCESS
    child, gate = node.children[0], node.children[-1]
    pc = frame[1]
    if pc == 0:
        w.st[node.id] = RUNNING
        if w.st.get(child, IDLE) == RUNNING:
            return ("call", child, (node.id, 2))
        return ("call", gate, (node.id, 1))
    if pc == 1:
        w.st.pop(gate, None)
        if result == SUCCESS:
            return ("call", child, (node.id, 2))
        return ("ret", no_more)
    if result == RUNNING:
        return ("ret", RUNNING)
    ip.reset_child(w, child, hook)
    return ("ret", stop if result == stop else RUNNING)


def _closed_not_skipped(node: CompiledNode) -> bool:
    """A gated node whose closed gate returns SKIPPED (its ``closed`` port or the declared
    default) is outside the canonical class."""
    return not (bool(node.params) and node.params[0] == SKIPPED)


#: A gated node in the canonical class: its declared ``Gate`` says what it reads.
_GATED_READS = CanonicalReads(member=_closed_not_skipped, reads_gate=True)


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "gated": FamilyRule(tick_gated, canonical=_GATED_READS),
    "timeout": FamilyRule(tick_timeout),
    "sleep": FamilyRule(tick_sleep),
    "for_each": FamilyRule(tick_for_each),
}
