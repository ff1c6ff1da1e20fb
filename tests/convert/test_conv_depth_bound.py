"""The depth-bounded LEBT (docs/semantics.md §5, "Depth-bounded LEBT"): every written tree nests at
most 200 XML levels, machines that shallow keep the paper's exact shape, and every promoted
form is proven equivalent by the checker (flat and SubTree LEBTs)."""

from __future__ import annotations

import importlib

import pytest

from fsmbt.convert import convert
from fsmbt.convert.lebt import build_lebt, fsm_to_lebt, lebt_node_models, tree_depth
from fsmbt.convert.structure import MAX_SELECTOR_LEVELS, MAX_XML_LEVELS, analyse, bound_depth
from fsmbt.formats import dumps
from fsmbt.generate import random_fsm
from fsmbt.generate.outcome_machines import random_outcome_fsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from support.chains import chain, xml_depth
from support.conv_helpers import check, paper_aj_fsm


def test_the_bound_is_200_xml_levels() -> None:
    assert MAX_XML_LEVELS == 200
    assert 2 * MAX_SELECTOR_LEVELS + 1 + 2 <= MAX_XML_LEVELS


def test_shallow_machines_keep_the_paper_shape_exactly() -> None:
    for fsm in (paper_aj_fsm(), chain(60), chain(MAX_SELECTOR_LEVELS)):
        structure = analyse(fsm)
        assert bound_depth(structure) is structure  # nothing promoted, nothing copied
        result = fsm_to_lebt(fsm)
        assert "depth_bound_roots" not in result.stats
        assert result.stats["root_subtrees"] == len(structure.root_ids)
    assert fsm_to_lebt(chain(MAX_SELECTOR_LEVELS)).stats["depth"] == 2 * MAX_SELECTOR_LEVELS + 1


def test_a_chain_one_state_too_deep_promotes_that_state() -> None:
    result = fsm_to_lebt(chain(MAX_SELECTOR_LEVELS + 1))
    root = result.model.trees["MainTree"].root
    assert result.stats["depth_bound_roots"] == 1
    assert [sel.name for sel in root.children] == [
        "S0_selector",
        f"S{MAX_SELECTOR_LEVELS}_selector",
    ]
    assert result.stats["depth"] == tree_depth(root) == 2 * MAX_SELECTOR_LEVELS + 1


def test_a_1000_state_chain_is_depth_bounded_and_equivalent() -> None:
    fsm = chain(1000)
    result = convert(fsm, style="lebt")
    root = result.model.trees["MainTree"].root
    assert tree_depth(root) <= MAX_XML_LEVELS - 2
    assert xml_depth(dumps(result.model, "btcpp")) <= MAX_XML_LEVELS
    assert len(root.children) == 11  # ceil(1000 / 98) root selectors
    assert result.stats["depth_bound_roots"] == 10
    assert check(fsm, result.model).equivalent


def _bounded_doc(fsm: FSM, levels: int) -> BTDocument:
    doc = BTDocument.single(build_lebt(fsm, bound_depth(analyse(fsm), levels)))
    doc.node_models.update(lebt_node_models())
    return doc


def test_promotion_at_every_level_is_equivalent_on_random_machines() -> None:
    """The rule with a tiny bound (1-3 selector levels), so that chains, branches, loops and
    final states are promoted on every shape; each result proven by the checker."""
    promoted = 0
    for seed in range(60):
        fsm = random_fsm(seed, shape=("chain", "tree", "loop", "mixed")[seed % 4], max_states=25)
        structure = analyse(fsm)
        for levels in (1, 2, 3):
            bounded = bound_depth(structure, levels)
            promoted += len(bounded.root_ids) - len(structure.root_ids)
            doc = _bounded_doc(fsm, levels)
            assert tree_depth(doc.trees["MainTree"].root) <= 2 * levels + 1
            report = check(fsm, doc)
            assert report.equivalent, (seed, levels, report.verdicts())
    assert promoted > 100  # the rule was exercised, not skipped


def test_a_deep_chain_inside_a_composite_state_is_bounded_in_its_subtree() -> None:
    top = FSM(name="h")
    inner = chain(250, "inner")
    top.add_state("Top", regions=[inner])
    top.add_state("After", action="after", final=True)
    top.initial = "Top"
    top.add_transition("Top", None, "After")
    top.add_transition("Top", "abort", "After")
    result = convert(top, style="lebt")
    assert result.stats["hierarchy"] == "subtrees"
    assert set(result.model.trees) == {"MainTree", "Top"}
    for tree in result.model.trees.values():
        assert tree_depth(tree.root) <= 2 * MAX_SELECTOR_LEVELS + 1
    assert xml_depth(dumps(result.model, "btcpp")) <= MAX_XML_LEVELS
    assert check(top, result.model).equivalent


def test_a_hierarchy_deeper_than_the_subtree_bound_is_converted_flat() -> None:
    machine = chain(2, "leaf")
    for k in range(40):
        outer = FSM(name=f"n{k}")
        outer.add_state(f"C{k}", regions=[machine])
        outer.add_state(f"E{k}", action=f"e{k}", final=True)
        outer.initial = f"C{k}"
        outer.add_transition(f"C{k}", None, f"E{k}")
        outer.add_transition(f"C{k}", f"stop{k}", f"E{k}")
        machine = outer
    result = convert(machine, style="lebt")
    assert list(result.model.trees) == ["MainTree"]
    assert any("SubTree levels written: converted flat" in w for w in result.warnings)
    assert check(machine, result.model).equivalent


def test_a_structured_tree_past_the_bound_becomes_the_bounded_lebt_under_auto(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The rule of ``rules_fsm_to_bt`` with the bound lowered to 10 XML levels (a structured
    tree that deep takes ~1 300 states, too slow for a test): ``auto`` writes the LEBT and says
    why, ``structured`` refuses; both conversions proven or refused, never a deep tree."""
    fsm = random_outcome_fsm(0, 50, containers=0.0)
    natural = convert(fsm, style="structured", outcome_driven=True)
    assert natural.stats["style"] == "structured" and natural.stats["depth"] + 2 > 10
    # the module (``fsmbt.convert.engines`` the attribute is the function ``engines``)
    engine_table = importlib.import_module("fsmbt.convert.engines")
    monkeypatch.setattr(engine_table, "MAX_XML_LEVELS", 10)
    result = convert(fsm, style="auto", outcome_driven=True)
    assert result.stats["style"] == "lebt"
    assert any("the depth-bounded LEBT was written instead" in w for w in result.warnings)
    assert check(fsm, result.model).equivalent
    with pytest.raises(UnsupportedError, match="--style lebt writes a depth-bounded tree"):
        convert(fsm, style="structured", outcome_driven=True)
