"""The structured style gives outcome-driven machines the tree a person would write, and every
tree is proven equivalent to its machine by the outcome pairing (docs/semantics.md §11)."""

from __future__ import annotations

import json

import pytest

from fsmbt.convert import convert
from fsmbt.convert.structured import fsm_to_structured
from fsmbt.generate.outcome_machines import random_outcome_fsm
from fsmbt.model import state_info
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.verify import verify
from support.structured_machines import container, machine, pipeline


def _proven(fsm, doc: BTDocument, outcomes: str | None = None) -> bool:
    report = verify(fsm, doc, outcomes=OutcomeRules.from_option(outcomes), outcome_driven=True)
    return bool(report.equivalent)


def _types(doc: BTDocument) -> list[str]:
    return [node.type for _tree, node in doc.nodes()]


def _leaves(doc: BTDocument) -> dict[str, BTNode]:
    return {node.name: node for _tree, node in doc.nodes() if node.type in doc.node_models}


def test_a_pipeline_of_1000_states_is_one_sequence_of_depth_2() -> None:
    fsm = pipeline(1000)
    result = fsm_to_structured(fsm)
    root = result.model.main.root
    assert root is not None and root.type == "Sequence"
    assert [c.name for c in root.children] == [f"S{i}" for i in range(1000)]
    assert all(not c.children for c in root.children)
    assert result.stats["depth"] == 2 and result.stats["flags"] == 0
    assert list(result.model.node_models) == ["Step"]
    assert _proven(fsm, result.model)


def test_a_recovery_becomes_a_fallback_and_the_top_machine_is_the_main_tree() -> None:
    fsm = machine(
        {
            "Grasp": {"succeeded": "succeeded", "aborted": "Recover"},
            "Recover": {"succeeded": "succeeded", "aborted": "aborted"},
        }
    )
    result = fsm_to_structured(fsm)
    root = result.model.main.root
    assert root is not None and root.type == "Fallback"
    assert [c.name for c in root.children] == ["Grasp", "Recover"]
    assert [c.type for c in root.children] == ["GraspAction", "RecoverAction"]
    assert result.model.main.id == "m" and len(result.model.trees) == 1
    assert "1 fallback" in result.stats["summary"] and "0 flags" in result.stats["summary"]
    assert _proven(fsm, result.model)


def test_retry_and_patrol_loops_become_retry_and_keep_running_decorators() -> None:
    retry = machine(
        {
            "Dock": {"succeeded": "Charge", "aborted": "Dock"},
            "Charge": {"succeeded": "succeeded", "aborted": "aborted"},
        }
    )
    result = fsm_to_structured(retry)
    assert "RetryUntilSuccessful" in _types(result.model)
    assert _proven(retry, result.model)
    patrol = machine(
        {
            "GoA": {"succeeded": "GoB", "aborted": "aborted"},
            "GoB": {"succeeded": "GoA", "aborted": "aborted"},
        }
    )
    result = fsm_to_structured(patrol)
    root = result.model.main.root
    assert root is not None and root.type == "KeepRunningUntilFailure"
    assert _proven(patrol, result.model)


def test_three_outcomes_dispatch_through_an_outcome_port_and_a_switch() -> None:
    fsm = machine(
        {
            "Look": {"found": "Grasp", "lost": "Search", "blocked": "aborted"},
            "Grasp": {"succeeded": "succeeded", "aborted": "aborted"},
            "Search": {"succeeded": "succeeded", "aborted": "aborted"},
        }
    )
    result = fsm_to_structured(fsm)
    look = _leaves(result.model)["Look"]
    assert look.attrs["outcome"] == "{Look_outcome}"
    switches = [n for _t, n in result.model.nodes() if n.type.startswith("Switch")]
    assert len(switches) == 1 and switches[0].attrs["variable"] == "{Look_outcome}"
    model = result.model.node_models["LookAction"]
    assert [(p.name, p.direction) for p in model.ports] == [("outcome", "output")]
    assert result.stats["dispatches"] == 1
    assert _proven(fsm, result.model)


def test_parameters_and_userdata_travel_with_the_state_as_ports() -> None:
    extra = {
        "Move": state_info.encode(
            params={"velocity": "0.5", "text": "go"},
            inputs=["target", "speed"],
            outputs=["speed"],
            remap={"target": "home"},
        )
    }
    fsm = machine({"Move": {"succeeded": "succeeded", "aborted": "aborted"}}, extra=extra)
    result = fsm_to_structured(fsm)
    leaf = _leaves(result.model)["Move"]
    assert leaf.attrs == {
        "velocity": "0.5",
        "text": "go",
        "target": "{home}",
        "speed": "{speed}",
    }
    ports = {p.name: p.direction for p in result.model.node_models["MoveAction"].ports}
    assert ports == {"velocity": "input", "text": "input", "target": "input", "speed": "inout"}
    assert _proven(fsm, result.model)


def test_preempted_is_a_halt_when_it_ends_the_machine_and_an_outcome_otherwise() -> None:
    finals = ("succeeded", "aborted", "preempted")
    halted = machine(
        {
            "Go": {"succeeded": "Put", "aborted": "aborted", "preempted": "preempted"},
            "Put": {"succeeded": "succeeded", "aborted": "aborted", "preempted": "preempted"},
        },
        finals=finals,
    )
    result = fsm_to_structured(halted)
    root = result.model.main.root
    assert root is not None and root.type == "Sequence" and len(root.children) == 2
    assert result.stats["halts"] == 2 and any("preempted" in w for w in result.warnings)
    assert _proven(halted, result.model)
    recovered = machine(
        {
            "Go": {"succeeded": "succeeded", "aborted": "aborted", "preempted": "Stop"},
            "Stop": {"succeeded": "aborted"},
        },
        finals=finals,
    )
    result = fsm_to_structured(recovered)
    assert result.stats["halts"] == 0 and result.stats["dispatches"] == 1
    assert _proven(recovered, result.model)


def test_the_outcomes_option_names_statuses_and_the_default_choice_is_named() -> None:
    spec = {
        "Drive": {"lost": "aborted", "arrived": "Hand"},
        "Hand": {"done": "succeeded", "refused": "aborted"},
    }
    fsm = machine(spec, declared=False)
    default = fsm_to_structured(fsm)
    assert "Inverter" in _types(default.model)  # 'lost' came first: read as SUCCESS
    report = verify(fsm, default.model, outcome_driven=True)
    assert report.equivalent and default.stats["order_choices"] == 1
    assert any("'lost' read as SUCCESS" in s for s in report.stats["abstractions"])
    told = fsm_to_structured(fsm, outcomes="arrived=success,lost=failure")
    root = told.model.main.root
    assert root is not None and [c.name for c in root.children] == ["Drive", "Hand"]
    assert _proven(fsm, told.model, "arrived=success,lost=failure")
    # the default rules do not hold for the told tree: the checker sees the difference
    assert not _proven(fsm, told.model)


def test_each_container_is_one_subtree_and_a_dispatching_one_reports_its_outcome() -> None:
    inner = machine(
        {"Pick": {"succeeded": "Lift", "aborted": "aborted"}, "Lift": {"done": "succeeded"}},
        name="inner",
    )
    outer = machine({"Home": {"succeeded": "succeeded", "aborted": "aborted"}})
    container(outer, "FETCH", inner, {"succeeded": "Home", "aborted": "aborted"}, first=True)
    result = fsm_to_structured(outer)
    assert sorted(result.model.trees) == ["FETCH", "m"]
    sub = [n for _t, n in result.model.nodes() if n.type == "SubTree"]
    assert [(n.name, n.attrs) for n in sub] == [("FETCH", {"ID": "FETCH", "_autoremap": "true"})]
    assert _proven(outer, result.model)
    three = machine(
        {"A": {"found": "succeeded", "lost": "aborted", "blocked": "other"}},
        finals=("succeeded", "aborted", "other"),
        name="three",
    )
    outer = machine(
        {
            "X": {"succeeded": "succeeded", "aborted": "aborted"},
            "Y": {"succeeded": "succeeded", "aborted": "aborted"},
        }
    )
    container(outer, "C", three, {"succeeded": "X", "aborted": "Y", "other": "aborted"}, first=True)
    result = fsm_to_structured(outer)
    scripts = [n.attrs["code"] for _t, n in result.model.nodes() if n.type == "Script"]
    assert sorted(scripts) == ["C_outcome:='aborted'", "C_outcome:='other'",
                               "C_outcome:='succeeded'"]  # fmt: skip
    assert _proven(outer, result.model)


def test_an_irreducible_region_gets_the_flag_form_named_in_the_summary() -> None:
    fsm = machine(
        {
            "A": {"succeeded": "B", "aborted": "C"},
            "B": {"succeeded": "C", "aborted": "aborted"},
            "C": {"succeeded": "B", "aborted": "succeeded"},
        }
    )
    result = fsm_to_structured(fsm)
    assert result.stats["flags"] >= 1 and not result.stats["fully_structured"]
    assert any(w.startswith("flag") for w in result.warnings)
    assert f"{result.stats['flags']} flag" in result.stats["summary"]
    assert _proven(fsm, result.model)


def test_states_without_declared_outcomes_use_their_transitions() -> None:
    fsm = machine({"A": {"ok": "B", "bad": "aborted"}, "B": {"done": "succeeded"}}, declared=False)
    event_driven = convert(fsm)  # nothing says its events are outcomes: auto gives dispatch
    assert event_driven.stats["style"] == "dispatch"
    assert "DispatchEntry" in _types(event_driven.model)
    structured = convert(fsm, outcome_driven=True)
    assert structured.stats["style"] == "structured"
    assert _proven(fsm, structured.model)


@pytest.mark.parametrize("seed", range(40))
def test_generated_outcome_machines_are_proven_equivalent(seed: int) -> None:
    fsm = random_outcome_fsm(seed, states=7)
    result = fsm_to_structured(fsm)
    assert _proven(fsm, result.model), json.dumps(result.stats, default=str)
    labels = [n.name for _t, n in result.model.nodes() if n.type in result.model.node_models]
    assert len(labels) == len(set(labels))  # each state is ONE leaf
