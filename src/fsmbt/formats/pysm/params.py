"""What a SMACH / FlexBE state is configured with, read from its constructor call (never run).

A state is ``Class(args...)`` added to a container: its constructor arguments are the state's
parameters (FlexBE ``LogState(text='hi')``, ``TimedCmdVelState(velocity=0.5)``), its class
declares outcomes and userdata keys in ``__init__`` (``super().__init__(outcomes=[...],
input_keys=[...], output_keys=[...])``), and SMACH's generic ROS states name an action or a
service. This module turns those syntax trees into the strings ``fsmbt.model.state_info``
stores (docs/formats/smach.md, "What a state was configured with").

Rules:
- A parameter's value is its literal text rendered for a port: a string is its value, a
  number, boolean or ``None`` its JSON spelling, a list / tuple / dict of literals its JSON
  form; a name bound earlier to such a literal is that literal. Anything else - a variable,
  an attribute (``Logger.REPORT_HINT``, ``self.waiting_time``), a call, a lambda - is kept as
  its source text and listed as an expression parameter.
- Positional arguments take the names of the class's ``__init__`` parameters when the class
  is known (in the file or its package), else ``arg0``, ``arg1`` ...; ``*args`` / ``**kw``
  are kept as expression parameters ``*`` / ``**``.
- ``outcomes``, ``input_keys`` and ``output_keys`` given to the constructor are the state's
  declared outcomes and keys, not parameters.
- SMACH ``SimpleActionState`` / ``ServiceState`` (ROS 1 ``(name, spec, ...)``, ROS 2
  ``(node, name, spec, ...)``): kind ``action`` / ``service``, the interface type (the spec's
  import path as ``package/sub/Name``, else its name) and the literal name; ``goal_key``,
  ``goal_slots``, ``request_key``, ``request_slots`` are input keys, ``result_key``,
  ``result_slots``, ``response_key``, ``response_slots`` output keys. The ROS 2 node argument
  is not a parameter.
Costs: O(size of the call) per state.
"""

from __future__ import annotations

import ast
import json
from collections.abc import Callable
from dataclasses import dataclass, field

from fsmbt.formats.pysm.source import NotStatic, dotted_name, literal, source_text

#: Constructor arguments that declare the state's interface rather than configure it.
INTERFACE_ARGUMENTS = frozenset({"outcomes", "input_keys", "output_keys"})

_ACTION_ARGS = (
    "goal",
    "goal_key",
    "goal_slots",
    "goal_cb",
    "goal_cb_args",
    "goal_cb_kwargs",
    "result_key",
    "result_slots",
    "result_cb",
    "result_cb_args",
    "result_cb_kwargs",
    "input_keys",
    "output_keys",
    "outcomes",
)
_SERVICE_ARGS = (
    "request",
    "request_cb",
    "request_cb_args",
    "request_cb_kwargs",
    "request_key",
    "request_slots",
    "response_cb",
    "response_cb_args",
    "response_cb_kwargs",
    "response_key",
    "response_slots",
    "input_keys",
    "output_keys",
    "outcomes",
)
_INPUT_ARGS = frozenset({"goal_key", "goal_slots", "request_key", "request_slots"})
_OUTPUT_ARGS = frozenset({"result_key", "result_slots", "response_key", "response_slots"})
ROS_STATES = {"SimpleActionState": "action", "ServiceState": "service"}


@dataclass
class ClassDecl:
    """What a state class declares in its ``__init__`` (``None``: not found)."""

    outcomes: list[str] | None = None
    inputs: list[str] | None = None
    outputs: list[str] | None = None
    arguments: list[str] = field(default_factory=list)  # __init__'s parameters after self


@dataclass
class Configured:
    """One state's configuration as ``state_info`` stores it."""

    params: dict[str, str] = field(default_factory=dict)
    expressions: list[str] = field(default_factory=list)
    inputs: list[str] | None = None
    outputs: list[str] | None = None
    ros: tuple[str, str, str | None] | None = None


Lookup = Callable[[str], object]


def render(node: ast.expr, text: str, lookup: Lookup | None) -> tuple[str, bool]:
    """``(value text, is an expression)`` of one argument (see the module rules)."""
    if not any(isinstance(n, ast.Attribute) for n in ast.walk(node)):
        try:
            value = literal(node, lookup)
        except NotStatic:
            value = _NOT_LITERAL
        if value is not _NOT_LITERAL:
            if isinstance(value, str):
                return value, False
            try:
                return json.dumps(value), False
            except (TypeError, ValueError):  # a dict with tuple keys, a set ...
                pass
    return source_text(text, node, 400), True


_NOT_LITERAL = object()


def string_list(node: ast.expr | None, lookup: Lookup | None) -> list[str] | None:
    """A literal list of strings (a single string is a list of one), else ``None``."""
    if node is None:
        return None
    try:
        value = literal(node, lookup)
    except NotStatic:
        return None
    if isinstance(value, str):
        return [value]
    if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        return [str(v) for v in value]
    return None


def class_declaration(cls: ast.ClassDef) -> ClassDecl:
    """Outcomes, userdata keys and constructor parameters of a state class (its own
    ``__init__`` and the base ``__init__`` call in it; nothing inherited)."""
    decl = ClassDecl()
    init = next(
        (s for s in cls.body if isinstance(s, ast.FunctionDef) and s.name == "__init__"), None
    )
    if init is None:
        return decl
    names = [a.arg for a in [*init.args.posonlyargs, *init.args.args]]
    decl.arguments = names[1:] if names and names[0] == "self" else names
    for node in ast.walk(init):
        if not (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "__init__"
        ):
            continue
        args = list(node.args)
        if args and isinstance(args[0], ast.Name) and args[0].id == "self":
            args = args[1:]
        given = dict(zip(("outcomes", "input_keys", "output_keys"), args))
        given.update({k.arg: k.value for k in node.keywords if k.arg is not None})
        decl.outcomes = string_list(given.get("outcomes"), None)
        decl.inputs = string_list(given.get("input_keys"), None)
        decl.outputs = string_list(given.get("output_keys"), None)
        break
    return decl


def configure(
    call: ast.Call,
    original: str,
    text: str,
    lookup: Lookup | None,
    argument_names: list[str] | None,
    imports: dict[str, str],
) -> Configured:
    """The parameters, keys and ROS interface of the state made by ``call``.

    Args:
        call: the constructor call.
        original: the state's class name (import aliases resolved).
        text: the source the call was parsed from (for expression text).
        lookup: resolves names bound to literals.
        argument_names: the class's ``__init__`` parameters, when known.
        imports: local name -> dotted import path (for ROS interface types).
    """
    out = Configured()
    positional = list(call.args)
    names = list(argument_names or [])
    kind = ROS_STATES.get(original)
    if kind is not None:
        ros_names = _ACTION_ARGS if kind == "action" else _SERVICE_ARGS
        offset = _ros_offset(positional, lookup)
        interface = positional[offset + 1] if len(positional) > offset + 1 else None
        name_node = positional[offset] if len(positional) > offset else None
        for keyword in call.keywords:
            if keyword.arg in ("action_name", "service_name"):
                name_node = keyword.value
            elif keyword.arg in ("action_spec", "service_spec"):
                interface = keyword.value
        if interface is not None:
            out.ros = (
                kind,
                _interface_type(interface, text, imports),
                _literal_str(name_node, lookup),
            )
        positional = positional[offset + 2 :]
        names = list(ros_names)
    bound: list[tuple[str, ast.expr]] = []
    for index, arg in enumerate(positional):
        if isinstance(arg, ast.Starred):
            bound.append(("*", arg.value))
            continue
        bound.append((names[index] if index < len(names) else f"arg{index}", arg))
    for keyword in call.keywords:
        if kind is not None and keyword.arg in (
            "action_name",
            "service_name",
            "action_spec",
            "service_spec",
        ):
            continue
        bound.append((keyword.arg or "**", keyword.value))
    inputs: list[str] = []
    outputs: list[str] = []
    for name, node in bound:
        if name == "input_keys" or name in _INPUT_ARGS:
            inputs.extend(string_list(node, lookup) or [])
            if name == "input_keys":
                continue
        if name == "output_keys" or name in _OUTPUT_ARGS:
            outputs.extend(string_list(node, lookup) or [])
            if name == "output_keys":
                continue
        if name in INTERFACE_ARGUMENTS:
            continue
        value, expression = render(node, text, lookup)
        out.params[name] = value
        if expression:
            out.expressions.append(name)
    if inputs:
        out.inputs = list(dict.fromkeys(inputs))
    if outputs:
        out.outputs = list(dict.fromkeys(outputs))
    return out


def _ros_offset(positional: list[ast.expr], lookup: Lookup | None) -> int:
    """0 for ROS 1's ``(name, spec, ...)``, 1 for ROS 2's ``(node, name, spec, ...)``."""
    if positional and _literal_str(positional[0], lookup) is not None:
        return 0
    if len(positional) > 1 and _literal_str(positional[1], lookup) is not None:
        return 1
    return 0


def _literal_str(node: ast.expr | None, lookup: Lookup | None) -> str | None:
    if node is None:
        return None
    try:
        value = literal(node, lookup)
    except NotStatic:
        return None
    return value if isinstance(value, str) else None


def _interface_type(node: ast.expr, text: str, imports: dict[str, str]) -> str:
    """``package/sub/Name`` from the spec's import path, else its source text."""
    dotted = dotted_name(node)
    if dotted is None:
        return source_text(text, node, 200)
    head, _, rest = dotted.partition(".")
    path = imports.get(head)
    if path is None:
        full = dotted
    elif not rest:
        full = path
    elif dotted.startswith(path + "."):  # ``import a.b`` then ``a.b.Name``
        full = dotted
    else:
        full = f"{path}.{rest}"
    return full.replace(".", "/")
