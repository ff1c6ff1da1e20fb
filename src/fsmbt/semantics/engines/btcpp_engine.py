"""Run a ``BTDocument`` in BehaviorTree.CPP v4 through ``behaviortreepy``.

The tree is written to v4 XML here (with lxml) from the *compiled* tree, so that every
environment leaf has a unique name ``n<id>`` (its pre-order id in ``CompiledTree``) and every
SubTree occurrence gets its own generated ``<BehaviorTree>`` (SubTree semantics are kept, leaf
names stay unique). Leaves are registered once per kind:

- ``FsmbtCondition``: a simple condition; each tick asks the environment.
- ``FsmbtAction``: a stateful action; ``onStart`` and ``onRunning`` ask the environment (so an
  action ticked while still SUCCESS/FAILURE returns that status without asking, as v4 does).
- ``Script``/``SetBlackboard``/``UnsetBlackboard`` are written as ``AlwaysSuccess`` (same
  control flow; the blackboard is not modelled).

``BTCppRunner.tick_once()`` calls ``Tree.tick_once`` (v4 ``tickOnce``: re-ticks while a wake-up
is pending) or ``tick_exactly_once`` and returns the same ``TickRecord`` as the interpreter.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import behaviortreepy as btpy  # no stubs shipped (ignore_missing_imports in pyproject)
from lxml import etree

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.bt_interpreter import CompiledNode, CompiledTree, Environment, TickRecord
from fsmbt.semantics.lebt.driver import EngineLebtRun
from fsmbt.semantics.lebt.leaves import (
    LebtLeaves,
    guard_outcome,
    state_on_running,
    state_on_start,
)
from fsmbt.semantics.lebt.spec import BB_EVENT, BB_STATE, GUARD_TYPE, NO_EVENT, STATE_TYPE
from fsmbt.semantics.nodes import all_nodes
from fsmbt.semantics.status import LeafOutcome, NodeStatus

ACTION_ID = "FsmbtAction"
CONDITION_ID = "FsmbtCondition"

#: A leaf outcome (``LeafOutcome`` or its string) as the engine's status.
_STATUS: dict[str, Any] = {
    outcome: getattr(btpy.NodeStatus, outcome.status.name) for outcome in LeafOutcome
}
#: The engine's status as ours, and by name (the interpreter's ``TickRecord`` spelling).
_NODE_STATUS = {getattr(btpy.NodeStatus, status.name): status for status in NodeStatus}
_NAME_OF = {engine: status.name for engine, status in _NODE_STATUS.items()}

#: The Loop family: written with their literal queue and if_empty (a {blackboard} queue is an
#: abstraction the engine cannot run).
_LOOPS = frozenset(n.name for n in all_nodes() if n.handler == "loop_queue")

#: How a leaf is written: (registration ID, extra attributes) for a compiled leaf.
LeafWriter = Callable[[CompiledNode], tuple[str, dict[str, str]]]


def leaf_name(node: CompiledNode) -> str:
    return f"n{node.id}"


def _default_leaf(node: CompiledNode) -> tuple[str, dict[str, str]]:
    if node.internal_status is not None:
        return ("AlwaysFailure" if node.type == "AlwaysFailure" else "AlwaysSuccess"), {}
    return (CONDITION_ID if node.kind is NodeKind.CONDITION else ACTION_ID), {}


def compiled_to_xml(tree: CompiledTree, leaf_writer: LeafWriter = _default_leaf) -> str:
    """v4 XML of the compiled tree; SubTree occurrences become generated trees ``T<id>``."""
    nodes = tree.nodes
    root_el = etree.Element("root", BTCPP_format="4", main_tree_to_execute="MainTree")
    work: list[tuple[int, etree._Element]] = []
    main = etree.SubElement(root_el, "BehaviorTree", ID="MainTree")
    work.append((0, main))
    while work:
        nid, parent_el = work.pop()
        node = nodes[nid]
        if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
            tag, extra = leaf_writer(node)
            leaf_attrs = {"name": leaf_name(node)}
            leaf_attrs.update(extra)
            etree.SubElement(parent_el, tag, attrib=leaf_attrs)
            continue
        if node.type == "SubTree":
            sub_id = f"T{nid}"
            etree.SubElement(parent_el, "SubTree", ID=sub_id, name=leaf_name(node))
            sub_el = etree.SubElement(root_el, "BehaviorTree", ID=sub_id)
            work.append((node.children[0], sub_el))
            continue
        attrs = {"name": leaf_name(node)}
        if node.type == "Parallel":
            attrs["success_count"], attrs["failure_count"] = map(str, node.params)
        elif node.type == "ParallelAll":
            attrs["max_failures"] = str(node.params[0])
        elif node.type == "Repeat":
            attrs["num_cycles"] = str(node.params[0])
        elif node.type == "RetryUntilSuccessful":
            attrs["num_attempts"] = str(node.params[0])
        elif node.type == "RunOnce":
            attrs["then_skip"] = "true" if node.params[0] else "false"
        elif node.type in _LOOPS and node.params[1] >= 0:  # a literal queue (exact)
            attrs["queue"] = node.source.attrs["queue"]
            attrs["if_empty"] = NodeStatus(node.params[0]).name
            attrs["value"] = "{" + f"loop_value_{nid}" + "}"
        el = etree.SubElement(parent_el, node.type, attrib=attrs)
        for child in reversed(node.children):
            work.append((child, el))
    # children were pushed reversed but SubElement appends: rebuild order by sorting on ids
    for el in root_el.iter():
        kids = list(el)
        if len(kids) > 1 and el.tag != "root":
            kids.sort(key=lambda e: int(e.get("name", "n0")[1:]))
            el[:] = kids
    return etree.tostring(root_el, pretty_print=True, encoding="unicode")


class BTCppRunner:
    """A BehaviorTree.CPP tree whose leaves ask ``env(node, path)`` for their outcome."""

    def __init__(
        self, doc: BTDocument | CompiledTree, env: Environment, *, exactly_once: bool = False
    ) -> None:
        self.tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        self.env = env
        self.exactly_once = exactly_once
        self._leaves: list[tuple[str, str, str]] = []
        self.halted: list[str] = []
        factory = btpy.BehaviorTreeFactory()
        factory.register_simple_condition(CONDITION_ID, self._tick)
        factory.register_simple_stateful_action(ACTION_ID, self._tick, self._tick, self._halt)
        self.xml = compiled_to_xml(self.tree)
        self.bt = factory.create_tree_from_text(self.xml)

    def _node_of(self, bt_node: btpy.TreeNode) -> CompiledNode:
        return self.tree.nodes[int(bt_node.name()[1:])]

    def _tick(self, bt_node: btpy.TreeNode) -> btpy.NodeStatus:
        node = self._node_of(bt_node)
        outcome = self.env(node.source, node.path)
        self._leaves.append((node.label, node.path, outcome))
        return _STATUS[outcome]

    def _halt(self, bt_node: btpy.TreeNode) -> None:
        self.halted.append(self._node_of(bt_node).label)

    def tick_once(self) -> TickRecord:
        self._leaves = []
        status = self.bt.tick_exactly_once() if self.exactly_once else self.bt.tick_once()
        return TickRecord(self._leaves, _NAME_OF[status])


# -- the LEBT protocol in BehaviorTree.CPP (tick function for fsmbt.semantics.lebt.driver) ----
class _TreeBlackboard:
    """``state``/``event`` kept in the BehaviorTree.CPP tree's root blackboard."""

    def __init__(self, bb: btpy.Blackboard) -> None:
        self._bb = bb

    @property
    def state(self) -> str:
        value: str = self._bb.get_string(BB_STATE)
        return value

    @state.setter
    def state(self, value: str) -> None:
        self._bb.set_string(BB_STATE, value)

    @property
    def event(self) -> str:
        value: str = self._bb.get_string(BB_EVENT)
        return value

    @event.setter
    def event(self, value: str) -> None:
        self._bb.set_string(BB_EVENT, value)


class BTCppLebtRunner(EngineLebtRun):
    """An LEBT in BehaviorTree.CPP: ``LebtGuard`` is a simple condition, ``LebtState`` a
    stateful action (``onStart`` enters the state, ``onRunning`` watches the event); the
    blackboard is the tree's; leaves find their spec by their name ``n<id>``."""

    def __init__(self, doc: BTDocument | CompiledTree, *, start: str | None = None) -> None:
        self.tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        super().__init__()
        self.leaves = LebtLeaves.of(self.tree, start)
        factory = btpy.BehaviorTreeFactory()
        factory.register_simple_condition(GUARD_TYPE, self._guard)
        factory.register_simple_stateful_action(
            STATE_TYPE, self._start, self._running, lambda node: None
        )

        def writer(node: CompiledNode) -> tuple[str, dict[str, str]]:
            return (GUARD_TYPE if node.id in self.leaves.guards else STATE_TYPE), {}

        self.xml = compiled_to_xml(self.tree, writer)
        self.bt = factory.create_tree_from_text(self.xml)
        self.bb = _TreeBlackboard(self.bt.root_blackboard())
        self.bb.state = self.leaves.start
        self.bb.event = NO_EVENT

    def _id(self, bt_node: btpy.TreeNode) -> int:
        return int(bt_node.name()[1:])

    def _guard(self, bt_node: btpy.TreeNode) -> btpy.NodeStatus:
        return _STATUS[guard_outcome(self.leaves.guards[self._id(bt_node)], self.bb)]

    def _start(self, bt_node: btpy.TreeNode) -> btpy.NodeStatus:
        spec = self.leaves.states[self._id(bt_node)]
        return _STATUS[state_on_start(spec, self.bb, self.actions)]

    def _running(self, bt_node: btpy.TreeNode) -> btpy.NodeStatus:
        return _STATUS[state_on_running(self.leaves.states[self._id(bt_node)], self.bb)]

    def _tick_engine(self) -> NodeStatus:
        """One ``tickOnce`` of the engine's tree."""
        return _NODE_STATUS[self.bt.tick_once()]
