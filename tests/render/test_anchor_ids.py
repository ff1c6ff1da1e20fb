"""SVG anchors: ids built from state names and node paths, and the ids a trace step is at."""

from __future__ import annotations

import re

import pytest

from fsmbt import api
from fsmbt.render import model_to_dot, svg_text, trace_anchors
from fsmbt.render.anchor_ids import _configuration_paths
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.verify.mutations import mutants
from support.web_server import REPO

EXAMPLES = REPO / "examples"


def _ids(svg: str) -> set[str]:
    return set(re.findall(r'<g id="([^"]+)"', svg))


@pytest.mark.parametrize(
    "name", ["paper_fsm.xml", "door_hfsm.scxml", "robot_bt.xml", "game_npc_bt.xml"]
)
def test_every_state_and_node_has_its_anchor(name):
    loaded = api.load(EXAMPLES / name)
    ids = _ids(svg_text(loaded.model, expand_subtrees=True))
    if loaded.kind == "fsm":
        stack = [(loaded.model, "")]
        while stack:
            machine, prefix = stack.pop()
            for state in machine.states.values():
                assert f"s@{prefix}{state.name}" in ids
                stack.extend((region, f"{prefix}{state.name}/") for region in state.regions)
    else:  # the interpreter's paths (docs/semantics.md) are exactly the drawn ones
        tree = CompiledTree(loaded.model)
        assert {f"n@{node.path or 'root'}" for node in tree.nodes} == {
            i for i in ids if i.startswith("n@")
        }


def test_anchors_are_off_by_default():
    model = api.load(EXAMPLES / "paper_fsm.xml").model
    assert "s@A" not in model_to_dot(model)
    assert 'id="s@A"' in model_to_dot(model, anchors=True)


def test_configuration_names_split_into_state_paths():
    assert _configuration_paths("C/x") == ["C/x"]
    assert _configuration_paths("P/[x|Q/[y|z]]") == ["P/x", "P/Q/y", "P/Q/z"]
    assert _configuration_paths("A") == ["A"]


@pytest.mark.parametrize("name", ["paper_fsm.xml", "robot_bt.xml", "door_hfsm.scxml"])
def test_every_trace_state_of_a_mutant_maps_to_drawn_elements(name):
    source = api.load(EXAMPLES / name)
    result = api.convert_loaded(source, style="lebt").result  # LEBT anchors
    checked = 0
    for original in (source.model, result):
        other = result if original is source.model else source.model
        for mutant in mutants(original, per_operator=1)[:4]:
            report = api.verify_either_order(other, mutant.model)
            first, second = (
                (mutant.model, other) if report.stats["swapped"] else (other, mutant.model)
            )
            drawn = {
                id(first): _ids(svg_text(first, expand_subtrees=True)),
                id(second): _ids(svg_text(second, expand_subtrees=True)),
            }
            for prop in report.properties.values():
                for step in prop.counterexample or []:
                    for model, state in ((first, step.source_state), (second, step.result_state)):
                        anchors = trace_anchors(model, state)
                        assert anchors, (name, state)
                        assert set(anchors) <= drawn[id(model)], (name, state, anchors)
                        checked += 1
    assert checked > 0


def test_leaf_execution_state_names_the_leaf_at_its_path():
    doc = api.load(EXAMPLES / "robot_bt.xml").model
    tree = CompiledTree(doc)
    for node in tree.nodes:
        if not node.children and node.is_env_leaf:
            assert trace_anchors(doc, f"{node.label}@{node.path or 'root'}") == [
                f"n@{node.path or 'root'}"
            ]
    assert trace_anchors(doc, "SUCCESS") == ["n@root"]


def test_macro_step_state_names_the_lebt_leaves_acting_for_it():
    fsm = api.load(EXAMPLES / "paper_fsm.xml").model
    bt = api.convert_loaded(api.load(EXAMPLES / "paper_fsm.xml"), style="lebt").result
    svg = svg_text(bt, expand_subtrees=True)
    for state in fsm.states:
        anchors = trace_anchors(bt, state)
        assert anchors
        for anchor in anchors:  # each highlighted node's label names the state
            group = svg.split(f'<g id="{anchor}"', 1)[1].split("</g>", 1)[0]
            assert f"state={state}" in group or f"target={state}" in group or state in group
