"""Pieces both baselines share: the state-variable leaves' node models, reachable FSM states,
and the flat one-state-per-leaf reading of a BT's Sequence/Fallback rules."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from fsmbt.model.bt import BTNode, NodeModel, PortModel
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten, needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.semantics import state_variable_runtime as sv
from fsmbt.semantics.lebt.spec import NO_EVENT
from fsmbt.semantics.nodes import (
    PLAIN_CONTROLS,
    REACTIVE_CONTROLS,
    RESULT_MAP_DECORATORS,
)
from fsmbt.semantics.status import LeafOutcome, RootResult

#: End-state names (``RootResult``) and leaf-outcome events (``LeafOutcome``), as plain str.
SUCCESS, FAILURE = RootResult.SUCCESS.value, RootResult.FAILURE.value
EV_SUCCESS, EV_FAILURE, EV_RUNNING = (
    LeafOutcome.SUCCESS.value,
    LeafOutcome.FAILURE.value,
    LeafOutcome.RUNNING.value,
)


def sv_node_models(types: tuple[str, ...]) -> dict[str, NodeModel]:
    """``TreeNodesModel`` entries for the state-variable leaves a baseline writes (Groot2)."""
    ports = {
        sv.IS_STATE: ["state", "initial"],
        sv.ENTRY_ACTION: ["state", "action"],
        sv.TRANSITION: ["state", "transitions", "final"],
        sv.GUARD: ["state", "event", "initial"],
        sv.ASSIGN: ["target"],
        sv.MODE: ["state", "action", "final"],
    }
    return {
        t: NodeModel(
            t,
            NodeKind.CONDITION if t in sv.CONDITION_TYPES else NodeKind.ACTION,
            [PortModel(p, "input") for p in ports[t]],
        )
        for t in types
    }


def prepare_fsm(fsm: FSM) -> tuple[FSM, list[str], list[str]]:
    """Flatten if hierarchical; return the flat FSM, its reachable states in declaration order
    and warnings. Transitions out of final states never fire and are ignored by the callers."""
    warnings: list[str] = []
    flat = fsm
    if needs_flattening(fsm):
        flat = flatten(fsm)
        warnings.append(f"hierarchical FSM flattened to {len(flat.states)} states")
    if flat.initial is None or flat.initial not in flat.states:
        raise InputError("the state machine has no initial state", element=fsm.name)
    start = flat.start_name
    if start is not None and start in flat.states:
        raise UnsupportedError(
            f"a state is named like the start pseudo-state '{start}'", element=start
        )
    table = flat.transition_map()
    seen = {flat.initial}
    queue = deque([flat.initial])
    while queue:
        name = queue.popleft()
        if flat.states[name].final:
            continue
        for event, t in table.get(name, {}).items():
            if event is None:
                raise InputError("eventless transition in a flat FSM", element=name)
            if event == NO_EVENT:
                raise UnsupportedError(
                    "an empty event name cannot be told from 'no event'", element=name
                )
            if t.target not in flat.states:
                raise InputError(f"transition to unknown state '{t.target}'", element=name)
            if t.target not in seen:
                seen.add(t.target)
                queue.append(t.target)
    reachable = [name for name in flat.states if name in seen]
    dropped = len(flat.states) - len(reachable)
    if dropped:
        warnings.append(f"dropped {dropped} unreachable state(s)")
    return flat, reachable, warnings


def exits_of(flat: FSM, state: str) -> list[tuple[str, str]]:
    """``(event, target)`` of the transitions that can fire from ``state`` (first one wins)."""
    if flat.states[state].final:
        return []
    return [(str(event), t.target) for event, t in flat.transition_map().get(state, {}).items()]


def leaf_node(type_name: str, name: str, **attrs: str) -> BTNode:
    kind = NodeKind.CONDITION if type_name in sv.CONDITION_TYPES else NodeKind.ACTION
    return BTNode(type=type_name, kind=kind, name=name, attrs=dict(attrs))


def control(type_name: str, name: str, children: list[BTNode]) -> BTNode:
    return BTNode(type=type_name, kind=NodeKind.CONTROL, name=name, children=children)


@dataclass
class Cont:
    """Where a node's outcomes lead: the entry state (name) for success / failure / running."""

    success: str
    failure: str


def check_baseline_node(node: BTNode) -> None:
    """Refuse the node types the classical mappings do not describe (named, with location)."""
    if node.is_leaf:
        if node.is_builtin:
            raise UnsupportedError(
                f"built-in leaf {node.type} has no classical mapping",
                location=node.location,
                element=node.label,
            )
        return
    if node.kind is NodeKind.CONTROL and node.type in PLAIN_CONTROLS | REACTIVE_CONTROLS:
        if not node.children:
            raise InputError(
                f"{node.type} has no children", location=node.location, element=node.label
            )
        return
    if node.kind is NodeKind.DECORATOR and node.type in RESULT_MAP_DECORATORS:
        return
    raise UnsupportedError(
        f"{node.type}: the classical baselines map Sequence, Fallback, their Reactive "
        "variants, Inverter, ForceSuccess, ForceFailure and leaves only",
        location=node.location,
        element=node.label,
    )
