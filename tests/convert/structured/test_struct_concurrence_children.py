"""Concurrences beyond leaf children (docs/semantics.md §11, "Container children", "YASMIN
concurrences", "Concurrence callbacks"; issue 23 item 1): a StateMachine child or a YASMIN
region becomes a SubTree under the Parallel, proven EQUIVALENT, loaded and run in
BehaviorTree.CPP 4.8.2 with the same leaf calls and results as the round reading; a wrong
Parallel, a wrong child order and a loop that goes round in the same tick are found NOT
EQUIVALENT; what keeps the product form is named; SMACH callbacks are read, never run, and named
as abstractions."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert.structured import fsm_to_structured
from fsmbt.convert.structured.builder import decorator
from fsmbt.generate.outcome_machines import random_outcome_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.fsm import FSM, State
from fsmbt.model.serialize import fsm_to_dict
from fsmbt.verify import verify
from support.corpus import CORPUS

DATA = Path(__file__).resolve().parents[2] / "data" / "concurrence"
BUDGET = 60


def _convert(name: str) -> api.Outcome:
    return api.convert_file(DATA / name, style="structured")


def _doc(outcome: api.Outcome) -> BTDocument:
    doc = outcome.conversion.model
    assert isinstance(doc, BTDocument)
    return doc


def _node(doc: BTDocument, kind: str) -> BTNode:
    return next(n for _t, n in doc.nodes() if n.type == kind)


def _kept(outcome: api.Outcome) -> list[str]:
    return [w for w in outcome.conversion.warnings if "kept as its product machine" in w]


def _proven_loaded(outcome: api.Outcome) -> None:
    assert outcome.report is not None and outcome.report.equivalent
    assert outcome.load is not None and outcome.load.loaded


def _runs_alike(fsm: FSM, doc: BTDocument, seeds: range) -> None:
    btcpp = pytest.importorskip("support.structured_btcpp")
    for seed in seeds:
        ours = btcpp.run_source(fsm, seed, BUDGET)
        theirs = btcpp.run_btcpp(doc, fsm, seed, BUDGET)
        assert theirs == ours, (seed, ours, theirs)


def test_a_state_machine_child_is_a_subtree_under_the_parallel() -> None:
    outcome = _convert("smach_container_child.py")
    doc = _doc(outcome)
    node = _node(doc, "ParallelAll")
    assert node.attrs == {"max_failures": "1"}
    assert [(c.type, c.name) for c in node.children] == [("SubTree", "NAV"), ("Two", "WATCH")]
    assert [c.name for c in doc.trees["NAV"].root.children] == ["PLAN", "DRIVE"]
    _proven_loaded(outcome)
    _runs_alike(outcome.source.model, doc, range(25))


def test_a_wrong_parallel_or_child_order_is_not_equivalent() -> None:
    outcome = _convert("smach_container_child.py")
    source, doc = outcome.source.model, _doc(outcome)
    halting = copy.deepcopy(doc)
    node = _node(halting, "ParallelAll")
    node.type, node.attrs = "Parallel", {"success_count": "2", "failure_count": "1"}
    assert verify(source, halting, outcome_driven=True).equivalent is False
    swapped = copy.deepcopy(doc)
    _node(swapped, "ParallelAll").children.reverse()
    assert verify(source, swapped, outcome_driven=True).equivalent is False


def test_a_looping_child_goes_round_with_running_and_a_same_tick_retry_is_caught() -> None:
    outcome = _convert("smach_looping_child.py")
    doc = _doc(outcome)
    _proven_loaded(outcome)
    retry = doc.trees["NAV"].root.children[0]
    assert [retry.type, retry.children[0].type, retry.children[0].children[0].type] == [
        "Inverter",
        "KeepRunningUntilFailure",
        "Inverter",
    ]
    _runs_alike(outcome.source.model, doc, range(25))
    # RetryUntilSuccessful goes round in the same tick after a body that ran on: the Parallel
    # then ticks the looping child twice before the next child - another schedule
    same_tick = copy.deepcopy(doc)
    sequence = same_tick.trees["NAV"].root
    plan = sequence.children[0].children[0].children[0].children[0]
    sequence.children[0] = decorator("RetryUntilSuccessful", plan, num_attempts="-1")
    report = verify(outcome.source.model, same_tick, outcome_driven=True)
    assert report.equivalent is False


def test_a_child_needing_the_flag_form_keeps_the_product_named() -> None:
    outcome = _convert("smach_flag_child.py")
    kept = _kept(outcome)
    assert len(kept) == 1 and "child 'NAV' needs the flag form" in kept[0]
    assert not any(n.type.startswith("Parallel") for _t, n in _doc(outcome).nodes())
    _proven_loaded(outcome)


def test_flexbe_container_children_keep_the_product_named() -> None:
    outcome = _convert("flexbe_container_child.py")
    kept = _kept(outcome)
    assert len(kept) == 1 and "FlexBE steps a container child one state per tick" in kept[0]
    _proven_loaded(outcome)


@pytest.mark.parametrize("name", ["yasmin_concurrence.xml", "yasmin_orthogonal.xml"])
def test_yasmin_concurrence_and_orthogonal_state_are_parallels(name: str) -> None:
    outcome = _convert(name)
    doc = _doc(outcome)
    node = _node(doc, "ParallelAll")
    assert node.attrs == {"max_failures": "1"}
    if name == "yasmin_orthogonal.xml":
        assert [c.type for c in node.children] == ["SubTree", "SubTree"]
        assert [c.name for c in doc.trees["A"].root.children] == ["plan", "drive"]
    _proven_loaded(outcome)
    _runs_alike(outcome.source.model, doc, range(20))


YASMIN = CORPUS / "fsm" / "yasmin"


@pytest.mark.skipif(not YASMIN.exists(), reason="corpus not present (FSMBT_CORPUS)")
def test_yasmin_orthogonal_demo_regions_loop_and_keep_their_parameters() -> None:
    outcome = api.convert_file(YASMIN / "demo_orthogonal.xml", style="structured")
    doc = _doc(outcome)
    assert [c.name for c in _node(doc, "ParallelAll").children] == ["A", "B"]
    leaves = {n.name: n.attrs for _t, n in doc.nodes() if n.type == "WorkerState"}
    assert leaves["work_a"] == {"max_count": "3", "sleep_ms": "300"}
    _proven_loaded(outcome)
    _runs_alike(outcome.source.model, doc, range(10))
    synced = api.convert_file(YASMIN / "demo_orthogonal_sync.xml", style="structured")
    kept = _kept(synced)
    assert len(kept) == 1 and "JoinState barrier" in kept[0]


def test_smach_callbacks_are_an_environment_choice_named_in_the_verdict() -> None:
    outcome = _convert("smach_callbacks.py")
    doc = _doc(outcome)
    _proven_loaded(outcome)
    assert outcome.report is not None
    abstractions = outcome.report.stats["abstractions"]
    assert any(a.startswith("outcome_cb out_cb of CC not modelled") for a in abstractions)
    assert any(a.startswith("child_termination_cb child_term_cb of CC") for a in abstractions)
    root = doc.trees["CC"].root
    assert [c.type for c in root.children] == ["ForceSuccess", "out_cb"]
    assert [c.name for c in root.children[0].children[0].children] == ["A", "B"]
    _runs_alike(outcome.source.model, doc, range(20))


def test_an_outcome_cb_whose_outcome_is_dispatched_on_keeps_the_product(tmp_path: Path) -> None:
    text = (DATA / "smach_callbacks.py").read_text()
    three = text.replace('outcomes=["ok", "bad"]', 'outcomes=["ok", "bad", "again"]').replace(
        '"bad": "gave_up"}', '"bad": "gave_up", "again": "CC"}'
    )
    assert three != text
    path = tmp_path / "callbacks3.py"
    path.write_text(three)
    outcome = api.convert_file(path, style="structured")
    kept = _kept(outcome)
    assert len(kept) == 1 and "its outcome_cb out_cb may give" in kept[0]
    assert any(n.name == "out_cb" for _t, n in _doc(outcome).nodes())  # a leaf of the product
    _proven_loaded(outcome)


def _child(seed: int) -> FSM:
    """A generated machine without 'preempted' (a halt has no place inside a concurrence)."""
    fsm = random_outcome_fsm(seed, states=4, containers=0.3)
    for machine in fsm.machines():
        for t in machine.transitions:
            if t.target == "preempted":
                t.target = "aborted"
        if "preempted" in machine.states and machine.states["preempted"].final:
            del machine.states["preempted"]
    return fsm


def _generated(seed: int) -> FSM:
    """A machine whose one state is a SMACH Concurrence of two generated container children
    (as the reader records it), ``ok`` when both succeed."""
    children = {"A": _child(2 * seed), "B": _child(2 * seed + 1)}
    product = FSM(name="CC")
    product.add_state(State("P", action="P"))
    for outcome in ("ok", "bad"):
        product.add_state(State(outcome, action=None, final=True))
        product.add_transition("P", outcome, outcome)
    product.initial = "P"
    spec = {
        "class": "Concurrence",
        "children": [[k, "StateMachine", ["succeeded", "aborted"]] for k in children],
        "outcome_map": [["ok", {"A": "succeeded", "B": "succeeded"}]],
        "default": "bad",
        "barriers": 0,
        "machines": {k: fsm_to_dict(m) for k, m in children.items()},
    }
    top = FSM(name=f"gen_{seed}")
    top.add_state(State("CC", action=None, regions=[product],
                        attrs={"smach.concurrence": json.dumps(spec)}))  # fmt: skip
    for final in ("finished", "gave_up"):
        top.add_state(State(final, action=None, final=True))
    top.add_transition("CC", None, "finished", exit="ok")
    top.add_transition("CC", None, "gave_up", exit="bad")
    top.initial = "CC"
    return top


@pytest.mark.parametrize("seed", range(12))
def test_generated_container_children_are_proven_and_run_alike(seed: int) -> None:
    fsm = _generated(seed)
    result = fsm_to_structured(fsm)
    doc = result.model
    assert isinstance(doc, BTDocument)
    named = [w for w in result.warnings if w.startswith("Concurrence 'CC'")]
    assert len(named) == 1
    assert verify(fsm, doc, outcome_driven=True).equivalent
    if "kept as its product machine" in named[0]:
        # children that need the flag form: the product is kept, with the reason named, and
        # proven like any result; the Parallel's own checks below do not apply
        assert "needs the flag form" in named[0]
        assert not any(n.type in ("Parallel", "ParallelAll") for _t, n in doc.nodes())
        return
    assert any(n.type == "ParallelAll" for _t, n in doc.nodes())
    _runs_alike(fsm, doc, range(seed * 4, seed * 4 + 4))


def test_the_yasmin_writer_writes_an_orthogonal_state_back_while_its_product_is_unchanged() -> None:
    from fsmbt.formats import dumps, loads

    source = api.load(DATA / "yasmin_orthogonal.xml").model
    assert isinstance(source, FSM)
    text = dumps(source, "yasmin")
    assert "<OrthogonalState" in text and text.count("<Region") == 2
    again = loads(text, "yasmin")
    assert isinstance(again, FSM)
    assert again.states["par"].regions[0].transitions == source.states["par"].regions[0].transitions
    edited = copy.deepcopy(source)
    product = edited.states["par"].regions[0]
    product.transitions.pop()
    assert "<OrthogonalState" not in dumps(edited, "yasmin")


def test_the_child_schedule_names_the_round_trips_and_without_it_a_loop_keeps_the_product() -> None:
    from fsmbt.convert.structured.schedule import read_structured_view
    from fsmbt.semantics.outcome_view import read_outcome_view

    fsm = api.load(DATA / "smach_looping_child.py").model
    assert isinstance(fsm, FSM)
    plain = read_outcome_view(fsm).regions["CC"]
    assert plain.concurrence is not None and plain.concurrence.form is None
    assert "child 'NAV' loops back to 'PLAN'" in plain.concurrence.why
    region = read_structured_view(fsm).regions["CC"]
    assert region.parallel
    assert region.round_trips == {("CC/NAV/PLAN", "failed")}
    assert [u.name for u in region.units.values()] == ["NAV", "WATCH"]


@pytest.mark.parametrize(
    "name",
    [
        "smach_container_child.py",
        "smach_looping_child.py",
        "smach_callbacks.py",
        "yasmin_orthogonal.xml",
        "yasmin_concurrence.xml",
    ],
)
def test_bt_to_fsm_of_a_tree_with_a_parallel_is_proven_equivalent_to_the_source(name: str) -> None:
    from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
    from fsmbt.verify.native import check
    from fsmbt.verify.outcome_roundtrip import leaf_fsm_machines

    fsm = api.load(DATA / name).model
    assert isinstance(fsm, FSM)
    doc = fsm_to_structured(fsm).model
    assert isinstance(doc, BTDocument)
    assert any(n.type.startswith("Parallel") for _t, n in doc.nodes())
    back = bt_to_hfsm(doc).model
    assert isinstance(back, FSM)
    source, result, mode = leaf_fsm_machines(fsm, back)
    assert check(source, result, mode=mode).equivalent
