"""Size metrics of a model as the paper counts them (our reading: docs/metrics.md).

- BT graphical elements = nodes + edges of every tree in the document (a tree of n nodes has
  n - 1 edges; a SubTree reference is one node, its tree is counted once where it is defined).
  Active elements = the nodes that execute something the environment sees: Action and Condition
  leaves (internal built-ins such as AlwaysSuccess included; SubTree references are not).
- FSM graphical elements = states at every level (composite states and final/end states
  included) + one start pseudo-state per machine (the top machine and every sub-FSM: each has an
  initial arrow from one) + transitions at every level + one initial arrow per machine.
  Active elements = states with an action (composite states have none).
Depth: BT levels (root = 1, references not expanded); FSM nesting depth (flat = 1).
Complexity: O(N + T), explicit stacks (models may be 100 000 deep).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.model.stats import bt_stats


@dataclass
class Elements:
    """Counts of one model; ``graphical`` and ``active`` are the paper's two size figures."""

    kind: str  # "fsm" or "bt"
    graphical: int
    active: int
    depth: int
    nodes: int = 0  # BT
    edges: int = 0  # BT
    by_type: dict[str, int] = field(default_factory=dict)  # BT node types / FSM state kinds
    states: int = 0  # FSM, every level
    transitions: int = 0  # FSM, every level
    machines: int = 0  # FSM: the top machine + sub-FSMs
    sub_fsms: int = 0  # FSM: composite/parallel regions (machines - 1)
    leaves: int = 0  # BT

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def bt_elements(doc: BTDocument) -> Elements:
    stats = bt_stats(doc)
    edges = sum(max(t.nodes - 1, 0) for t in stats.per_tree)
    return Elements(
        kind="bt",
        graphical=stats.nodes + edges,
        active=stats.actions + stats.conditions,
        depth=stats.depth,
        nodes=stats.nodes,
        edges=edges,
        by_type=dict(stats.by_type),
        leaves=stats.leaves,
    )


def fsm_elements(fsm: FSM) -> Elements:
    states = transitions = active = machines = 0
    depth = 0
    kinds: dict[str, int] = {}
    stack: list[tuple[FSM, int]] = [(fsm, 1)]
    while stack:
        machine, level = stack.pop()
        machines += 1
        depth = max(depth, level)
        transitions += len(machine.transitions)
        for state in machine.states.values():
            states += 1
            active += state.action is not None and not state.regions
            kind = (
                "parallel"
                if state.is_parallel
                else "composite"
                if state.is_composite
                else "final"
                if state.final
                else "atomic"
            )
            kinds[kind] = kinds.get(kind, 0) + 1
            stack.extend((region, level + 1) for region in state.regions)
    graphical = states + machines + transitions + machines  # + start markers + initial arrows
    return Elements(
        kind="fsm",
        graphical=graphical,
        active=active,
        depth=depth,
        by_type=dict(sorted(kinds.items())),
        states=states,
        transitions=transitions,
        machines=machines,
        sub_fsms=machines - 1,
    )


def elements(model: FSM | BTDocument) -> Elements:
    return fsm_elements(model) if isinstance(model, FSM) else bt_elements(model)
