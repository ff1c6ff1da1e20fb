"""Project nodes read from their projects' sources and given by the node-library files in
node_libraries/ (docs/semantics.md "Project nodes"): stardust's RealParallel (a kind
of its own, ``stardust.RealParallel``), robocup2020's ActivationSequence (a Sequence) and
hans-ros-supervisor's Negation (BehaviorTree.CPP's old name of Inverter). Each rule against a
hand-made trace, and the NuSMV encoding of RealParallel against the native checker."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.model.bt import BTDocument
from fsmbt.semantics.bt_interpreter import BTRuntimeError
from support.bt_traces import doc_of, run

LIBRARIES = Path(__file__).resolve().parents[2] / "node_libraries"
STARDUST = LIBRARIES / "stardust.yaml"
ROBOCUP = LIBRARIES / "robocup2020.yaml"
HANS = LIBRARIES / "hans_ros_supervisor.yaml"


# -- stardust RealParallel ----------------------------------------------------------------------
def test_sem_real_parallel_ticks_every_child_and_never_resets_them() -> None:
    doc = doc_of(
        '<RealParallel><Action ID="A"/><Condition ID="C"/></RealParallel>', nodes=[STARDUST]
    )
    trace = run(doc, {"A": ["running", "success"], "C": ["success", "failure", "success"]}, 3)
    assert trace == [
        (["A", "C"], "RUNNING"),  # a RUNNING child: RUNNING (C's SUCCESS does not end it)
        (["A", "C"], "FAILURE"),  # no RUNNING child, one FAILURE: FAILURE
        (["C"], "SUCCESS"),  # A was not reset: it still holds SUCCESS and is not asked
    ]


def test_sem_real_parallel_halt_resets_its_children() -> None:
    doc = doc_of(
        '<ReactiveSequence><Condition ID="G"/><RealParallel><Action ID="A"/><Action ID="B"/>'
        "</RealParallel></ReactiveSequence>",
        nodes=[STARDUST],
    )
    trace = run(
        doc,
        {
            "G": ["success", "failure", "success"],
            "A": ["success", "success"],
            "B": ["running", "running"],
        },
        3,
    )
    assert trace == [
        (["G", "A", "B"], "RUNNING"),
        (["G"], "FAILURE"),  # the ReactiveSequence halts the RealParallel and its children
        (["G", "A", "B"], "RUNNING"),  # A was reset by the halt: asked again
    ]


def test_sem_real_parallel_refuses_a_skipped_child() -> None:
    doc = doc_of(
        '<RealParallel><LoopInt queue="" if_empty="SKIPPED"><Action ID="A"/></LoopInt>'
        '<Action ID="B"/></RealParallel>',
        nodes=[STARDUST],
    )
    with pytest.raises(BTRuntimeError, match="SKIPPED"):
        run(doc, {"B": ["success"]}, 1)


def test_sem_real_parallel_keeps_the_users_type_name() -> None:
    doc = doc_of('<RealParallel><Action ID="A"/></RealParallel>', nodes=[STARDUST])
    node = doc.main.root
    assert node is not None and node.type == "RealParallel"
    assert node.semantics == "stardust.RealParallel"


def test_sem_real_parallel_without_its_library_is_refused() -> None:
    doc = doc_of('<RealParallel><Action ID="A"/></RealParallel>', no_profiles=True)
    with pytest.raises(Exception, match="RealParallel' is not supported"):
        run(doc, {"A": ["success"]}, 1)


def test_sem_real_parallel_finds_its_bundled_library_by_itself() -> None:
    """With no option the bundled stardust.yaml applies (docs/semantics.md §10, "Profiles found
    by themselves") and one line says so."""
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="Main"><RealParallel><Action ID="A"/>'
        "</RealParallel></BehaviorTree></root>"
    )
    loaded = api.load_text(text, "btcpp")
    root = loaded.model.main.root  # type: ignore[union-attr]
    assert root is not None and root.semantics == "stardust.RealParallel"
    assert any("stardust.yaml" in w and "RealParallel used here" in w for w in loaded.warnings)


REAL_PARALLEL_TREES = [
    '<Sequence><RealParallel><Action ID="A"/><Condition ID="C"/></RealParallel>'
    '<Action ID="D"/></Sequence>',
    '<ReactiveSequence><Condition ID="G"/><RealParallel><Action ID="A"/><Action ID="B"/>'
    "</RealParallel></ReactiveSequence>",
]


@pytest.mark.nusmv
@pytest.mark.parametrize("xml", REAL_PARALLEL_TREES)
def test_sem_real_parallel_nusmv_agrees_with_the_native_checker(
    xml: str, tmp_path, nusmv_binary
) -> None:
    # (single-tick mode: with --loop the children RealParallel leaves completed keep the tree
    # out of its start configuration, which the BT -> FSM converter refuses to express)
    path = tmp_path / "rp.xml"
    path.write_text(
        f'<root BTCPP_format="4"><BehaviorTree ID="Main">{xml}</BehaviorTree></root>',
        encoding="utf-8",
    )
    outcome = api.convert_file(path, verify_engine="both", options={"nodes": [str(STARDUST)]})
    assert outcome.equivalent is True, outcome.verdict


# -- robocup2020 ActivationSequence, hans-ros-supervisor Negation ------------------------------
def test_sem_activation_sequence_is_a_sequence() -> None:
    doc = doc_of(
        "<ActivationSequence><NavigateToEntrance/><AskPerson/></ActivationSequence>",
        nodes=[ROBOCUP],
    )
    trace = run(
        doc,
        {
            "NavigateToEntrance": ["running", "success", "success"],
            "AskPerson": ["failure", "success"],
        },
        3,
    )
    assert trace == [
        (["NavigateToEntrance"], "RUNNING"),
        (["NavigateToEntrance", "AskPerson"], "FAILURE"),  # the running child was resumed
        (["NavigateToEntrance", "AskPerson"], "SUCCESS"),  # the failure restarted from the first
    ]
    root = doc.main.root
    assert root is not None and root.type == "ActivationSequence"  # the name is kept
    assert root.semantics == "Sequence"


def test_sem_negation_is_inverter() -> None:
    loaded = api.load_text(
        '<root><BehaviorTree ID="Main"><Negation><Condition ID="C"/></Negation>'
        "</BehaviorTree></root>",
        "btcpp",
        options={"nodes": [str(HANS)]},
    )
    doc = loaded.model
    assert isinstance(doc, BTDocument)
    assert doc.main.root is not None and doc.main.root.type == "Inverter"
    assert any("Negation" in str(w) and "Inverter" in str(w) for w in loaded.warnings)
    assert run(doc, {"C": ["success", "failure"]}, 2) == [(["C"], "FAILURE"), (["C"], "SUCCESS")]
