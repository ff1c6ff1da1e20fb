"""Run a structured tree in BehaviorTree.CPP (behaviortreepy) and its source machine side by
side with the same scripted leaf outcomes; return both leaf-call sequences and results.

behaviortreepy cannot declare ports, so every state's leaf is written as one registered
stateful action ``ScriptedLeaf`` with only its ``name`` (the state's label), and a dispatch
leaf's output port is played by the callback writing the outcome to the tree's root blackboard
(the entry the port names; every SubTree has ``_autoremap="true"``, so that is where the
engine's Switch and Script nodes find it). Control nodes, SubTrees, Scripts and Switches are
BehaviorTree.CPP's own. The k-th leaf call gets outcome ``pick(seed, k, options)`` on both
sides; past ``budget`` calls the engine's leaf stays RUNNING (so a tick always returns).
"""

from __future__ import annotations

import random

import behaviortreepy as btpy
from lxml import etree

from fsmbt.convert.structured.schedule import read_structured_view
from fsmbt.formats import dumps
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.semantics.outcome_machine import OutcomeFSMMachine
from fsmbt.semantics.outcome_view import RUNNING_INPUT, Unit

LEAF_ID = "ScriptedLeaf"


def pick(seed: int, k: int, unit: Unit) -> str:
    rng = random.Random(seed * 100_003 + k)
    if rng.random() < 0.15:
        return RUNNING_INPUT
    return rng.choice(unit.outcomes)


def engine_xml(doc: BTDocument) -> str:
    """The tree's XML with each state's leaf as ``ScriptedLeaf name=LABEL`` (ports stripped)."""
    root = etree.fromstring(dumps(doc, "btcpp").encode())
    for models in root.findall("TreeNodesModel"):
        root.remove(models)
    for element in root.iter():
        if element.tag in doc.node_models:
            name = element.get("name")
            element.attrib.clear()
            element.tag = LEAF_ID
            element.set("name", name or "")
    return etree.tostring(root, encoding="unicode")


def run_btcpp(doc: BTDocument, fsm: FSM, seed: int, budget: int) -> tuple[list[str], str | None]:
    view = read_structured_view(fsm)
    calls: list[str] = []
    factory = btpy.BehaviorTreeFactory()
    holder: dict[str, object] = {}

    def leaf(node: btpy.TreeNode) -> btpy.NodeStatus:
        if len(calls) >= budget:
            return btpy.NodeStatus.RUNNING
        label = node.name()
        unit = view.by_label[label]
        outcome = pick(seed, len(calls), unit)
        calls.append(label)
        if outcome == RUNNING_INPUT:
            return btpy.NodeStatus.RUNNING
        if unit.dispatch:
            holder["bb"].set_string(unit.key, outcome)  # type: ignore[attr-defined]
            return btpy.NodeStatus.SUCCESS
        status = unit.status[outcome]
        return btpy.NodeStatus.SUCCESS if status == "success" else btpy.NodeStatus.FAILURE

    factory.register_simple_stateful_action(LEAF_ID, leaf, leaf, lambda node: None)
    tree = factory.create_tree_from_text(engine_xml(doc))
    holder["bb"] = tree.root_blackboard()
    while len(calls) < budget:
        status = tree.tick_once()
        if status in (btpy.NodeStatus.SUCCESS, btpy.NodeStatus.FAILURE):
            return calls, "SUCCESS" if status == btpy.NodeStatus.SUCCESS else "FAILURE"
    return calls, None


def run_source(fsm: FSM, seed: int, budget: int) -> tuple[list[str], str | None]:
    machine = OutcomeFSMMachine(read_structured_view(fsm))
    state, _outputs = machine.start()
    calls: list[str] = []
    while len(calls) < budget:
        if isinstance(state, tuple):
            return calls, state[0]
        unit = machine.unit_of(state)
        calls.append(unit.label)
        state, _outputs = machine.step(state, pick(seed, len(calls) - 1, unit))
    return calls, state[0] if isinstance(state, tuple) else None
