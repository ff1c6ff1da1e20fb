"""NuSMV rule of the sequence family: Sequence, Fallback, AsyncSequence, AsyncFallback,
SequenceWithMemory (docs/semantics.md "Control nodes", "SKIPPED"; docs/nusmv.md), mirroring
``fsmbt.semantics.families.sequence`` (``tick_sequence``; BehaviorTree.CPP 4.8
sequence_node.cpp, fallback_node.cpp, sequence_with_memory_node.cpp).

Rule ``sequence``. Variables (declared by the encoder, as ``TRAITS`` asks): ``idx_n``,
the running child's index (reset by a halt except with memory), and the frame local ``prev_n``,
the child's status when it was called. Children are called in order from ``idx_n``; the stop
status (FAILURE for a sequence, SUCCESS for a fallback) resets the children (with memory: only
from the failed one on) and is returned; the other status moves to the next child, or after the
last one resets them all and is returned. An asynchronous kind, or one with memory, returns
RUNNING with a wake-up (``wake``) after a child that was IDLE when called (it completed
synchronously). A child that may return SKIPPED adds ``sk_n``, the skipped count (zeroed when
the node is ticked while IDLE and when it completes; kept by SequenceWithMemory's halt): after
the last child the node returns SKIPPED when every child was skipped.

Cost: O(k) rules for k children; one variable of log2(k) bits for the skipped count.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics, all_nodes
from fsmbt.verify.nusmv.families.common import always, every_child_skips, increment
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits

#: kind -> (is_fallback, emits wake-up after a fresh child succeeds/fails, with memory)
SEQ_LIKE = {
    n.name: (n.is_fallback, n.wakes_up, n.with_memory) for n in all_nodes() if n.nusmv == "sequence"
}


def sequence(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """Sequence, Fallback, Async*, SequenceWithMemory (the module docstring)."""
    kids = list(x.children)
    k = len(kids)
    is_fb, wakes, memory = SEQ_LIKE[x.type]
    stop, go_on = ("S", "F") if is_fb else ("F", "S")
    idx = f"idx_{x.id}"
    skippable = any(core.may_skip[c] for c in kids)
    if skippable:  # the skipped count (memory; SequenceWithMemory's halt keeps it)
        skipped = core.memory(
            "sk", x.id, sum(core.may_skip[c] for c in kids), reset_by_halt=not memory
        )
        core.rule(skipped, f"{called} & {core.st(x.id)} = I", "0")
    core.rule(core.st(x.id), called, "R")
    for i, c in enumerate(kids):
        cond = f"{called} & {idx} = {i}"
        core.call(cond, c)
        core.rule(f"prev_{x.id}", cond, core.st(c))
    back = f"{here} & res != NONE"
    core.ret(f"{back} & res = R", x.id, "R")
    stopped = f"{back} & res = {stop}"
    if memory:
        for i, c in enumerate(kids):
            resets[c].append(f"{stopped} & {idx} <= {i}")
    else:
        for c in kids:
            resets[c].append(stopped)
        core.rule(idx, stopped, "0")
    core.ret(stopped, x.id, stop)
    went = f"{back} & res = {go_on}"
    for i in range(k):
        cond = f"{went} & {idx} = {i}"
        if i + 1 < k:
            if wakes:
                woke = f"{cond} & prev_{x.id} = I"
                core.rule("wake", woke, "TRUE")
                core.rule(idx, woke, str(i + 1))
                core.ret(woke, x.id, "R")
                cond = f"{cond} & prev_{x.id} != I"
            core.rule(idx, cond, str(i + 1))
            core.call(cond, kids[i + 1])
            core.rule(f"prev_{x.id}", cond, core.st(kids[i + 1]))
        else:
            for c in kids:
                resets[c].append(cond)
            core.rule(idx, cond, "0")
            if skippable:
                core.rule(skipped, cond, "0")
            core.ret(cond, x.id, go_on)
    if not skippable:
        return
    # SKIPPED (``tick_sequence``): the next child, no wake-up; after the last one the node
    # returns SKIPPED when every child was skipped, else go_on; the counter is zeroed when
    # the node is ticked while IDLE and when it completes
    top = sum(core.may_skip[c] for c in kids)
    for i in range(k):
        cond = f"{back} & res = K & {idx} = {i}"
        core.rule(skipped, cond, increment(skipped, top))
        if i + 1 < k:
            core.rule(idx, cond, str(i + 1))
            core.call(cond, kids[i + 1])
            core.rule(f"prev_{x.id}", cond, core.st(kids[i + 1]))
        else:
            for c in kids:
                resets[c].append(cond)
            core.rule(idx, cond, "0")
            core.rule(skipped, cond, "0")
            all_skipped = f"case {skipped} >= {k - 1} : K; TRUE : {go_on}; esac"
            core.ret(cond, x.id, all_skipped if core.may_skip[x.id] else go_on)


def _leaf_facts(
    x: CompiledNode,
    spec: NodeSemantics,
    sure: Sequence[bool],
    busy: Sequence[bool],
    may_skip: Sequence[bool],
) -> tuple[bool, bool]:
    """The livelock test's facts (``RuleTraits.leaf_facts``). Sequence/Fallback (no wake-up,
    no memory): child 0 ``sure`` and every later child ``busy`` (the index is above 0 at a
    tick's start only while that child is RUNNING: any completion moves or resets it in the
    same tick, a halt resets it). The other kinds: every child ``sure``."""
    kids = x.children
    if not spec.wakes_up and not spec.with_memory:
        plain = sure[kids[0]] and all(busy[c] for c in kids[1:])
        return plain, plain
    every = all(sure[c] for c in kids)
    return every, every


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {"sequence": sequence}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): SKIPPED is
#: counted (``sk_n``) and returned when every child was skipped; ``idx_n`` and ``prev_n`` are
#: the frame; a completed child is reset before it is ticked again.
TRAITS: dict[str, RuleTraits] = {
    "sequence": RuleTraits(
        skip_aware=always,
        returns_skipped=every_child_skips,
        index=True,
        prev=True,
        keeps_completed=True,
        leaf_facts=_leaf_facts,
    )
}
