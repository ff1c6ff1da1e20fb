"""The Loop family (LoopInt, LoopBool, LoopDouble, LoopString; BehaviorTree.CPP 4.8
``loop_node.h``; docs/semantics.md "LoopInt, LoopBool, LoopDouble, LoopString").

Each rule against a hand-made trace (the leaves ticked and the root result of every tick, the
environment's answers scripted per leaf label), then against BehaviorTree.CPP itself (random
trees holding Loop nodes with literal queues, run in behaviortreepy and in the interpreter,
traces compared), then the NuSMV encoding against the native checker.
"""

from __future__ import annotations

import random
from collections.abc import Iterable

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fsmbt import api
from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.nodes import abstractions_used
from support import bt_traces
from support.bt_traces import Script, doc_of
from support.btcpp_lockstep import matches_btcpp
from support.random_trees import ALL_DECORATORS, OutcomeScript, random_tree


def run(
    doc: BTDocument, answers: dict[str, Iterable[str]], ticks: int
) -> list[tuple[list[str], str]]:
    """The Loop traces run in tickOnce mode (a RUNNING child is not re-ticked in the tick)."""
    return bt_traces.run(doc, answers, ticks, exactly_once=False)


# -- literal queues: exact ---------------------------------------------------------------------
def test_sem_loop_literal_queue_one_element_per_tick_then_if_empty() -> None:
    doc = doc_of('<LoopDouble queue="1;2;3" value="{n}"><Action ID="P"/></LoopDouble>')
    trace = run(doc, {"P": ["success"] * 6}, 5)
    assert trace == [
        (["P"], "RUNNING"),  # each success returns RUNNING: the next value on the next tick
        (["P"], "RUNNING"),
        (["P"], "RUNNING"),
        ([], "SUCCESS"),  # the queue is empty: if_empty (default SUCCESS), child not ticked
        (["P"], "RUNNING"),  # the root was reset: the static queue is copied afresh
    ]


def test_sem_loop_running_child_pops_nothing() -> None:
    doc = doc_of('<LoopInt queue="4;5" if_empty="FAILURE"><Action ID="P"/></LoopInt>')
    trace = run(doc, {"P": ["running", "running", "success", "success"]}, 5)
    assert trace == [
        (["P"], "RUNNING"),
        (["P"], "RUNNING"),  # still the first element
        (["P"], "RUNNING"),  # first element done
        (["P"], "RUNNING"),  # second element done
        ([], "FAILURE"),  # if_empty="FAILURE"
    ]


def test_sem_loop_child_failure_returns_failure_and_keeps_the_rest_of_the_queue(
    tmp_path,
) -> None:
    # stardust's RealParallel ticks a completed child again without resetting it: the Loop is
    # not IDLE after its FAILURE, so the queue is not reloaded and the next element is popped.
    lib = tmp_path / "lib.yaml"
    lib.write_text("nodes:\n  RealParallel: {semantics: stardust.RealParallel}\n", "utf-8")
    doc = doc_of(
        '<RealParallel><LoopBool queue="true;false;1"><Condition ID="C"/></LoopBool>'
        '<Action ID="X"/></RealParallel>',
        nodes=[lib],
    )
    trace = run(
        doc, {"C": ["failure", "success", "success"], "X": ["running", "running", "success"]}, 5
    )
    assert trace == [
        (["C", "X"], "RUNNING"),  # element 1 failed: Loop FAILURE
        (["C", "X"], "RUNNING"),  # element 2 (not reloaded)
        (["C", "X"], "RUNNING"),  # element 3
        ([], "SUCCESS"),  # no element left: if_empty; X still holds SUCCESS (not asked)
        ([], "SUCCESS"),  # nothing was reset: the Loop stays empty, X stays SUCCESS
    ]


def test_sem_loop_reset_by_its_parent_reloads_the_queue() -> None:
    # a ReactiveFallback halts its other children when one is RUNNING: the Loop goes IDLE
    # and copies its static queue afresh on its next tick
    doc = doc_of(
        '<ReactiveFallback><LoopBool queue="true;false;1"><Condition ID="C"/></LoopBool>'
        '<Action ID="X"/></ReactiveFallback>'
    )
    trace = run(doc, dict(REACTIVE_ANSWERS), 4)
    assert trace == REACTIVE_TRACE


REACTIVE_ANSWERS = {"C": ["failure", "success", "failure", "success"], "X": ["running"] * 4}
REACTIVE_TRACE = [
    (["C", "X"], "RUNNING"),  # element 1 failed, X runs (the Loop is reset)
    (["C"], "RUNNING"),  # reloaded: element 1 succeeded; X halted
    (["C", "X"], "RUNNING"),  # element 2 failed, X runs again
    (["C"], "RUNNING"),  # reloaded again
]


def test_sem_loop_empty_literal_queue_and_skipped() -> None:
    doc = doc_of(
        '<Sequence><LoopString queue="" if_empty="SKIPPED"><Action ID="P"/></LoopString>'
        '<Action ID="Q"/></Sequence>'
    )
    # an empty queue never ticks the child; SKIPPED lets the Sequence go on
    assert run(doc, {"Q": ["success", "success"]}, 2) == [(["Q"], "SUCCESS"), (["Q"], "SUCCESS")]


def test_sem_loop_queue_split_as_btcpp_splits_it() -> None:
    # "a;;b;" -> a, "", b (a trailing ';' adds no element, an inner ";;" adds an empty one)
    doc = doc_of('<LoopString queue="a;;b;"><Action ID="P"/></LoopString>')
    assert CompiledTree(doc).nodes[0].params[1] == 3


def test_sem_loop_literal_is_exact_without_any_option() -> None:
    doc = doc_of('<LoopInt queue="1;2"><Action ID="P"/></LoopInt>')
    assert abstractions_used(doc) == []
    tree = CompiledTree(doc)
    assert len(tree.nodes[0].children) == 1  # no gate leaf
    # still exact (no gate) when the blackboard abstraction is on
    doc = doc_of('<LoopInt queue="1;2"><Action ID="P"/></LoopInt>', abstract=["blackboard"])
    assert abstractions_used(doc) == [] and len(CompiledTree(doc).nodes[0].children) == 1


@pytest.mark.parametrize(
    ("xml", "error", "message"),
    [
        ('<LoopInt queue="1;x"><Action ID="P"/></LoopInt>', InputError, "'x'"),
        ('<LoopInt queue="3000000000"><Action ID="P"/></LoopInt>', InputError, "not a valid int"),
        ('<LoopBool queue="yes"><Action ID="P"/></LoopBool>', InputError, "not a valid bool"),
        ('<LoopDouble queue="1.5;abc"><Action ID="P"/></LoopDouble>', InputError, "'abc'"),
        ('<LoopInt value="{v}"><Action ID="P"/></LoopInt>', InputError, "missing port 'queue'"),
        ('<LoopInt queue="1" if_empty="DONE"><Action ID="P"/></LoopInt>', InputError, "status"),
        (
            '<LoopInt queue="{q}"><Action ID="P"/></LoopInt>',
            UnsupportedError,
            "--abstract blackboard",
        ),
        (
            '<LoopInt queue="1" if_empty="{s}"><Action ID="P"/></LoopInt>',
            UnsupportedError,
            "reads the blackboard",
        ),
    ],
)
def test_sem_loop_bad_input_is_refused_with_its_place(
    xml: str, error: type[Exception], message: str
) -> None:
    doc = doc_of(xml)
    with pytest.raises(error) as caught:
        CompiledTree(doc)
    assert message in str(caught.value)
    assert ":1" in str(caught.value) or "<Loop" in str(caught.value)  # located


# -- {blackboard} queues: an abstraction ---------------------------------------------------------
def test_sem_loop_blackboard_queue_is_a_gate_asked_while_the_child_is_not_running() -> None:
    doc = doc_of(
        '<LoopString queue="{names}" value="{n}" if_empty="FAILURE"><Action ID="P"/></LoopString>',
        abstract=["blackboard"],
    )
    trace = run(
        doc,
        {
            "LoopString.more": ["success", "success", "failure"],
            "P": ["running", "success", "success"],
        },
        4,
    )
    assert trace == [
        (["LoopString.more", "P"], "RUNNING"),  # an element: the child starts
        (["P"], "RUNNING"),  # a RUNNING child is ticked without asking
        (["LoopString.more", "P"], "RUNNING"),  # second element
        (["LoopString.more"], "FAILURE"),  # no element left: if_empty
    ]
    (sentence,) = abstractions_used(doc)
    assert sentence.startswith("LoopString: whether its blackboard queue still has an element")


def test_sem_loop_user_type_via_a_node_library(tmp_path) -> None:
    lib = tmp_path / "lib.yaml"
    lib.write_text("nodes:\n  LoopPose: {semantics: LoopDouble}\n", encoding="utf-8")
    doc = doc_of('<LoopPose queue="{wps}" value="{wp}"><Action ID="U"/></LoopPose>', nodes=[lib])
    trace = run(doc, {"LoopPose.more": ["success", "failure"], "U": ["success"]}, 2)
    assert trace == [(["LoopPose.more", "U"], "RUNNING"), (["LoopPose.more"], "SUCCESS")]
    assert abstractions_used(doc)[0].startswith("LoopPose (as LoopDouble:")
    # a literal queue of a user-defined element type has no known length
    doc = doc_of('<LoopPose queue="1;2;3"><Action ID="U"/></LoopPose>', nodes=[lib])
    with pytest.raises(UnsupportedError, match="user-defined|element type"):
        CompiledTree(doc)


# -- against BehaviorTree.CPP ----------------------------------------------------------------
SETTINGS = settings(
    max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)
_QUEUES = ("", "1", "1;2", "7;8;9", "3;4;5;6")
_LOOP_TYPES = ("LoopInt", "LoopDouble", "LoopString", "LoopBool")


def _loop_tree(seed: int) -> BTDocument:
    """A random tree (every supported node type) whose decorators include the Loop family,
    each Loop with a random literal queue and if_empty."""
    rng = random.Random(seed)
    doc = random_tree(rng, decorators=ALL_DECORATORS + ("LoopInt",) * 3, max_nodes=16)
    for _tree, node in doc.nodes():
        if node.type == "LoopInt":
            node.type = rng.choice(_LOOP_TYPES)
            queue = rng.choice(_QUEUES)
            if node.type == "LoopBool":
                queue = ";".join("true" if ch in "13579" else "0" for ch in queue.split(";") if ch)
            node.attrs = {
                "queue": queue,
                "if_empty": rng.choice(["SUCCESS", "FAILURE", "SKIPPED"]),
            }
            node.kind = NodeKind.DECORATOR
    return doc


def _compare(seed: int, exactly_once: bool) -> bool:
    doc = _loop_tree(seed)
    if not any(n.type.startswith("Loop") for _t, n in doc.nodes()):
        return False
    return matches_btcpp(doc, OutcomeScript(seed), exactly_once, seed)


@SETTINGS
@given(st.integers(min_value=0, max_value=2**31 - 1))
def test_sem_loop_tick_once_traces_match_btcpp(seed: int) -> None:
    _compare(seed, exactly_once=False)


@SETTINGS
@given(st.integers(min_value=0, max_value=2**31 - 1))
def test_sem_loop_tick_exactly_once_traces_match_btcpp(seed: int) -> None:
    _compare(seed, exactly_once=True)


def test_sem_loop_differential_trees_do_compare() -> None:
    """The differential tests above really run Loop nodes (not every seed is skipped)."""
    compared = sum(_compare(seed, exactly_once=True) for seed in range(60))
    assert compared >= 20, compared


def test_sem_loop_hand_trace_matches_btcpp() -> None:
    """The ReactiveFallback trace above, in BehaviorTree.CPP."""
    from fsmbt.semantics.engines.btcpp_engine import BTCppRunner

    doc = doc_of(
        '<ReactiveFallback><LoopBool queue="true;false;1"><Condition ID="C"/></LoopBool>'
        '<Action ID="X"/></ReactiveFallback>'
    )
    engine = BTCppRunner(doc, Script(dict(REACTIVE_ANSWERS)))
    theirs = [engine.tick_once() for _ in range(4)]
    assert [([label for label, _p, _o in r.leaves], r.result) for r in theirs] == REACTIVE_TRACE


# -- NuSMV encoding ----------------------------------------------------------------------------
LOOP_TREES = [
    '<Sequence><LoopDouble queue="1;2;3" value="{n}"><Action ID="P"/></LoopDouble>'
    '<Action ID="Done"/></Sequence>',
    '<ReactiveFallback><LoopInt queue="1;2" if_empty="FAILURE"><Condition ID="C"/></LoopInt>'
    '<Action ID="X"/></ReactiveFallback>',
    '<Fallback><LoopString queue="" if_empty="FAILURE"><Action ID="P"/></LoopString>'
    '<Action ID="Q"/></Fallback>',
    '<Sequence><LoopInt queue="{q}" if_empty="FAILURE"><Action ID="P"/></LoopInt>'
    '<Action ID="Q"/></Sequence>',
]


@pytest.mark.nusmv
@pytest.mark.parametrize("xml", LOOP_TREES)
@pytest.mark.parametrize("loop", [False, True])
def test_sem_loop_nusmv_agrees_with_the_native_checker(
    xml: str, loop: bool, tmp_path, nusmv_binary
) -> None:
    path = tmp_path / "loop.xml"
    path.write_text(
        f'<root BTCPP_format="4"><BehaviorTree ID="Main">{xml}</BehaviorTree></root>',
        encoding="utf-8",
    )
    outcome = api.convert_file(
        path, verify_engine="both", loop=loop, options={"abstract": ["blackboard"]}
    )
    assert outcome.equivalent is True, outcome.verdict


#: What the NuSMV encoding encodes (no Parallel, Repeat, Retry, RunOnce, no internal leaves
#: under KeepRunningUntilFailure; docs/semantics.md §10 "NuSMV"), plus the Loop family and
#: stardust's RealParallel.
_SMV_CONTROLS = (
    "Sequence",
    "ReactiveSequence",
    "SequenceWithMemory",
    "Fallback",
    "ReactiveFallback",
    "IfThenElse",
    "WhileDoElse",
    "stardust.RealParallel",
)
_SMV_DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "LoopInt", "LoopInt")


def _smv_tree(seed: int) -> BTDocument:
    rng = random.Random(seed)
    doc = random_tree(
        rng,
        controls=_SMV_CONTROLS,
        decorators=_SMV_DECORATORS,
        leaves=("Action", "Condition"),
        max_nodes=7,
    )
    for _tree, node in doc.nodes():
        if node.type == "LoopInt":
            node.attrs = {
                "queue": rng.choice(_QUEUES[:4]),
                "if_empty": rng.choice(["SUCCESS", "FAILURE"]),
            }
    return doc


@pytest.mark.slow
@pytest.mark.nusmv
def test_sem_loop_and_real_parallel_nusmv_agrees_on_random_trees(nusmv_binary) -> None:
    """The NuSMV encoding against the native checker on random trees holding Loop nodes and
    RealParallel: ``verify_models(engine="both")`` raises ``EngineDisagreement`` when the two
    checkers differ; every tree the rules engine converts must be EQUIVALENT for both."""
    from fsmbt import limits
    from fsmbt.verify.nusmv.runner import NuSMVLimitError

    compared = 0
    with limits.changed(nusmv_max_seconds=8):
        for seed in range(40):
            doc = _smv_tree(seed)
            if not any(n.type in ("LoopInt", "stardust.RealParallel") for _t, n in doc.nodes()):
                continue
            try:
                result = api.convert_model(doc)
            except UnsupportedError:
                continue  # a shape the converter does not express (counted below)
            try:
                report = api.verify_models(doc, result.model, engine="both")
            except NuSMVLimitError:
                continue  # too large for NuSMV in 8 s (counted below)
            if "nusmv_limit" in report.stats:
                continue  # NuSMV gave up: only the native verdict (not a comparison)
            assert report.equivalent, (seed, report)
            compared += 1
    assert compared >= 10, compared
