"""YASMIN container records -> fsmbt's hierarchical FSM, with each state's declarations.

The shape is the SMACH reader's (``pysm.build.build_records``: one state per state, events are
outcomes, containers are composite states left by completion transitions ``exit=<outcome>``,
one final state per container outcome, a concurrence or orthogonal state as the product of its
children). This module then stores what each state was declared with (``model.state_info``:
class, outcomes, parameters, keys, remapping; ``yasmin.*``: type, module, position, ...) on the
state it became: a leaf or a container child on its own state, the leaves of a concurrence (whose
states are product states) as one JSON object on the concurrence's state. Explicit work list.
Costs: O(states).
"""

from __future__ import annotations

import json

from fsmbt.formats.pysm.analyze import Analysis, Container
from fsmbt.formats.pysm.build import A_NESTED, build_records
from fsmbt.formats.registry import ReadContext
from fsmbt.formats.yasmin.xml_read import A_CHILD_INFO, NO_ACTION_CLASS, START_CLASS, Records
from fsmbt.model.fsm import FSM, State
from fsmbt.model.serialize import fsm_from_dict, fsm_to_dict


def build(records: Records, ctx: ReadContext) -> FSM:
    """The FSM of one YASMIN document's records (see the module docstring)."""
    analysis = Analysis([records.root], {}, {}, records.warnings)
    fsm = build_records(records.root, records.name, ctx, analysis)
    fsm.attrs.update(records.root_info)
    _attach(fsm, records.root, records)
    return fsm


def _attach(fsm: FSM, root: Container, records: Records) -> None:
    work: list[tuple[FSM, Container]] = [(fsm, root)]
    while work:
        machine, container = work.pop()
        _start_state(machine)
        for outcome, action in records.final_actions.get(id(container), {}).items():
            if outcome in machine.states:
                machine.states[outcome].action = action
        for child in container.children:
            state = machine.states.get(child.label)
            if state is None:
                continue
            state.attrs.update(records.info.get(id(child), {}))
            if state.action == NO_ACTION_CLASS:
                state.action = None  # what fsmbt writes for a state that runs nothing
            inner = child.state
            if not isinstance(inner, Container) or not state.regions:
                continue
            if inner.kind == "concurrence":
                # its states are combinations of its children: their declarations go here
                infos = {c.label: records.info.get(id(c), {}) for c in inner.children}
                state.attrs[A_CHILD_INFO] = json.dumps(infos, sort_keys=True)
                _attach_nested(state, inner, records)
            else:
                work.append((state.regions[0], inner))


def _start_state(machine: FSM) -> None:
    """fsmbt's start pseudo-state, written as a state of class ``fsmbt_states/Start`` with one
    transition (its initial event), becomes the start pseudo-state again."""
    start = machine.states.get(str(machine.initial))
    if start is None or start.action != START_CLASS or start.regions:
        return
    leaving = machine.outgoing(start.name)
    if len(leaving) != 1 or leaving[0].event is None:
        return
    machine.start_name, machine.initial_event = start.name, leaving[0].event
    machine.initial = leaving[0].target
    machine.transitions.remove(leaving[0])
    del machine.states[start.name]


def _attach_nested(state: State, concurrence: Container, records: Records) -> None:
    """The declarations of a concurrence's container children (an OrthogonalState's regions)
    go on the states of the machines the reader recorded for them (``A_NESTED``), so they
    travel into the structured tree's leaves. Each child machine once: O(its states)."""
    if A_NESTED not in state.attrs:
        return
    spec = json.loads(state.attrs[A_NESTED])
    for child in concurrence.children:
        if not isinstance(child.state, Container) or child.label not in spec["machines"]:
            continue
        machine = fsm_from_dict(spec["machines"][child.label])
        _attach(machine, child.state, records)
        spec["machines"][child.label] = fsm_to_dict(machine)
    state.attrs[A_NESTED] = json.dumps(spec)
