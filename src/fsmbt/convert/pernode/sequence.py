"""Sequence and Fallback per node, with their with-memory and asynchronous kinds (handler
``sequence``; the reference is ``fsmbt.semantics.families.sequence.tick_sequence``).

Memory: ``idx`` (the running child) when the kind keeps memory across ticks (a with-memory kind
with two children or more) or may return RUNNING, and ``cr`` (the child at ``idx`` was RUNNING
before this tick: the wake-up test of an asynchronous / with-memory kind reads it).

Rules: the entry resumes at ``[idx == i] -> child i`` (child 0 otherwise). Child i's go-on
result sets ``idx = i + 1`` and ticks the next child - or, for an asynchronous / with-memory
kind whose child completed in this tick (``cr == 0``), returns RUNNING (the wake-up); the last
child's go-on resets ``idx`` and returns the go-on result. The stop result returns it, resetting
``idx`` unless the kind keeps memory. RUNNING sets ``cr``. A halt resets ``idx`` when the kind
forgets its memory on halt (a SequenceWithMemory keeps it, as BehaviorTree.CPP 4.8.2 does) and
always clears ``cr``. Cost: O(children) states and transitions.
"""

from __future__ import annotations

from fsmbt.convert.pernode.kernel import Assign, Cont, NodeRule, RegionWriter, Returns
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, CompiledNode


def can_run(writer: RegionWriter, node: CompiledNode, kids: list[bool]) -> bool:
    """A child may run, or a wake-up of an asynchronous / with-memory kind returns RUNNING."""
    _fb, asynch, memory = writer.tables.sequence_flags[node.type]
    return any(kids) or ((asynch or memory) and len(kids) > 1)


def declare(writer: RegionWriter, node: CompiledNode) -> list[Assign]:
    """``idx`` and ``cr`` where the rules above read them."""
    _fb, asynch, memory = writer.tables.sequence_flags[node.type]
    own: list[Assign] = []
    n = len(node.children)
    wakes = (asynch or memory) and n > 1
    if memory and n > 1 or writer.can_run[node.id]:
        var = writer.variable(node, "idx", writer.idx)
        if node.type in writer.tables.halt_resets_memory:
            own.append((var, "0"))
    if wakes and any(writer.can_run[c] for c in node.children[:-1]):
        own.append((writer.variable(node, "cr", writer.cr), "0"))
    return own


def write(writer: RegionWriter, node: CompiledNode, returns: Returns) -> list[Returns]:
    """The entry, then per child where its results lead (module docstring)."""
    is_fallback, asynch, memory = writer.tables.sequence_flags[node.type]
    stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
    kids = node.children
    n = len(kids)
    idx, cr = writer.idx.get(node.id), writer.cr.get(node.id)
    if idx is not None:  # the entry: resume at the running (or kept) child
        entry = writer.entry[node.id]
        for i in range(1, n):
            writer.go(entry, None, Cont(writer.entry[kids[i]]), f"{idx} == {i}")
        writer.go(entry, None, Cont(writer.entry[kids[0]]))
    done: list[Assign] = [(v, "0") for v in (idx, cr) if v is not None]
    out: list[Returns] = []
    for i in range(n):
        conts: Returns = {}
        if i == n - 1:
            conts[go_on] = returns[go_on].after(done)
        else:
            step = [(idx, str(i + 1))] if idx is not None else []
            onward = Cont(writer.entry[kids[i + 1]], tuple(step))
            if asynch or memory:  # a child that completed in this tick: wake-up, RUNNING
                wake = returns[RUNNING].after(step)
                if cr is not None:
                    resumed = Cont(onward.target, (*step, (cr, "0")))
                    conts[go_on] = writer.transient(
                        node, f"next{i}", [(f"{cr} == 1", resumed), (None, wake)]
                    )
                else:
                    conts[go_on] = wake
            else:
                conts[go_on] = onward
        kept = [(cr, "0")] if cr is not None else []
        if not memory and idx is not None:
            kept = [(idx, "0"), *kept]
        conts[stop] = returns[stop].after(kept)
        conts[RUNNING] = returns[RUNNING].after([(cr, "1")] if cr is not None else [])
        out.append(conts)
    return out


RULE = NodeRule(frozenset({"sequence"}), can_run, declare, write)
