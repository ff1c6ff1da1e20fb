"""FSM -> LEBT on the paper's A-J example and on corner cases, verified by the checker."""

from __future__ import annotations

import pytest

from fsmbt.convert import convert
from fsmbt.model.bt import BTNode
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE, GuardSpec, StateSpec
from support.conv_helpers import check, paper_aj_fsm


def _subtree_state(selector: BTNode) -> str:
    """The state a selector subtree Fallback(guard, body) enters."""
    assert selector.type == "Fallback" and len(selector.children) == 2
    guard = selector.children[0]
    assert guard.type == GUARD_TYPE
    return GuardSpec.from_attrs(guard.attrs).target


def _body_states(selector: BTNode) -> tuple[str, list[BTNode]]:
    """(state leaf of the body, the selector subtrees below it)."""
    body = selector.children[1]
    if body.type == STATE_TYPE:
        return StateSpec.from_attrs(body.attrs).state, []
    assert body.type == "Sequence" and body.children[0].type == STATE_TYPE
    return StateSpec.from_attrs(body.children[0].attrs).state, body.children[1:]


def test_paper_aj_structure_and_equivalence() -> None:
    fsm = paper_aj_fsm()
    result = convert(fsm, style="lebt")
    root = result.model.main.root
    assert root.type == "Sequence"
    assert [_subtree_state(c) for c in root.children] == ["A", "C", "D"]
    a_sel, c_sel, d_sel = root.children

    # A's body: a branch structure holding B and the chain F -> I -> J
    leaf, below = _body_states(a_sel)
    assert leaf == "A" and [_subtree_state(s) for s in below] == ["B", "F"]
    b_sel, f_sel = below
    assert _body_states(b_sel) == ("B", [])
    chain = []
    node = f_sel
    while True:
        state, nested = _body_states(node)
        chain.append(state)
        if not nested:
            break
        assert len(nested) == 1
        node = nested[0]
    assert chain == ["F", "I", "J"]

    # D's body: the chain D -> E -> G -> H
    chain, node = [], d_sel
    while True:
        state, nested = _body_states(node)
        chain.append(state)
        if not nested:
            break
        assert len(nested) == 1
        node = nested[0]
    assert chain == ["D", "E", "G", "H"]

    # C's guard merges eventAC, eventBC and eventEC; C's body is C alone
    guard = GuardSpec.from_attrs(c_sel.children[0].attrs)
    assert guard.pairs == (("A", "eventAC"), ("B", "eventBC"), ("E", "eventEC"))
    assert _body_states(c_sel) == ("C", [])
    entry_guard = GuardSpec.from_attrs(a_sel.children[0].attrs)
    assert entry_guard.pairs == (("Start", "eventSA"),)
    assert result.stats["root_subtrees"] == 3 and result.stats["loop_states"] == 2

    names = {n.name for n in root.walk() if n.is_leaf}
    assert {"Enter_C", "C", "Enter_A", "A"} <= names
    assert set(result.model.node_models) == {GUARD_TYPE, STATE_TYPE}
    assert check(fsm, result.model).equivalent


def test_no_initial_event_self_loops_and_unreachable() -> None:
    fsm = FSM(name="corner")
    for name in ("Idle", "Run", "Done", "Orphan"):
        fsm.add_state(name, final=name == "Done")
    fsm.add_transition("Idle", "go", "Run")
    fsm.add_transition("Run", "tick", "Run")  # self-loop: Run becomes a loop state
    fsm.add_transition("Run", "stop", "Done")
    fsm.add_transition("Orphan", "go", "Idle")  # unreachable source
    result = convert(fsm, style="lebt")
    root = result.model.main.root
    assert [_subtree_state(c) for c in root.children] == ["Idle", "Run"]
    entry = GuardSpec.from_attrs(root.children[0].children[0].attrs)
    assert entry.pairs == (("__start__", ""),), "the initialisation pair"
    assert any("unreachable" in w and "Orphan" in w for w in result.warnings)
    assert check(fsm, result.model).equivalent


def test_final_state_transitions_never_fire_and_hierarchy_flattens() -> None:
    fsm = FSM(name="h")
    inner = FSM(name="inner")
    inner.add_state("x")
    inner.add_state("y", final=True)
    inner.add_transition("x", "e", "y")
    fsm.add_state("Top", regions=[inner])
    fsm.add_state("After", final=True)
    fsm.add_transition("Top", None, "After")
    fsm.add_transition("Top", "abort", "After")
    result = convert(fsm, style="lebt")
    assert result.stats["flattened"] is True
    assert check(fsm, result.model).equivalent


def test_compact_style_is_refused() -> None:
    with pytest.raises(UnsupportedError):
        convert(paper_aj_fsm(), style="compact")


def test_cli_convert_verifies_writes_and_refuses_overwrite(tmp_path) -> None:
    from fsmbt import api
    from fsmbt.cli import main
    from fsmbt.formats import loads
    from fsmbt.model.serialize import model_to_dict
    from support.conv_helpers import paper_robot_bt

    source = tmp_path / "aj.json"
    api.write(paper_aj_fsm(), source)
    out = tmp_path / "aj.xml"
    assert main(["convert", str(source), "-o", str(out)]) == 0 and out.exists()
    assert main(["convert", str(source), "-o", str(out)]) == 2, "no overwrite without --force"
    assert main(["convert", str(source), "-o", str(out), "--force", "--json"]) == 0
    robot = tmp_path / "robot.json"
    api.write(paper_robot_bt(), robot)
    text_out = tmp_path / "robot.txt"
    assert main(["convert", str(robot), "-o", str(text_out)]) == 0
    hfsm = convert(paper_robot_bt()).model
    assert model_to_dict(loads(text_out.read_text(), "paper-text")) == model_to_dict(hfsm)
    assert main(["convert", str(tmp_path / "missing.json")]) == 2
