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

from fsmbt.model.fsm import State

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


def _json(state: State, key: str) -> object:
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


def input_keys(state: State) -> list[str]:
    """The userdata keys the state reads."""
    value = _json(state, INPUT_KEYS)
    return [str(v) for v in value] if isinstance(value, list) else []


def output_keys(state: State) -> list[str]:
    """The userdata keys the state writes."""
    value = _json(state, OUTPUT_KEYS)
    return [str(v) for v in value] if isinstance(value, list) else []


def remapping(state: State) -> dict[str, str]:
    """The state's userdata key -> the container's key."""
    value = _json(state, REMAPPING)
    if isinstance(value, dict):
        return {str(k): str(v) for k, v in value.items()}
    return {}


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
) -> dict[str, str]:
    """The ``State.attrs`` entries for what a reader found (fields left ``None`` are omitted)."""
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
    return attrs
