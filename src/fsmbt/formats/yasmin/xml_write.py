"""FSM -> YASMIN factory XML (docs/formats/yasmin.md, 'Writing').

Mapping (the inverse of the reader, so that what is written reads back as the same FSM):
- the machine is the root ``<StateMachine outcomes start_state>``; its final states are its
  outcomes (``<FinalOutcome>``); every other atomic state is a ``<State>`` whose class is its
  declared class (``state_info``) or else its action, with ``type``/``module`` as read (a Python
  state with no module gets ``module="fsmbt_states"``: the classes are the user's to write); a
  state that runs no action gets the C++ class ``fsmbt_states/NoAction``, which the reader takes
  back as no action;
- an event ``s --e--> t`` is ``<Transition from="e" to="t"/>`` of ``s``: in YASMIN a state
  returns one of its outcomes, and the outcome picks the next state;
- a composite state whose transitions are all completion transitions naming their exit is a
  nested ``<StateMachine>`` whose outcomes are its final states, each exit a ``<Transition>``;
- a composite read from a YASMIN ``Concurrence`` / ``OrthogonalState`` is written back as that
  container with its outcome map: leaf children as ``<State>``, container children (recorded
  with their machines, ``pysm.build.A_NESTED``) as ``<StateMachine>`` / ``<Region>``, while
  its product machine is the one read (``product_fingerprint``); else as the StateMachine of
  the product, the container named as a loss;
- a start pseudo-state left on an initial event is a state of class ``fsmbt_states/Start``
  whose one transition is that event (read back as the start pseudo-state);
- parameters, keys, remappings, positions and descriptions kept in ``State.attrs`` (by the
  YASMIN reader or another outcome-driven reader through ``model.state_info``) become ``Param``,
  ``Key``, ``Remap``, ``ParamRemap``, ``x``/``y`` and ``description``; a machine read from an
  included file is written inline (its states are in the model; the include is a named loss).
A final state's action is written as ``fsmbt_action`` on its ``<FinalOutcome>`` (YASMIN ignores
it and runs nothing there: ``yasmin_losses`` names it).
Refused (``UnsupportedError``, so ``translate --flatten`` can write the flat machine): a
parallel state that was not read from a YASMIN container, a composite left on an event or by a
completion transition without an exit, an eventless transition of an atomic state, a final
state with outgoing transitions, a state named like an outcome of its machine. Everything else
that differs when the text is read back (an action that is not a class,
...) is named as a loss by ``translate``. Explicit work list. Costs: O(S + T).
"""

from __future__ import annotations

import json
from typing import Any

from lxml import etree

from fsmbt.formats.pysm.build import (
    A_CHILDREN,
    A_DEFAULT,
    A_MAP,
    A_NESTED,
    product_fingerprint,
)
from fsmbt.formats.yasmin.xml_read import (
    A_CHILD_INFO,
    A_DESCRIPTION,
    A_FINAL_ACTION,
    A_KEYS,
    A_MODULE,
    A_PARAM_DECLS,
    A_PARAM_REMAP,
    A_POSITION,
    A_SYNC,
    A_TAG,
    A_TYPE,
    NO_ACTION_CLASS,
    START_CLASS,
)
from fsmbt.model import Model, state_info
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.serialize import fsm_from_dict

#: The module written for Python states whose module is not known.
DEFAULT_MODULE = "fsmbt_states"


def yasmin_losses(model: Model) -> list[str]:
    """What the YASMIN program itself cannot do that fsmbt keeps for its own reading."""
    if not isinstance(model, FSM):
        return []
    finals = [
        f"{machine.name}/{state.name}"
        for machine in model.machines()
        for state in machine.states.values()
        if state.final and state.action is not None
    ]
    if not finals:
        return []
    return [
        f"{len(finals)} final state(s) run an action ({', '.join(finals[:5])}"
        + (" ..." if len(finals) > 5 else "")
        + "): YASMIN runs none on reaching an outcome; kept as fsmbt_action on <FinalOutcome>, "
        "which YASMIN ignores"
    ]


def write_yasmin(model: Model) -> str:
    """The YASMIN XML of ``model`` (see the module docstring)."""
    if not isinstance(model, FSM):
        raise UnsupportedError("YASMIN holds state machines, not behavior trees")
    if model.initial is None:
        raise UnsupportedError("the machine has no initial state")
    root = etree.Element("StateMachine")
    root.set("name", model.name)
    work: list[tuple[FSM, etree._Element, dict[str, str]]] = [(model, root, model.attrs)]
    while work:
        machine, element, attrs = work.pop()
        work.extend(_machine(machine, element, attrs))
    etree.indent(root, space="  ")
    text: str = etree.tostring(root, xml_declaration=True, encoding="UTF-8").decode("utf-8")
    return text + "\n"


def _outcome_list(outcomes: list[str], where: str) -> str:
    """YASMIN's ``outcomes`` attribute: the names separated by blanks, so a name holding a
    blank cannot be written (it would read back as several outcomes)."""
    for outcome in outcomes:
        if not outcome or any(c.isspace() for c in outcome):
            raise UnsupportedError(
                f"{where}: outcome {outcome!r} holds a blank; YASMIN's outcomes attribute "
                "separates names by blanks"
            )
    return " ".join(outcomes)


def _machine(
    machine: FSM, element: etree._Element, attrs: dict[str, str]
) -> list[tuple[FSM, etree._Element, dict[str, str]]]:
    finals = [s.name for s in machine.states.values() if s.final]
    if not finals:
        raise UnsupportedError(
            f"machine '{machine.name}' has no final state: a YASMIN state machine ends with "
            "one of its outcomes"
        )
    if machine.initial is None or machine.states[machine.initial].final:
        raise UnsupportedError(
            f"machine '{machine.name}' starts in a final state; YASMIN starts in a state"
        )
    element.set("outcomes", _outcome_list(finals, f"machine '{machine.name}'"))
    element.set("start_state", machine.initial)
    _annotate(element, attrs)
    pending: list[tuple[FSM, etree._Element, dict[str, str]]] = []
    if machine.start_name is not None and machine.initial_event is not None:
        if machine.start_name in machine.states:
            raise UnsupportedError(f"start pseudo-state '{machine.start_name}' is also a state")
        start = etree.SubElement(element, "State")
        start.set("name", machine.start_name)
        start.set("type", "cpp")
        start.set("class", START_CLASS)
        leave = etree.SubElement(start, "Transition")
        leave.set("from", machine.initial_event)
        leave.set("to", machine.initial)
        element.set("start_state", machine.start_name)
    for state in machine.states.values():
        if state.final:
            if machine.outgoing(state.name):
                raise UnsupportedError(
                    f"final state '{state.name}' of '{machine.name}' has outgoing transitions"
                )
            continue
        if state.name in finals:
            raise UnsupportedError(f"state '{state.name}' is named like an outcome")
        pending.extend(_state(machine, state, element))
    for name in finals:
        final = etree.SubElement(element, "FinalOutcome")
        final.set("name", name)
        final_attrs = machine.states[name].attrs
        action = machine.states[name].action
        if action is not None:
            final.set(A_FINAL_ACTION, action)
        if final_attrs.get(A_DESCRIPTION):
            final.set("description", final_attrs[A_DESCRIPTION])
        _position(final, final_attrs)
    for transition in element.findall("Transition"):  # this machine's own exits, last
        element.remove(transition)
        element.append(transition)
    return pending


def _state(
    machine: FSM, state: State, parent: etree._Element
) -> list[tuple[FSM, etree._Element, dict[str, str]]]:
    if state.is_parallel:
        raise UnsupportedError(
            f"parallel state '{state.name}': YASMIN's Concurrence runs children that end "
            "independently and waits for all, which regions sharing events are not"
        )
    if state.is_composite:
        region = state.regions[0]
        tag = state.attrs.get(A_TAG)
        if tag in ("Concurrence", "OrthogonalState") and state.attrs.get(A_MAP) is not None:
            element = _concurrence(state, parent, tag)
            _transitions(machine, state, element, completion=True)
            return []
        nested = _nested_spec(state) if tag in ("Concurrence", "OrthogonalState") else None
        if tag is not None and nested is not None:
            element, children = _nested_concurrence(state, nested, parent, tag)
            _transitions(machine, state, element, completion=True)
            return children
        element = etree.SubElement(parent, "StateMachine")
        element.set("name", state.name)
        _transitions(machine, state, element, completion=True)
        return [(region, element, state.attrs)]
    element = etree.SubElement(
        parent, "JoinState" if state.attrs.get(A_TAG) == "JoinState" else "State"
    )
    element.set("name", state.name)
    if element.tag == "JoinState":
        element.set("sync_id", state.attrs.get(A_SYNC, ""))
        outcomes = state_info.declared_outcomes(state) or ["joined"]
        element.set("outcome", outcomes[0])
    elif state.action is None:
        element.set("type", "cpp")
        element.set("class", NO_ACTION_CLASS)
    else:
        kind = state.attrs.get(A_TYPE, "py")
        element.set("type", kind)
        if kind == "py":
            element.set("module", state.attrs.get(A_MODULE, DEFAULT_MODULE))
        element.set("class", state.action)
    _annotate(element, state.attrs)
    _transitions(machine, state, element, completion=False)
    return []


def _transitions(machine: FSM, state: State, element: etree._Element, *, completion: bool) -> None:
    for t in machine.outgoing(state.name):
        if completion:
            if t.event is not None or t.exit is None:
                raise UnsupportedError(
                    f"composite state '{state.name}' is left "
                    + (f"on event '{t.event}'" if t.event is not None else "by any final state")
                    + ": a YASMIN state machine is left only by one of its outcomes"
                )
            outcome = t.exit
        else:
            if t.event is None:
                raise UnsupportedError(
                    f"state '{state.name}' has an eventless transition; a YASMIN state "
                    "returns an outcome"
                )
            outcome = t.event
        transition = etree.SubElement(element, "Transition")
        transition.set("from", outcome)
        transition.set("to", t.target)


def _concurrence(state: State, parent: etree._Element, tag: str) -> etree._Element:
    default = state.attrs.get(A_DEFAULT)
    outcome_map = json.loads(state.attrs[A_MAP])
    element, outcomes = _concurrence_element(
        state, parent, tag, default, outcome_map, f"Concurrence '{state.name}'"
    )
    children = json.loads(state.attrs.get(A_CHILDREN, "[]"))
    infos = json.loads(state.attrs.get(A_CHILD_INFO, "{}"))
    for label, cls, _outcomes in children:
        info = infos.get(label, {})
        if info.get(A_TAG) == "JoinState":
            child = etree.SubElement(element, "JoinState")
            child.set("name", label)
            _annotate(child, info)
        else:
            _leaf_child(element, label, cls, info)
    _finals_and_map(element, outcomes, outcome_map)
    return element


def _concurrence_element(
    state: State,
    parent: etree._Element,
    tag: str,
    default: str | None,
    outcome_map: list[Any],
    where: str,
) -> tuple[etree._Element, list[str]]:
    """The concurrence's element with its name, outcomes (the default first, then the map's),
    default outcome and annotations; and those outcomes."""
    element = etree.SubElement(parent, tag)
    element.set("name", state.name)
    outcomes = list(dict.fromkeys([*([default] if default else []), *(o for o, _ in outcome_map)]))
    element.set("outcomes", _outcome_list(sorted(outcomes), where))
    if default:
        element.set("default_outcome", default)
    _annotate(element, state.attrs)
    return element, outcomes


def _leaf_child(element: etree._Element, label: str, cls: str, info: dict[str, str]) -> None:
    """A leaf child ``<State>`` of a concurrence: its type, module and class, annotated."""
    child = etree.SubElement(element, "State")
    child.set("name", label)
    kind = info.get(A_TYPE, "py")
    child.set("type", kind)
    if kind == "py":
        child.set("module", info.get(A_MODULE, DEFAULT_MODULE))
    child.set("class", info.get(state_info.CLASS, cls))
    _annotate(child, info)


def _finals_and_map(element: etree._Element, outcomes: list[str], outcome_map: list[Any]) -> None:
    """A concurrence's ``<FinalOutcome>`` per outcome, then its ``<OutcomeMap>`` entries."""
    for outcome in outcomes:
        final = etree.SubElement(element, "FinalOutcome")
        final.set("name", outcome)
    for outcome, required in outcome_map:
        entry = etree.SubElement(element, "OutcomeMap")
        entry.set("outcome", outcome)
        for label, child_outcome in required.items():
            item = etree.SubElement(entry, "Item")
            item.set("state", label)
            item.set("outcome", child_outcome)


def _nested_spec(state: State) -> dict[str, Any] | None:
    """The concurrence with container children the reader recorded on ``state``, while its
    product machine is the one read; else None."""
    if A_NESTED not in state.attrs or not state.regions:
        return None
    spec: dict[str, Any] = json.loads(state.attrs[A_NESTED])
    if spec.get("product") != product_fingerprint(state.regions[0]):
        return None
    return spec


def _nested_concurrence(
    state: State, spec: dict[str, Any], parent: etree._Element, tag: str
) -> tuple[etree._Element, list[tuple[FSM, etree._Element, dict[str, str]]]]:
    """A Concurrence / OrthogonalState with container children, and its children's machines
    to write (``<Region>`` in an OrthogonalState, ``<StateMachine>`` in a Concurrence)."""
    default = spec.get("default")
    outcome_map = spec["outcome_map"]
    element, outcomes = _concurrence_element(
        state, parent, tag, default, outcome_map, f"{tag} '{state.name}'"
    )
    infos = json.loads(state.attrs.get(A_CHILD_INFO, "{}"))
    pending: list[tuple[FSM, etree._Element, dict[str, str]]] = []
    for label, cls, _outcomes in spec["children"]:
        info = infos.get(label, {})
        if label in spec["machines"]:
            child_tag = "Region" if tag == "OrthogonalState" else "StateMachine"
            child = etree.SubElement(element, child_tag)
            child.set("name", label)
            machine = fsm_from_dict(spec["machines"][label], where=f"child '{label}'")
            pending.append((machine, child, {**info, **machine.attrs}))
            continue
        _leaf_child(element, label, cls, info)
    _finals_and_map(element, outcomes, outcome_map)
    return element, pending


def _annotate(element: etree._Element, attrs: dict[str, str]) -> None:
    """``description``, ``x``/``y``, and the Param / Key / ParamRemap / Remap children."""
    if attrs.get(A_DESCRIPTION):
        element.set("description", attrs[A_DESCRIPTION])
    _position(element, attrs)
    declared = json.loads(attrs[A_PARAM_DECLS]) if A_PARAM_DECLS in attrs else None
    param_remap = json.loads(attrs[A_PARAM_REMAP]) if A_PARAM_REMAP in attrs else None
    probe = State("_", attrs=attrs)
    if declared is None:  # another reader's parameters: literal ones become Param defaults
        expression = set(state_info.expression_parameters(probe))
        params = state_info.parameters(probe)
        declared = [
            {"name": k, "default_type": "str", "default_value": v}
            for k, v in params.items()
            if k not in expression
        ]
        if param_remap is None:
            param_remap = {k: v for k, v in params.items() if k in expression}
    for declaration in declared:
        param = etree.SubElement(element, "Param")
        for key in ("name", "description", "default_type", "default_value"):
            if declaration.get(key) is not None:
                param.set(key, str(declaration[key]))
    keys = json.loads(attrs[A_KEYS]) if A_KEYS in attrs else None
    if keys is None:
        inputs, outputs = state_info.input_keys(probe), state_info.output_keys(probe)
        keys = [{"name": k, "type": "in/out" if k in outputs else "in"} for k in inputs] + [
            {"name": k, "type": "out"} for k in outputs if k not in inputs
        ]
    for declaration in keys:
        key_element = etree.SubElement(element, "Key")
        for name in ("name", "type", "description", "default_type", "default_value"):
            if declaration.get(name) is not None:
                key_element.set(name, str(declaration[name]))
    for old, new in (param_remap or {}).items():
        remap = etree.SubElement(element, "ParamRemap")
        remap.set("old", old)
        remap.set("new", new)
    for old, new in state_info.remapping(probe).items():
        remap = etree.SubElement(element, "Remap")
        remap.set("old", old)
        remap.set("new", new)


def _position(element: etree._Element, attrs: dict[str, str]) -> None:
    position = attrs.get(A_POSITION, "").split()
    if len(position) == 2:
        element.set("x", position[0])
        element.set("y", position[1])
