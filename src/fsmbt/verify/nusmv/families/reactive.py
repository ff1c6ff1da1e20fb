"""NuSMV rule of the reactive family: ReactiveSequence, ReactiveFallback (docs/semantics.md
"Control nodes", "SKIPPED"; docs/nusmv.md), mirroring ``fsmbt.semantics.families.reactive``
(``tick_reactive``; BehaviorTree.CPP 4.8 reactive_sequence.cpp, reactive_fallback.cpp).

Rule ``reactive``. No memory: every tick calls child 0 and each return moves on by ``lidx``. A
RUNNING child resets every other child and the node returns RUNNING; the stop status (FAILURE
for a sequence, SUCCESS for a fallback) resets every child and is returned; the other status
calls the next child, or after the last one resets them all and is returned. A child that may
return SKIPPED adds the frame flag ``rk_n`` ("every child so far skipped", 1 off the stack so
the state stays canonical; the encoder's ``ret`` sets it back): after the last child the node
returns SKIPPED when it is still set.

Cost: O(k) rules for k children; one bit when a child may skip.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics, all_nodes
from fsmbt.verify.nusmv.families.common import always, every_child_skips
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits

#: kind -> is_fallback
REACTIVE = {n.name: n.is_fallback for n in all_nodes() if n.nusmv == "reactive"}


def reactive(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """ReactiveSequence, ReactiveFallback (the module docstring)."""
    kids = list(x.children)
    k = len(kids)
    is_fb = REACTIVE[x.type]
    stop, go_on = ("S", "F") if is_fb else ("F", "S")
    core.rule(core.st(x.id), called, "R")
    core.call(called, kids[0])
    back = f"{here} & res != NONE"
    skippable = any(core.may_skip[c] for c in kids)
    flag = f"rk_{x.id}"
    if skippable:  # the frame's "every child so far skipped" (1; canonical off the stack)
        core.var_types[flag] = "0..1"
        core.init[flag] = "1"
        core.rule(flag, called, "1")
        for i in range(k):
            cond = f"{back} & res = K & lidx = {i}"
            resets[kids[i]].append(cond)
            if i + 1 < k:
                core.call(cond, kids[i + 1])
            else:
                for c in kids:
                    resets[c].append(cond)
                all_skipped = f"case {flag} = 1 : K; TRUE : {go_on}; esac"
                core.ret(cond, x.id, all_skipped if core.may_skip[x.id] else go_on)
        core.rule(flag, f"{back} & res = {go_on} & lidx < {k - 1}", "0")
    running = f"{back} & res = R"
    for i, c in enumerate(kids):
        resets[c].append(f"{running} & lidx != {i}")
    core.ret(running, x.id, "R")
    stopped = f"{back} & res = {stop}"
    for c in kids:
        resets[c].append(stopped)
    core.ret(stopped, x.id, stop)
    for i in range(k):
        cond = f"{back} & res = {go_on} & lidx = {i}"
        if i + 1 < k:
            core.call(cond, kids[i + 1])
        else:
            for c in kids:
                resets[c].append(cond)
            core.ret(cond, x.id, go_on)


def _leaf_facts(
    x: CompiledNode,
    spec: NodeSemantics,
    sure: Sequence[bool],
    busy: Sequence[bool],
    may_skip: Sequence[bool],
) -> tuple[bool, bool]:
    """The livelock test's facts (``RuleTraits.leaf_facts``): every tick starts at child 0."""
    first = sure[x.children[0]]
    return first, first


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {"reactive": reactive}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): SKIPPED is
#: tracked by ``rk_n`` and returned when every child was skipped.
TRAITS: dict[str, RuleTraits] = {
    "reactive": RuleTraits(
        skip_aware=always, returns_skipped=every_child_skips, leaf_facts=_leaf_facts
    )
}
