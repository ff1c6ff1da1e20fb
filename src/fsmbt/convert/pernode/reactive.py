"""ReactiveSequence and ReactiveFallback per node (handler ``reactive``; the reference is
``fsmbt.semantics.families.reactive.tick_reactive``).

No memory of its own: every tick starts at child 0 (the entry is child 0's). Child i's go-on
result ticks child i + 1 (the last child's returns it); its stop result and its RUNNING halt
the later children - a chain of transient states, one per later child with memory, each
resetting that child's subtree (``RegionWriter.chain``), so the size stays linear - and return.
Cost: O(children) states, O(subtree) assignments per halted child, once per chain.
"""

from __future__ import annotations

from fsmbt.convert.pernode.kernel import Assign, Cont, NodeRule, RegionWriter, Returns
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, CompiledNode


def can_run(_writer: RegionWriter, _node: CompiledNode, kids: list[bool]) -> bool:
    """RUNNING only from a child."""
    return any(kids)


def declare(_writer: RegionWriter, _node: CompiledNode) -> list[Assign]:
    """No variables: a reactive node remembers nothing between ticks."""
    return []


def write(writer: RegionWriter, node: CompiledNode, returns: Returns) -> list[Returns]:
    """Per child where its results lead (module docstring)."""
    is_fallback = node.type in writer.tables.reactive_fallbacks
    stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
    kids = node.children
    n = len(kids)
    stops = writer.chain(node, "stop", returns[stop])
    runs = writer.chain(node, "run", returns[RUNNING])
    return [
        {
            go_on: returns[go_on] if i == n - 1 else Cont(writer.entry[kids[i + 1]]),
            stop: stops[i + 1],
            RUNNING: runs[i + 1],
        }
        for i in range(n)
    ]


RULE = NodeRule(frozenset({"reactive"}), can_run, declare, write)
