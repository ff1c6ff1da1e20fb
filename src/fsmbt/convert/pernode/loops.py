"""Repeat and RetryUntilSuccessful per node (handlers ``repeat``, ``retry``; the reference is
``fsmbt.semantics.families.loops.loop_decorator``).

Memory: ``count`` (the repetitions done, when the limit is above 1) and ``cr`` (the child was
RUNNING before this tick, when the child may run and the limit is not 1). Rules: the repeated
result (SUCCESS for Repeat, FAILURE for Retry) goes on while ``count + 1 < limit`` - again at
once after a child that was RUNNING (``cr == 1``), else RUNNING (the wake-up) - and returns once
the limit is reached, resetting the memory; the other result returns it, resetting the memory;
RUNNING sets ``cr``. A count of 0 is refused (the node returns at once without its child).
Cost: O(1) states and transitions.
"""

from __future__ import annotations

from fsmbt.convert.pernode.kernel import (
    LOOP_AGAIN_ON,
    Assign,
    Cont,
    NodeRule,
    RegionWriter,
    Returns,
)
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, CompiledNode


def can_run(_writer: RegionWriter, node: CompiledNode, kids: list[bool]) -> bool:
    """The child may run, or a repetition past the first returns RUNNING (the wake-up)."""
    limit = node.params[0]
    return kids[0] or limit != 1


def declare(writer: RegionWriter, node: CompiledNode) -> list[Assign]:
    """``count`` and ``cr`` where the rules above read them; a halt resets both."""
    own: list[Assign] = []
    limit = node.params[0]
    if limit is not None and limit > 1:
        own.append((writer.variable(node, "count", writer.count), "0"))
    if limit != 1 and writer.can_run[node.children[0]]:
        own.append((writer.variable(node, "cr", writer.cr), "0"))
    return own


def write(writer: RegionWriter, node: CompiledNode, returns: Returns) -> list[Returns]:
    """Where the only child's results lead (module docstring)."""
    again_on = LOOP_AGAIN_ON[writer.tables.handlers.get(node.type) or ""]
    stop_on = FAILURE if again_on == SUCCESS else SUCCESS
    limit = node.params[0]
    count, cr = writer.count.get(node.id), writer.cr.get(node.id)
    child_entry = writer.entry[node.children[0]]
    rest: list[Assign] = [(v, "0") for v in (count, cr) if v is not None]
    if limit == 1:
        again = returns[again_on]
    else:
        arms: list[tuple[str | None, Cont]] = []
        bump = [(count, f"{count} + 1")] if count is not None else []
        if count is not None:
            arms.append((f"{count} >= {limit - 1}", returns[again_on].after(rest)))
        if cr is not None:
            arms.append((f"{cr} == 1", Cont(child_entry, (*bump, (cr, "0")))))
        arms.append((None, returns[RUNNING].after(bump)))
        again = writer.transient(node, "again", arms)
    return [
        {
            again_on: again,
            stop_on: returns[stop_on].after(rest),
            RUNNING: returns[RUNNING].after([(cr, "1")] if cr is not None else []),
        }
    ]


def refuse(node: CompiledNode) -> str | None:
    """A count of 0: the node returns at once, its child never ticked."""
    if node.params[0] is not None and node.params[0] == 0:
        return f"{node.type} '{node.label}' returns at once (a count of 0)"
    return None


RULE = NodeRule(frozenset(LOOP_AGAIN_ON), can_run, declare, write, refuse)
