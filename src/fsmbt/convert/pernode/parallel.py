"""Parallel and ParallelAll per node (handlers ``parallel``, ``parallel_all``; the reference is
``fsmbt.semantics.families.parallel.tick_parallel`` / ``tick_parallel_all``).

Memory: ``done<i>`` per child (it completed), ``successes`` and ``failures`` (counts); both kinds
forget all of it on halt. Rules: every child not completed is ticked in order (``visit i``:
``[done_i == 1]`` skips it); Parallel checks its thresholds after each child's result (success
first: ``successes >= need_s`` ends in SUCCESS, ``failures > n - need_s`` or ``failures ==
need_f`` in FAILURE), ParallelAll once every child completed (FAILURE when ``failures >=
max_failures``); ending halts every child and forgets the memory; a visit past the last child
returns RUNNING. A threshold of 0 is refused. Cost: O(children) states and transitions, and the
two halt chains.
"""

from __future__ import annotations

from fsmbt.convert.pernode.kernel import (
    EVENTS_BY_STATUS,
    PARALLEL_HANDLERS,
    Assign,
    Cont,
    NodeRule,
    RegionWriter,
    Returns,
)
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, CompiledNode
from fsmbt.semantics.families.parallel import parallel_threshold
from fsmbt.semantics.nodes import runtime_tables


def thresholds(node: CompiledNode) -> tuple[int, int]:
    """(successes, failures) needed, resolved (``families.parallel``); ParallelAll:
    (children, max_failures)."""
    n = len(node.children)
    if runtime_tables().handlers.get(node.type) == "parallel":
        succ, fail = node.params
        return parallel_threshold(succ, n), parallel_threshold(fail, n)
    return n, node.params[0]


def can_run(_writer: RegionWriter, _node: CompiledNode, kids: list[bool]) -> bool:
    """With two children or more it waits for the others; else as its child."""
    return len(kids) > 1 or kids[0]


def declare(writer: RegionWriter, node: CompiledNode) -> list[Assign]:
    """``done<i>``, ``successes`` and ``failures``; a halt resets all of them."""
    own: list[Assign] = []
    flags = writer.done.setdefault(node.id, {})
    for i in range(len(node.children)):
        own.append((writer.variable(node, f"done{i}", flags, i), "0"))
    own.append((writer.variable(node, "successes", writer.successes), "0"))
    own.append((writer.variable(node, "failures", writer.failures), "0"))
    return own


def write(writer: RegionWriter, node: CompiledNode, returns: Returns) -> list[Returns]:
    """The visits, then per child where its results lead (module docstring)."""
    kids = node.children
    n = len(kids)
    done = writer.done[node.id]
    sc, fc = writer.successes[node.id], writer.failures[node.id]
    need_s, need_f = thresholds(node)
    waits_for_all = writer.tables.handlers.get(node.type) == "parallel_all"
    forget = [(done[i], "0") for i in range(n)] + [(sc, "0"), (fc, "0")]
    halt_s = writer.chain(node, "S", returns[SUCCESS].after(forget), first=0)
    halt_f = writer.chain(node, "F", returns[FAILURE].after(forget), first=0)
    # visit i, from the last: skip a completed child, else tick it
    visits: list[Cont] = [Cont("")] * (n + 1)
    if waits_for_all:
        all_done = " and ".join(f"{done[i]} == 1" for i in range(n))
        visits[n] = writer.transient(
            node,
            "end",
            [
                (f"({all_done}) and {fc} >= {need_f}", halt_f[0]),
                (f"{all_done}", halt_s[0]),
                (None, returns[RUNNING]),
            ],
        )
    else:
        visits[n] = returns[RUNNING]
    for i in range(n - 1, -1, -1):
        if i == 0:
            visits[i] = Cont(writer.entry[node.id])
            writer.go(writer.entry[node.id], None, visits[i + 1], f"{done[i]} == 1")
            writer.go(writer.entry[node.id], None, Cont(writer.entry[kids[i]]))
        else:
            visits[i] = writer.transient(
                node,
                f"visit{i}",
                [(f"{done[i]} == 1", visits[i + 1]), (None, Cont(writer.entry[kids[i]]))],
            )
    out: list[Returns] = []
    for i in range(n):
        conts: Returns = {RUNNING: visits[i + 1]}
        for status, count in ((SUCCESS, sc), (FAILURE, fc)):
            mark = [(done[i], "1"), (count, f"{count} + 1")]
            if waits_for_all:
                conts[status] = visits[i + 1].after(mark)
                continue
            check = writer.transient(
                node,
                f"check{i}{EVENTS_BY_STATUS[status]}",
                [
                    (f"{sc} >= {need_s}", halt_s[0]),
                    (f"{fc} > {n - need_s} or {fc} == {need_f}", halt_f[0]),
                    (None, visits[i + 1]),
                ],
            )
            conts[status] = check.after(mark)
        out.append(conts)
    return out


def refuse(node: CompiledNode) -> str | None:
    """A threshold of 0: the node would end before ticking a child."""
    if 0 in thresholds(node):
        return f"{node.type} '{node.label}' has a threshold of 0"
    return None


RULE = NodeRule(PARALLEL_HANDLERS, can_run, declare, write, refuse)
