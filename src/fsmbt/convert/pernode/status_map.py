"""Inverter, ForceSuccess, ForceFailure and KeepRunningUntilFailure per node (handler
``simple_decorator``; the reference is
``fsmbt.semantics.families.status_map.tick_simple_decorator``).

No state of its own: the child's results are rewired to the decorator's (``result_maps``;
KeepRunningUntilFailure, which has none, turns SUCCESS into RUNNING). Cost: O(1).
"""

from __future__ import annotations

from fsmbt.convert.pernode.kernel import Assign, NodeRule, RegionWriter, Returns
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, CompiledNode


def can_run(writer: RegionWriter, node: CompiledNode, kids: list[bool]) -> bool:
    """The child may run, or SUCCESS becomes RUNNING (KeepRunningUntilFailure)."""
    return kids[0] or node.type not in writer.tables.result_maps


def declare(_writer: RegionWriter, _node: CompiledNode) -> list[Assign]:
    """No variables."""
    return []


def write(writer: RegionWriter, node: CompiledNode, returns: Returns) -> list[Returns]:
    """Where the only child's results lead: the mapped results."""
    mapped = writer.tables.result_maps.get(node.type)
    if mapped is None:  # KeepRunningUntilFailure
        return [{SUCCESS: returns[RUNNING], FAILURE: returns[FAILURE], RUNNING: returns[RUNNING]}]
    return [{SUCCESS: returns[mapped[0]], FAILURE: returns[mapped[1]], RUNNING: returns[RUNNING]}]


RULE = NodeRule(frozenset({"simple_decorator"}), can_run, declare, write)
