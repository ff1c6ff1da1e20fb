"""What an outcome-driven state was declared with: the one contract between readers and writers.

SMACH, FlexBE and YASMIN states are objects of a class, built with parameters, that run and
return one of their declared outcomes, reading and writing userdata keys that the container may
remap. The readers (``formats``) store that in ``State.attrs`` under the keys below; the
converters and writers (the structured FSM -> BT conversion, ``translate``, the runtimes) read it
back through the accessors here, never by spelling the keys themselves. A reader that knows
nothing of a field leaves it out: every accessor has an "unknown" answer.

Values are JSON text (``State.attrs`` is ``dict[str, str]`` so that every format can round-trip
it). Parameter values are kept as the *literal text* the user wrote, rendered for a port: a
Python string literal becomes its value, a number or a boolean its JSON spelling (``true``), any
other literal (a list, a dict, a tuple) its JSON form; an expression that is not a literal
(a variable, a call) is kept as its source text and marked by ``expression_parameters``.

Cost: every accessor parses one small JSON value, O(size of that value).
"""

from __future__ import annotations

import json
from collections.abc import Mapping

from fsmbt.model.fsm import FSM, State

#: The state's class, i.e. its action type (``DetectObject``; ``SimpleActionState``...).
CLASS = "class"
#: JSON list of the outcomes the state declares, in declaration order.
OUTCOMES = "outcomes"
#: JSON object: parameter name -> literal value text (positional ones are ``arg0``, ``arg1``...).
PARAMETERS = "params"
#: JSON list of parameter names whose value is an expression, not a literal (kept as source).
EXPRESSION_PARAMETERS = "params.expr"
#: JSON list of userdata keys the state reads (``input_keys``).
INPUT_KEYS = "userdata.in"
#: JSON list of userdata keys the state writes (``output_keys``).
OUTPUT_KEYS = "userdata.out"
#: JSON object: the state's key -> the container's key (``remapping=``).
REMAPPING = "remapping"
#: For generic ROS states (SMACH ``SimpleActionState``/``ServiceState``, FlexBE's action and
#: service states): the ROS interface type (``move_base_msgs/MoveBaseAction``), when known.
ROS_INTERFACE = "ros.interface"
#: ``action`` or ``service``, beside ``ROS_INTERFACE``.
ROS_KIND = "ros.kind"
#: The ROS action or service name the state talks to (``/move_base``), when literal.
ROS_NAME = "ros.name"
#: JSON object on a composite state (or, for the top machine, ``FSM.attrs``): userdata key ->
#: the literal text of the value the container sets before it runs (``sm.userdata.home = ...``).
USERDATA = "userdata.values"
#: JSON ``[x, y]``: where the FlexBE editor draws the state (``# x:120 y:40`` above its ``add``).
POSITION = "position"
#: JSON object on a concurrency composite: child label -> that leaf child's own entries (the
#: children of a concurrence are not states of the model, which holds their product).
CHILD_STATES = "children.states"

#: Every key above: the annotations a reader of outcome-driven states adds to ``attrs``
#: (writers that have no place for them name them as losses, docs/cli.md "translate").
KEYS = (
    CLASS,
    OUTCOMES,
    PARAMETERS,
    EXPRESSION_PARAMETERS,
    INPUT_KEYS,
    OUTPUT_KEYS,
    REMAPPING,
    ROS_INTERFACE,
    ROS_KIND,
    ROS_NAME,
    USERDATA,
    POSITION,
    CHILD_STATES,
)
#: What each key is, in words, for loss messages.
DESCRIPTIONS = {
    CLASS: "state class",
    OUTCOMES: "declared outcomes",
    PARAMETERS: "parameters",
    EXPRESSION_PARAMETERS: "expression parameters",
    INPUT_KEYS: "input userdata keys",
    OUTPUT_KEYS: "output userdata keys",
    REMAPPING: "userdata remappings",
    ROS_INTERFACE: "ROS interface types",
    ROS_KIND: "ROS interface kinds",
    ROS_NAME: "ROS interface names",
    USERDATA: "userdata initial values",
    POSITION: "editor positions",
    CHILD_STATES: "concurrent children's configuration",
}


def _json(state: State | FSM, key: str) -> object:
    text = state.attrs.get(key)
    if text is None:
        return None
    try:
        return json.loads(text)
    except ValueError:
        return None


def state_class(state: State) -> str | None:
    """The state's class (action type), or ``None`` when the reader did not know it."""
    return state.attrs.get(CLASS) or state.action


def declared_outcomes(state: State) -> list[str] | None:
    """The outcomes the state declares, in order; ``None`` when unknown."""
    value = _json(state, OUTCOMES)
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        return list(value)
    return None


def parameters(state: State) -> dict[str, str]:
    """Parameter name -> literal value text (empty when none or unknown)."""
    value = _json(state, PARAMETERS)
    if isinstance(value, dict):
        return {str(k): str(v) for k, v in value.items()}
    return {}


def expression_parameters(state: State) -> list[str]:
    """The parameter names whose value is an expression kept as source text."""
    value = _json(state, EXPRESSION_PARAMETERS)
    return [str(v) for v in value] if isinstance(value, list) else []


def input_keys(state: State | FSM) -> list[str]:
    """The userdata keys the state reads."""
    value = _json(state, INPUT_KEYS)
    return [str(v) for v in value] if isinstance(value, list) else []


def output_keys(state: State | FSM) -> list[str]:
    """The userdata keys the state writes."""
    value = _json(state, OUTPUT_KEYS)
    return [str(v) for v in value] if isinstance(value, list) else []


def remapping(state: State) -> dict[str, str]:
    """The state's userdata key -> the container's key."""
    value = _json(state, REMAPPING)
    if isinstance(value, dict):
        return {str(k): str(v) for k, v in value.items()}
    return {}


def userdata_values(holder: State | FSM) -> dict[str, str]:
    """Userdata key -> initial value text a container sets (a composite state or the top FSM)."""
    value = _json(holder, USERDATA)
    if isinstance(value, dict):
        return {str(k): str(v) for k, v in value.items()}
    return {}


def position(state: State) -> tuple[int, int] | None:
    """Where the FlexBE editor drew the state, or ``None``."""
    value = _json(state, POSITION)
    if (
        isinstance(value, list)
        and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) for v in value)
    ):
        return value[0], value[1]
    return None


def child_states(state: State) -> dict[str, dict[str, str]]:
    """A concurrency composite's leaf children: label -> their own ``attrs`` entries."""
    value = _json(state, CHILD_STATES)
    if not isinstance(value, dict):
        return {}
    return {
        str(label): {str(k): str(v) for k, v in entries.items()}
        for label, entries in value.items()
        if isinstance(entries, dict)
    }


def ros_interface(state: State) -> tuple[str, str, str | None] | None:
    """``(kind, interface type, name)`` of a generic ROS state, or ``None``."""
    kind = state.attrs.get(ROS_KIND)
    interface = state.attrs.get(ROS_INTERFACE)
    if kind is None or interface is None:
        return None
    return kind, interface, state.attrs.get(ROS_NAME)


def encode(
    *,
    outcomes: list[str] | None = None,
    params: Mapping[str, str] | None = None,
    expression_params: list[str] | None = None,
    inputs: list[str] | None = None,
    outputs: list[str] | None = None,
    remap: Mapping[str, str] | None = None,
    userdata: Mapping[str, str] | None = None,
    at: tuple[int, int] | None = None,
    ros: tuple[str, str, str | None] | None = None,
) -> dict[str, str]:
    """The ``State.attrs`` entries for what a reader found (fields left ``None`` are omitted).

    ``ros`` is ``(kind, interface type, name or None)``; ``at`` the editor position."""
    attrs: dict[str, str] = {}
    if outcomes is not None:
        attrs[OUTCOMES] = json.dumps(list(outcomes))
    if params:
        attrs[PARAMETERS] = json.dumps(dict(params))
    if expression_params:
        attrs[EXPRESSION_PARAMETERS] = json.dumps(list(expression_params))
    if inputs:
        attrs[INPUT_KEYS] = json.dumps(list(inputs))
    if outputs:
        attrs[OUTPUT_KEYS] = json.dumps(list(outputs))
    if remap:
        attrs[REMAPPING] = json.dumps(dict(remap))
    if userdata:
        attrs[USERDATA] = json.dumps(dict(userdata))
    if at is not None:
        attrs[POSITION] = json.dumps([at[0], at[1]])
    if ros is not None:
        attrs[ROS_KIND], attrs[ROS_INTERFACE] = ros[0], ros[1]
        if ros[2] is not None:
            attrs[ROS_NAME] = ros[2]
    return attrs
