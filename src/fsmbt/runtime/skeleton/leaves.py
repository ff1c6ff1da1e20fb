"""The leaf kinds of a behavior tree the user has to implement, with their ports.

A *leaf kind* is one non-built-in Action or Condition type of a BehaviorTree.CPP v4 document
(``Detect``, ``MoveBase``): every leaf of that type, whatever its ``name`` (the state's label),
runs the same class. Its ports come from the document's ``<TreeNodesModel>`` entry; a type the
file does not declare gets a model inferred from its uses, every attribute of every use (but
``name`` and BehaviorTree.CPP's ``_`` pre/post-condition attributes) being an input port.

Rules (docs/runtime.md, "The migration path"):

- Built-in node types (``Sequence``, ``RetryUntilSuccessful``, ``AlwaysSuccess``, ``Script`` ...)
  are BehaviorTree.CPP's own and get no class; ``SubTree`` references are followed by reading
  every tree of the document.
- A leaf that uses an attribute its declared model does not list is an error naming the leaf
  and its line: BehaviorTree.CPP 4.8.2 refuses such a tree at load time.
- An LEBT (``LebtGuard``/``LebtState`` leaves) or a dispatch tree (``DispatchEntry``) is not a
  leaf-skeleton input: its leaves are fsmbt's runtime's, and it is refused with that advice
  (a C++ skeleton of such a tree, every leaf fsmbt's, is ``machine.py``'s).
- A ROS action or service leaf is declared by an attribute of its ``<TreeNodesModel>`` entry:
  ``ros_action="nav2_msgs/action/NavigateToPose"`` or ``ros_service="std_srvs/srv/Trigger"``
  (ROS 1 spellings ``move_base_msgs/MoveBaseAction`` and ``std_srvs/Trigger`` are accepted).
  The leaf's ROS name is behaviortree_ros2's own port (``action_name`` / ``service_name``).

Cost: O(N + P) for N nodes and P attributes, one explicit-stack walk, no recursion.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from fsmbt.model.bt import BTDocument, BTNode, NodeModel, PortModel
from fsmbt.model.errors import InputError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.dispatch_runtime import ENTRY
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE

#: ``<TreeNodesModel>`` attributes that declare a ROS interface, and the kind each declares.
ROS_ATTRIBUTES = {"ros_action": "action", "ros_service": "service"}
#: behaviortree_ros2's port naming the ROS action server / service of a leaf.
ROS_NAME_PORT = {"action": "action_name", "service": "service_name"}
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


@dataclass(frozen=True)
class RosInterface:
    """A ROS 2 action or service type, split for C++ (``nav2_msgs::action::NavigateToPose``)."""

    kind: str  # "action" | "service"
    package: str
    name: str  # the type's own name (``NavigateToPose``)

    @property
    def cpp_type(self) -> str:
        folder = "action" if self.kind == "action" else "srv"
        return f"{self.package}::{folder}::{self.name}"

    @property
    def header(self) -> str:
        """The rosidl header (``nav2_msgs/action/navigate_to_pose.hpp``)."""
        folder = "action" if self.kind == "action" else "srv"
        return f"{self.package}/{folder}/{snake_case(self.name)}.hpp"

    @property
    def spelling(self) -> str:
        folder = "action" if self.kind == "action" else "srv"
        return f"{self.package}/{folder}/{self.name}"


@dataclass
class LeafKind:
    """One leaf type to implement: its ID, family, ports, ROS interface and where it is used."""

    type: str
    kind: NodeKind  # ACTION or CONDITION
    ports: list[PortModel]
    declared: bool  # the document's <TreeNodesModel> declares it (else inferred from uses)
    ros: RosInterface | None = None
    labels: list[str] = field(default_factory=list)  # the leaves' names, first use first

    @property
    def class_name(self) -> str:
        """A C++/Python class name for the type (its ID when it is an identifier)."""
        return class_name(self.type)

    @property
    def is_condition(self) -> bool:
        return self.kind is NodeKind.CONDITION

    @property
    def kind_word(self) -> str:
        """``action`` or ``condition`` (what the Python base class tests)."""
        return "condition" if self.is_condition else "action"

    @property
    def file_stem(self) -> str:
        return snake_case(self.class_name)

    @property
    def input_ports(self) -> list[PortModel]:
        return [p for p in self.ports if p.direction in ("input", "inout")]

    @property
    def output_ports(self) -> list[PortModel]:
        return [p for p in self.ports if p.direction in ("output", "inout")]


def snake_case(name: str) -> str:
    """``NavigateToPose`` -> ``navigate_to_pose`` (rosidl's rule for header names)."""
    text = re.sub(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])", "_", name)
    return re.sub(r"[^0-9a-zA-Z]+", "_", text).strip("_").lower() or "node"


def class_name(type_id: str) -> str:
    """An identifier for ``type_id``: itself when it is one, else its words in CamelCase."""
    if _IDENTIFIER.match(type_id):
        return type_id
    words = [w for w in re.split(r"[^0-9A-Za-z]+", type_id) if w]
    text = "".join(w[:1].upper() + w[1:] for w in words) or "Node"
    return text if not text[0].isdigit() else "N" + text


def parse_ros_interface(kind: str, text: str) -> RosInterface | None:
    """``pkg/action/Name``, ``pkg/srv/Name`` or ROS 1's ``pkg/NameAction`` / ``pkg/Name``."""
    parts = [p for p in text.strip().split("/") if p]
    folder = "action" if kind == "action" else "srv"
    if len(parts) == 3 and parts[1] == folder:
        package, name = parts[0], parts[2]
    elif len(parts) == 2:
        package, name = parts
        if kind == "action" and name.endswith("Action") and len(name) > len("Action"):
            name = name[: -len("Action")]
    else:
        return None
    if not (_IDENTIFIER.match(package) and _IDENTIFIER.match(name)):
        return None
    return RosInterface(kind, package, name)


def _ros_of(model: NodeModel) -> RosInterface | None:
    found = [(attr, kind) for attr, kind in ROS_ATTRIBUTES.items() if attr in model.attrs]
    if not found:
        return None
    if len(found) > 1:
        raise InputError(
            f"<TreeNodesModel> entry '{model.type}' declares both ros_action and ros_service"
        )
    attr, kind = found[0]
    interface = parse_ros_interface(kind, model.attrs[attr])
    if interface is None:
        example = "nav2_msgs/action/NavigateToPose" if kind == "action" else "std_srvs/srv/Trigger"
        raise InputError(
            f"<TreeNodesModel> entry '{model.type}': {attr}='{model.attrs[attr]}' is not a "
            f"ROS {kind} type (expected e.g. '{example}')"
        )
    return interface


def _is_user_leaf(node: BTNode) -> bool:
    return node.is_leaf and not node.is_builtin


def leaf_kinds(doc: BTDocument) -> list[LeafKind]:
    """The leaf kinds of every tree of ``doc``, in order of first use.

    Raises:
        InputError: an LEBT (see the module doc), a leaf using an attribute that is not a port
            of its declared model (naming the leaf and its line), a malformed ROS declaration,
            two types whose class names collide, a document without any leaf to implement.
    """
    found: dict[str, LeafKind] = {}
    for tree in doc.trees.values():
        if tree.root is None:
            continue
        stack = [tree.root]
        while stack:
            node = stack.pop()
            stack.extend(reversed(node.children))
            if node.type == ENTRY:
                raise InputError(
                    f"<{ENTRY}> is the leaf of the dispatch form (a tree written by fsmbt "
                    "convert for an event-driven machine): run it with fsmbt's runtime (fsmbt "
                    "runtime python DIR, no model; fsmbt runtime cpp DIR MODEL writes its C++ "
                    "skeleton when every leaf is one), or convert the machine with the "
                    "structured style for a skeleton of your own leaves",
                    location=node.location,
                    element=f"<{node.type}> '{node.label}'",
                )
            if node.type in (GUARD_TYPE, STATE_TYPE):
                raise InputError(
                    f"<{node.type}> is a leaf of an LEBT (a tree written by fsmbt convert "
                    "--style lebt): run it with the LEBT runtime (fsmbt runtime cpp DIR / "
                    "fsmbt runtime python DIR, no model), or convert the machine with the "
                    "structured style for a skeleton of your own leaves",
                    location=node.location,
                    element=f"<{node.type}> '{node.label}'",
                )
            if not _is_user_leaf(node):
                continue
            leaf = found.get(node.type)
            if leaf is None:
                leaf = _new_kind(doc, node)
                found[node.type] = leaf
            _add_use(leaf, node)
    if not found:
        raise InputError(
            "the tree has no leaf of its own to implement (only BehaviorTree.CPP built-ins)"
        )
    names: dict[str, str] = {}
    for leaf in found.values():
        other = names.setdefault(leaf.class_name.lower(), leaf.type)
        if other != leaf.type:
            raise InputError(
                f"node types '{other}' and '{leaf.type}' would get the same class or file "
                f"name '{leaf.class_name}'; rename one of them"
            )
    return list(found.values())


def _new_kind(doc: BTDocument, node: BTNode) -> LeafKind:
    model = doc.node_models.get(node.type)
    kind = NodeKind.CONDITION if node.kind is NodeKind.CONDITION else NodeKind.ACTION
    if model is None or not node.kind_declared:
        return LeafKind(node.type, kind, [], declared=False)
    ports = [
        PortModel(p.name, p.direction, p.default, p.description, p.type)
        for p in model.ports
        if p.name != "name"
    ]
    return LeafKind(node.type, kind, ports, declared=True, ros=_ros_of(model))


def _add_use(leaf: LeafKind, node: BTNode) -> None:
    if node.label not in leaf.labels:
        leaf.labels.append(node.label)
    known = {p.name for p in leaf.ports}
    ros_port = ROS_NAME_PORT.get(leaf.ros.kind) if leaf.ros is not None else None
    for attr in node.attrs:
        if attr in known or attr.startswith("_") or attr == ros_port:
            continue
        if leaf.declared:
            raise InputError(
                f"attribute '{attr}' is not a port of <{node.type}> in <TreeNodesModel> "
                f"(ports: {', '.join(sorted(known)) or 'none'}); BehaviorTree.CPP refuses it "
                "at load time: declare the port or remove the attribute",
                location=node.location,
                element=f"<{node.type}> '{node.label}'",
            )
        leaf.ports.append(PortModel(attr, "input"))
        known.add(attr)
