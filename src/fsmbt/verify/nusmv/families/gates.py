"""NuSMV rules of the gated abstractions: Nav2's controllers, Delay, Precondition,
SkipUnlessUpdated, WaitValueUpdate, BlackboardCheck*, Timeout, Sleep, MoveIt Pro ForEach
(docs/semantics.md §10, "Abstractions"; docs/nusmv.md), mirroring
``fsmbt.semantics.families.gates`` (``tick_gated``, ``tick_timeout``, ``tick_sleep``,
``tick_for_each``).

The gate is the node's last child, a condition leaf the environment answers (the interpreter
adds it at compile time); it is reset as soon as it answers. Only statuses are kept: no
variable.

- ``gated``: the child is called directly while the declared ``Gate`` frees it (the node IDLE,
  the child RUNNING), else the gate is asked: SUCCESS calls the child, anything else returns
  the declared closed status (``x.params[0]``, SKIPPED allowed; a RUNNING child is halted first
  when the gate says ``halt_on_closed``); the child's status is passed on (reset when completed
  if ``reset_on_done``).
- ``timeout``: the gate says the timer fired (not asked on the first tick): FAILURE, the child
  reset; otherwise the child is ticked and its status passed on.
- ``sleep``: RUNNING until the gate says the time is up, then SUCCESS.
- ``for_each``: the gate says whether another element is left: none returns the closed status;
  one ticks the child, whose stop result (the other of SUCCESS/FAILURE) ends the loop, any
  other completion leaves the node RUNNING for the next element.

Cost: O(1) rules per node.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics, node_semantics
from fsmbt.semantics.status import NodeStatus
from fsmbt.verify.nusmv.families.common import (
    PASSED,
    SUCCESS,
    every_child_sure,
    returned_status,
)
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits, named
from fsmbt.verify.nusmv.smv import any_of


def _gate(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> str:
    """The rows every gated rule starts with (the node RUNNING when called, the gate reset once
    it answered); the condition "the gate answered"."""
    back = f"{here} & res != NONE"
    core.rule(core.st(x.id), called, "R")
    from_gate = f"{back} & lidx = {len(x.children) - 1}"
    resets[x.children[-1]].append(from_gate)
    return from_gate


def sleep(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """Sleep (the module docstring)."""
    from_gate = _gate(core, x, here, called, resets)
    core.call(called, x.children[-1])
    core.ret(f"{from_gate} & res = S", x.id, "S")
    core.ret(from_gate, x.id, "R")


def timeout(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """Timeout (the module docstring)."""
    from_gate = _gate(core, x, here, called, resets)
    c, gate = x.children[0], x.children[-1]
    from_child = f"{here} & res != NONE & lidx = 0"
    core.call(f"{called} & {core.st(x.id)} != R", c)
    core.call(called, gate)
    resets[c].append(f"{from_gate} & res = S")
    core.ret(f"{from_gate} & res = S", x.id, "F")
    core.call(from_gate, c)
    resets[c].append(f"{from_child} & (res = S | res = F)")
    core.ret(from_child, x.id, PASSED)


def gated(core: BTCore, x: CompiledNode, rule: str, here: str, called: str, resets: Resets) -> None:
    """The ``gated`` kinds and ForEach (``rule``: ``gated`` / ``for_each``; the module
    docstring)."""
    from_gate = _gate(core, x, here, called, resets)
    c, gate = x.children[0], x.children[-1]
    from_child = f"{here} & res != NONE & lidx = 0"
    spec = node_semantics(x.type)
    assert spec is not None and spec.gate is not None
    closed = returned_status(x, x.params[0], "", skipped_ok=rule == "gated")
    if rule == "for_each":
        core.call(f"{called} & {core.st(c)} = R", c)
        core.call(called, gate)
        core.call(f"{from_gate} & res = S", c)
        core.ret(from_gate, x.id, closed)
        stop = "F" if closed == SUCCESS else "S"
        core.ret(f"{from_child} & res = R", x.id, "R")
        resets[c].append(f"{from_child} & res != R")
        core.ret(f"{from_child} & res = {stop}", x.id, stop)
        core.ret(from_child, x.id, "R")
        return
    gate_rule = spec.gate
    free = []
    if gate_rule.free_when_idle:
        free.append(f"{core.st(x.id)} = I")
    if gate_rule.free_when_running:
        free.append(f"{core.st(c)} = R")
    if free:
        core.call(f"{called} & {any_of(free)}", c)
    core.call(called, gate)
    core.call(f"{from_gate} & res = S", c)
    if gate_rule.halt_on_closed:
        resets[c].append(f"{from_gate} & res = F & {core.st(c)} = R")
    core.ret(from_gate, x.id, closed)
    if gate_rule.reset_on_done:
        resets[c].append(f"{from_child} & (res = S | res = F)")
    core.ret(from_child, x.id, PASSED)


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "gated": named(gated, "gated"),
    "for_each": named(gated, "for_each"),
    "timeout": timeout,
    "sleep": sleep,
}


def _closed_skips(x: CompiledNode, spec: NodeSemantics, may_skip: Sequence[bool]) -> bool:
    """A gated node whose declared gate answers SKIPPED when closed may return SKIPPED."""
    return spec.gate is not None and spec.gate.closed == NodeStatus.SKIPPED.name


#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): a ``gated``
#: node may return SKIPPED (its closed gate) and may tick any child on any tick; the others
#: have the defaults.
TRAITS: dict[str, RuleTraits] = {
    "gated": RuleTraits(returns_skipped=_closed_skips, leaf_facts=every_child_sure),
}
