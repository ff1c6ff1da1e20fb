"""fsmbt's own JSON form of every model (documented in docs/formats.md).

The same plain dictionaries back the JSON and YAML formats and the LLM path's output schema, so
there is one schema. ``"kind"`` says which model a dictionary holds: ``"fsm"`` (flat or
hierarchical) or ``"bt"``.
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode, NodeModel, PortModel
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM, State, Transition

SCHEMA_VERSION = 1


# -- FSM ----------------------------------------------------------------------------------------
def fsm_to_dict(fsm: FSM) -> dict[str, Any]:
    """An FSM as fsmbt's JSON/YAML schema (docs/formats/README.md).

    Args:
        fsm: A flat or hierarchical machine.

    Returns:
        Plain data with ``kind: "fsm"`` and the schema version.
    """
    out: dict[str, Any] = {"kind": "fsm", "schema": SCHEMA_VERSION}
    out.update(_machine_to_dict(fsm))
    return out


def _machine_to_dict(fsm: FSM) -> dict[str, Any]:
    out: dict[str, Any] = {"name": fsm.name, "initial": fsm.initial}
    if fsm.start_name is not None:
        out["start"] = fsm.start_name
    if fsm.initial_event is not None:
        out["initial_event"] = fsm.initial_event
    out["states"] = [_state_to_dict(s) for s in fsm.states.values()]
    out["transitions"] = [_transition_to_dict(t) for t in fsm.transitions]
    if fsm.attrs:
        out["attrs"] = dict(fsm.attrs)
    return out


def _state_to_dict(state: State) -> dict[str, Any]:
    out: dict[str, Any] = {"name": state.name, "action": state.action}
    if state.final:
        out["final"] = True
    if state.regions:
        out["regions"] = [_machine_to_dict(r) for r in state.regions]
    if state.attrs:
        out["attrs"] = dict(state.attrs)
    return out


def _transition_to_dict(t: Transition) -> dict[str, Any]:
    out: dict[str, Any] = {"source": t.source, "event": t.event, "target": t.target}
    if t.exit is not None:
        out["exit"] = t.exit
    if t.attrs:
        out["attrs"] = dict(t.attrs)
    return out


def fsm_from_dict(data: dict[str, Any], *, where: str = "fsm") -> FSM:
    """An FSM from fsmbt's JSON/YAML schema.

    Args:
        data: Plain data as :func:`fsm_to_dict` writes it.
        where: The path of ``data`` in the document, for error messages.

    Returns:
        The machine.

    Raises:
        InputError: A missing or mistyped field, named by its path in the data.
    """
    _expect(isinstance(data, dict), where, "expected an object")
    return _machine_from_dict(data, where)


def _machine_from_dict(data: dict[str, Any], where: str) -> FSM:
    """Build a machine and its regions with an explicit stack (regions nest without bound in
    user data; no recursion). Every field's type is checked: a wrong type is an ``InputError``
    naming the field's path."""
    top = FSM(name="fsm")
    stack: list[tuple[Any, str, FSM]] = [(data, where, top)]
    while stack:
        item, path, fsm = stack.pop()
        _expect(isinstance(item, dict), path, "expected an object")
        _fill_machine(item, path, fsm, stack)
    return top


def _fill_machine(
    data: dict[str, Any], where: str, fsm: FSM, stack: list[tuple[Any, str, FSM]]
) -> None:
    fsm.name = str(data.get("name", "fsm"))
    for i, s in enumerate(_as_list(data.get("states", []), f"{where}.states")):
        path = f"{where}.states[{i}]"
        _expect(
            isinstance(s, dict) and isinstance(s.get("name"), str),
            path,
            "a state needs a string 'name'",
        )
        if s["name"] in fsm.states:
            raise InputError(f"duplicate state '{s['name']}'", element=path)
        regions: list[FSM] = []
        for j, r in enumerate(_as_list(s.get("regions", []), f"{path}.regions")):
            region = FSM(name="region")
            regions.append(region)
            stack.append((r, f"{path}.regions[{j}]", region))
        fsm.add_state(
            State(
                s["name"],
                action=_opt_str(s.get("action", s["name"]), f"{path}.action"),
                final=bool(s.get("final", False)),
                regions=regions,
                attrs=_str_dict(s.get("attrs", {})),
            )
        )
    transitions = _as_list(data.get("transitions", []), f"{where}.transitions")
    for i, t in enumerate(transitions):
        path = f"{where}.transitions[{i}]"
        _expect(
            isinstance(t, dict)
            and isinstance(t.get("source"), str)
            and isinstance(t.get("target"), str),
            path,
            "a transition needs string 'source' and 'target'",
        )
        event = t.get("event")
        _expect(event is None or isinstance(event, str), path, "'event' must be a string or null")
        fsm.add_transition(
            t["source"],
            event,
            t["target"],
            exit=_opt_str(t.get("exit"), f"{path}.exit"),
            attrs=_str_dict(t.get("attrs", {})),
        )
    if "initial" in data:
        fsm.initial = _opt_str(data["initial"], f"{where}.initial")
    fsm.start_name = _opt_str(data.get("start"), f"{where}.start")
    fsm.initial_event = _opt_str(data.get("initial_event"), f"{where}.initial_event")
    fsm.attrs = _str_dict(data.get("attrs", {}))


# -- BT -----------------------------------------------------------------------------------------
def bt_to_dict(doc: BTDocument) -> dict[str, Any]:
    """A BT document as fsmbt's JSON/YAML schema (docs/formats/README.md).

    Args:
        doc: The document.

    Returns:
        Plain data with ``kind: "bt"`` and the schema version.
    """
    out: dict[str, Any] = {
        "kind": "bt",
        "schema": SCHEMA_VERSION,
        "format_version": doc.format_version,
        "main_tree": doc.main_tree,
        "trees": [
            {
                "id": t.id,
                "root": node_to_dict(t.root) if t.root is not None else None,
                **({"attrs": dict(t.attrs)} if t.attrs else {}),
            }
            for t in doc.trees.values()
        ],
    }
    if doc.node_models:
        out["node_models"] = [
            {
                "type": m.type,
                "kind": m.kind.value,
                "ports": [vars(p).copy() for p in m.ports],
                **({"attrs": dict(m.attrs)} if m.attrs else {}),
            }
            for m in doc.node_models.values()
        ]
    if doc.includes:
        out["includes"] = list(doc.includes)
    if doc.attrs:
        out["attrs"] = dict(doc.attrs)
    return out


def node_to_dict(root: BTNode) -> dict[str, Any]:
    """A node and its subtree as plain data; iterative, so 100 000-deep trees do not hit the
    recursion limit.

    Args:
        root: The subtree's root.

    Returns:
        Nested dicts, children under ``"children"``.
    """

    def shallow(node: BTNode) -> dict[str, Any]:
        d: dict[str, Any] = {"type": node.type, "kind": node.kind.value}
        if node.name is not None:
            d["name"] = node.name
        if node.attrs:
            d["attrs"] = dict(node.attrs)
        if not node.kind_declared:
            d["kind_declared"] = False
        return d

    top = shallow(root)
    stack = [(root, top)]
    while stack:
        node, out = stack.pop()
        if node.children:
            kids = [shallow(c) for c in node.children]
            out["children"] = kids
            stack.extend(zip(node.children, kids))
    return top


def node_from_dict(data: dict[str, Any], where: str = "node") -> BTNode:
    """A node and its subtree from plain data, without recursion.

    Args:
        data: Nested dicts as :func:`node_to_dict` writes them.
        where: The path of ``data`` in the document, for error messages.

    Returns:
        The subtree's root.

    Raises:
        InputError: A missing or mistyped field, named by its path in the data.
    """

    def shallow(d: Any, path: str) -> BTNode:
        _expect(
            isinstance(d, dict) and isinstance(d.get("type"), str),
            path,
            "a node needs a string 'type'",
        )
        kind = _node_kind(d.get("kind", "Action"), path)
        return BTNode(
            type=d["type"],
            kind=kind,
            name=_opt_str(d.get("name"), f"{path}.name"),
            attrs=_str_dict(d.get("attrs", {})),
            kind_declared=bool(d.get("kind_declared", True)),
        )

    root = shallow(data, where)
    stack = [(data, root, where)]
    while stack:
        d, node, path = stack.pop()
        for i, c in enumerate(_as_list(d.get("children", []), f"{path}.children")):
            child = shallow(c, f"{path}.children[{i}]")
            node.children.append(child)
            stack.append((c, child, f"{path}.children[{i}]"))
    return root


def bt_from_dict(data: dict[str, Any], *, where: str = "bt") -> BTDocument:
    """A BT document from fsmbt's JSON/YAML schema.

    Args:
        data: Plain data as :func:`bt_to_dict` writes it.
        where: The path of ``data`` in the document, for error messages.

    Returns:
        The document.

    Raises:
        InputError: A missing or mistyped field, named by its path in the data.
    """
    _expect(isinstance(data, dict), where, "expected an object")
    doc = BTDocument(
        format_version=str(data.get("format_version", "4")),
        main_tree=_opt_str(data.get("main_tree"), f"{where}.main_tree"),
        includes=[str(i) for i in _as_list(data.get("includes", []), f"{where}.includes")],
        attrs=_str_dict(data.get("attrs", {})),
    )
    for i, t in enumerate(_as_list(data.get("trees", []), f"{where}.trees")):
        path = f"{where}.trees[{i}]"
        _expect(
            isinstance(t, dict) and isinstance(t.get("id"), str), path, "a tree needs a string 'id'"
        )
        root = node_from_dict(t["root"], f"{path}.root") if t.get("root") is not None else None
        doc.trees[t["id"]] = BehaviorTree(t["id"], root, attrs=_str_dict(t.get("attrs", {})))
    for i, m in enumerate(_as_list(data.get("node_models", []), f"{where}.node_models")):
        path = f"{where}.node_models[{i}]"
        _expect(
            isinstance(m, dict) and isinstance(m.get("type"), str),
            path,
            "a node model needs a string 'type'",
        )
        kind = _node_kind(m.get("kind", "Action"), path)
        ports = [
            _port_from_dict(p, f"{path}.ports[{j}]")
            for j, p in enumerate(_as_list(m.get("ports", []), f"{path}.ports"))
        ]
        doc.node_models[m["type"]] = NodeModel(
            m["type"], kind, ports, _str_dict(m.get("attrs", {}))
        )
    return doc


# -- either -------------------------------------------------------------------------------------
def model_to_dict(model: FSM | BTDocument) -> dict[str, Any]:
    """Either kind of model as fsmbt's JSON/YAML schema.

    Args:
        model: An ``FSM`` or a ``BTDocument``.

    Returns:
        Plain data whose ``kind`` says which.
    """
    return fsm_to_dict(model) if isinstance(model, FSM) else bt_to_dict(model)


def model_from_dict(data: Any, *, where: str = "model") -> FSM | BTDocument:
    """Either kind of model from fsmbt's JSON/YAML schema, by its ``kind`` field.

    Args:
        data: Plain data as :func:`model_to_dict` writes it.
        where: The path of ``data`` in the document, for error messages.

    Returns:
        The ``FSM`` or ``BTDocument``.

    Raises:
        InputError: Not a mapping, an unknown ``kind``, or a missing or mistyped field
            (named by its path in the data).
    """
    _expect(isinstance(data, dict), where, "expected a JSON/YAML object")
    kind = data.get("kind")
    if kind == "fsm":
        return fsm_from_dict(data, where=where)
    if kind == "bt":
        return bt_from_dict(data, where=where)
    raise InputError(f'\'kind\' must be "fsm" or "bt", not {kind!r}', element=where)


_PORT_FIELDS = ("name", "direction", "default", "description", "type")


def _port_from_dict(data: Any, where: str) -> PortModel:
    _expect(
        isinstance(data, dict) and isinstance(data.get("name"), str),
        where,
        "a port needs a string 'name'",
    )
    unknown = sorted(str(k) for k in data if k not in _PORT_FIELDS)
    _expect(
        not unknown,
        where,
        f"unknown port field(s) {', '.join(unknown)} (known: {', '.join(_PORT_FIELDS)})",
    )
    return PortModel(
        name=data["name"],
        direction=str(data.get("direction", "input")),
        default=_opt_str(data.get("default"), f"{where}.default"),
        description=_opt_str(data.get("description"), f"{where}.description"),
        type=_opt_str(data.get("type"), f"{where}.type"),
    )


def _node_kind(value: Any, where: str) -> NodeKind:
    try:
        return NodeKind(value)
    except (ValueError, TypeError):
        raise InputError(f"unknown node kind {str(value)[:60]!r}", element=where) from None


def _opt_str(value: Any, where: str) -> str | None:
    """A string or null field: anything else is refused (numbers are not names)."""
    _expect(value is None or isinstance(value, str), where, "expected a string or null")
    return None if value is None else str(value)


def _expect(ok: bool, where: str, message: str) -> None:
    if not ok:
        raise InputError(message, element=where)


def _as_list(value: Any, where: str) -> list[Any]:
    if not isinstance(value, list):
        raise InputError("expected a list", element=where)
    return value


def _str_dict(value: Any) -> dict[str, str]:
    if not isinstance(value, dict):
        return {}
    return {str(k): str(v) for k, v in value.items()}
