"""The nodes of a structured tree: one leaf per state, its ports, and the built-in controls
(docs/conversion.md, "The structured style").

A state becomes ONE leaf: ``name`` = the state's label, ID = its class (for a generic ROS state
its action or service type, ``move_base_msgs/MoveBaseAction`` -> ``move_base_msgs_MoveBaseAction``;
a state of unknown class: its name). What it was configured with travels with it
(``fsmbt.model.state_info``): each parameter is an input port holding its literal text, each
userdata key a blackboard port ``{key}`` (through the container's remapping), read keys input
ports, written keys output ports, both inout ports; a dispatch state has the output port
``outcome="{<label>_outcome}"``. Every leaf type is declared in ``<TreeNodesModel>`` with the
union of its states' ports. Controls are BehaviorTree.CPP 4.8.2 built-ins only.

Costs: O(ports) per leaf.
"""

from __future__ import annotations

import re

from fsmbt.model import state_info
from fsmbt.model.bt import BTNode, NodeModel, PortModel
from fsmbt.model.bt_nodes import builtin_spec
from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import SUBTREE_TYPE
from fsmbt.semantics.outcome_blackboard import OUTCOME_PORT
from fsmbt.semantics.outcome_view import Unit

_NOT_ID = re.compile(r"[^A-Za-z0-9_]+")
#: Port names BehaviorTree.CPP reserves (a parameter of that name gets ``param_`` in front).
RESERVED_PORTS = frozenset({"name", "ID", OUTCOME_PORT})


def type_id(text: str) -> str:
    """A valid, non-built-in node type ID for a class or interface name."""
    out = _NOT_ID.sub("_", text).strip("_") or "State"
    if out[0].isdigit():
        out = f"S_{out}"
    if builtin_spec(out) is not None or out == SUBTREE_TYPE:
        out = f"{out}State"
    return out


def leaf_type(unit: Unit) -> str:
    """The leaf's ID: the ROS interface type, else the class, else the state's name."""
    ros = state_info.ros_interface(unit.state)
    if ros is not None:
        return type_id(ros[1])
    return type_id(state_info.state_class(unit.state) or unit.name)


def control(kind: str, *children: BTNode, **attrs: str) -> BTNode:
    """A built-in control node."""
    return BTNode(kind, NodeKind.CONTROL, attrs=dict(attrs), children=list(children))


def decorator(kind: str, child: BTNode, **attrs: str) -> BTNode:
    """A built-in decorator."""
    return BTNode(kind, NodeKind.DECORATOR, attrs=dict(attrs), children=[child])


def always(success: bool) -> BTNode:
    """``AlwaysSuccess`` / ``AlwaysFailure``."""
    return BTNode("AlwaysSuccess" if success else "AlwaysFailure", NodeKind.ACTION)


def script(key: str, value: str) -> BTNode:
    """``Script code="key:='value'"``: writes a literal to a blackboard entry."""
    return BTNode("Script", NodeKind.ACTION, attrs={"code": f"{key}:='{value}'"})


def subtree(tree_id: str, label: str) -> BTNode:
    """A container's SubTree node; ``_autoremap`` shares the root's blackboard (userdata keys
    and outcome entries are the machine's, as SMACH's containers pass them down)."""
    return BTNode("SubTree", NodeKind.SUBTREE, name=label, attrs={"ID": tree_id,
                                                                   "_autoremap": "true"})  # fmt: skip


def _port(name: str) -> str:
    return f"param_{name}" if name in RESERVED_PORTS or name.startswith("_") else name


def leaf(unit: Unit, models: dict[str, NodeModel]) -> BTNode:
    """The state's leaf, and its type's declaration added to ``models``."""
    kind_id = leaf_type(unit)
    attrs: dict[str, str] = {}
    ports: list[PortModel] = []
    expressions = set(state_info.expression_parameters(unit.state))
    for name, value in state_info.parameters(unit.state).items():
        port = _port(name)
        attrs[port] = value
        note = "expression kept as its source text" if name in expressions else "parameter"
        ports.append(PortModel(port, "input", description=note))
    remap = state_info.remapping(unit.state)
    reads = state_info.input_keys(unit.state)
    writes = state_info.output_keys(unit.state)
    for key in dict.fromkeys([*reads, *writes]):
        port = _port(key)
        if port in attrs:
            continue
        attrs[port] = "{" + remap.get(key, key) + "}"
        direction = "inout" if key in reads and key in writes else (
            "input" if key in reads else "output")  # fmt: skip
        ports.append(PortModel(port, direction, description="userdata key"))
    if unit.dispatch:
        attrs[OUTCOME_PORT] = "{" + unit.key + "}"
        ports.append(
            PortModel(
                OUTCOME_PORT,
                "output",
                description="the outcome returned: " + ", ".join(unit.outcomes),
            )
        )
    _declare(models, kind_id, ports)
    return BTNode(kind_id, NodeKind.ACTION, name=unit.label, attrs=attrs)


def _declare(models: dict[str, NodeModel], kind_id: str, ports: list[PortModel]) -> None:
    model = models.setdefault(kind_id, NodeModel(kind_id, NodeKind.ACTION))
    known = {p.name: p for p in model.ports}
    for port in ports:
        old = known.get(port.name)
        if old is None:
            model.ports.append(port)
            known[port.name] = port
        elif old.direction != port.direction:
            old.direction = "inout"
