"""Project node kinds and abstractions (docs/semantics.md §10), each rule against a hand-made
trace: the leaves ticked (gates included, labelled ``<node>.<word>``) and the root result of
every tick, with the environment's answers scripted per leaf label."""

from __future__ import annotations

import pytest

from fsmbt import api
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.semantics.bt_interpreter import BTRunner
from support.bt_traces import Script, doc_of, run


def test_sem_pipeline_sequence_reticks_earlier_children() -> None:
    doc = doc_of('<PipelineSequence><Condition ID="C"/><Action ID="B"/></PipelineSequence>')
    trace = run(doc, {"C": ["success", "success", "failure"], "B": ["running", "running"]}, 3)
    # a plain Sequence would resume at B; the pipeline asks C again on every tick
    assert trace == [(["C", "B"], "RUNNING"), (["C", "B"], "RUNNING"), (["C"], "FAILURE")]


def test_sem_pipeline_passes_over_an_earlier_running_child() -> None:
    doc = doc_of(
        '<PipelineSequence><RateController hz="1"><Action ID="Plan"/></RateController>'
        '<Action ID="Follow"/></PipelineSequence>',
        nodes=["nav2"],
    )
    trace = run(
        doc,
        {
            "Plan": ["success"],
            "RateController.gate": ["failure", "success"],
            "Follow": ["running", "running", "success"],
        },
        3,
    )
    assert trace == [
        (["Plan", "Follow"], "RUNNING"),  # first tick after IDLE: no gate
        (["RateController.gate", "Follow"], "RUNNING"),  # closed: RUNNING, passed over
        # open: Plan is ticked but still holds SUCCESS (not reset), so it does not ask
        (["RateController.gate", "Follow"], "SUCCESS"),
    ]


def test_sem_recovery_node_retries_in_the_same_tick() -> None:
    doc = doc_of(
        '<RecoveryNode number_of_retries="1"><Action ID="M"/><Action ID="R"/></RecoveryNode>'
    )
    trace = run(
        doc,
        {"M": ["failure", "failure", "failure", "success"], "R": ["success", "running", "success"]},
        3,
    )
    assert trace == [
        (["M", "R", "M"], "FAILURE"),  # one retry, then FAILURE
        (["M", "R"], "RUNNING"),
        (["R", "M"], "SUCCESS"),
    ]


def test_sem_round_robin_keeps_its_position_and_wraps_only_when_asked() -> None:
    xml = '<RoundRobin{w}><Action ID="A"/><Action ID="B"/><Action ID="C"/></RoundRobin>'
    answers = {"A": ["success"], "B": ["failure"], "C": ["success"]}
    # wrap_around=false (Nav2's default): the last child completing ends with FAILURE
    assert run(doc_of(xml.format(w="")), answers, 2) == [
        (["A"], "SUCCESS"),
        (["B", "C"], "FAILURE"),
    ]
    answers = {"A": ["success"], "B": ["failure"], "C": ["success"]}
    assert run(doc_of(xml.format(w=' wrap_around="true"')), answers, 2) == [
        (["A"], "SUCCESS"),
        (["B", "C"], "SUCCESS"),
    ]


def test_sem_repeat_unless_failure_each_tick_runs_one_cycle_per_tick() -> None:
    doc = doc_of(
        '<RepeatUnlessFailureEachTick num_cycles="2"><Action ID="A"/></RepeatUnlessFailureEachTick>'
    )
    trace = run(doc, {"A": ["success", "success"]}, 2)
    assert trace == [(["A"], "RUNNING"), (["A"], "SUCCESS")]


def test_sem_for_each_asks_for_another_element() -> None:
    doc = doc_of(
        '<ForEach vector_in="{v}" out="{x}"><Action ID="A"/></ForEach>', nodes=["moveit_pro"]
    )
    trace = run(doc, {"ForEach.more": ["success", "failure"], "A": ["success"]}, 2)
    assert trace == [(["ForEach.more", "A"], "RUNNING"), (["ForEach.more"], "SUCCESS")]
    doc = doc_of(
        '<ForEachUntilSuccess vector_in="{v}" out="{x}"><Action ID="A"/></ForEachUntilSuccess>',
        nodes=["moveit_pro"],
    )
    trace = run(doc, {"ForEachUntilSuccess.more": ["success", "failure"], "A": ["failure"]}, 2)
    assert trace == [
        (["ForEachUntilSuccess.more", "A"], "RUNNING"),
        (["ForEachUntilSuccess.more"], "FAILURE"),
    ]


def test_sem_timers_as_abstractions() -> None:
    doc = doc_of('<Sequence><Sleep msec="10"/><Action ID="A"/></Sequence>', abstract=["time"])
    assert run(doc, {"Sleep.timer": ["failure", "success"], "A": ["success"]}, 2) == [
        (["Sleep.timer"], "RUNNING"),
        (["Sleep.timer", "A"], "SUCCESS"),
    ]
    doc = doc_of('<Timeout msec="5"><Action ID="A"/></Timeout>', abstract=["time"])
    assert run(doc, {"A": ["running", "running"], "Timeout.timer": ["failure", "success"]}, 3) == [
        (["A"], "RUNNING"),
        (["Timeout.timer", "A"], "RUNNING"),
        (["Timeout.timer"], "FAILURE"),
    ]
    doc = doc_of('<Delay delay_msec="5"><Action ID="A"/></Delay>', abstract=["time"])
    assert run(doc, {"Delay.timer": ["failure", "success"], "A": ["running", "success"]}, 3) == [
        (["Delay.timer"], "RUNNING"),
        (["Delay.timer", "A"], "RUNNING"),
        (["A"], "SUCCESS"),
    ]


def test_sem_blackboard_abstractions() -> None:
    doc = doc_of(
        '<Precondition if="x &gt; 1" else="SUCCESS"><Action ID="A"/></Precondition>',
        abstract=["blackboard"],
    )
    assert run(doc, {"Precondition.if": ["failure", "success"], "A": ["failure"]}, 2) == [
        (["Precondition.if"], "SUCCESS"),
        (["Precondition.if", "A"], "FAILURE"),
    ]
    doc = doc_of(
        '<Fallback><ScriptCondition code="a == 1"/><Action ID="A"/></Fallback>',
        abstract=["blackboard"],
    )
    assert run(doc, {"ScriptCondition": ["failure"], "A": ["success"]}, 1) == [
        (["ScriptCondition", "A"], "SUCCESS")
    ]
    doc = doc_of(
        '<BlackboardCheckString value_A="{a}" value_B="x" return_on_mismatch="SUCCESS">'
        '<Action ID="A"/></BlackboardCheckString>',
        abstract=["blackboard"],
    )
    assert run(doc, {"BlackboardCheckString.match": ["failure"]}, 1) == [
        (["BlackboardCheckString.match"], "SUCCESS")
    ]


@pytest.mark.parametrize(
    ("xml", "option"),
    [
        ('<RateController hz="1"><Action ID="A"/></RateController>', "--nodes nav2"),
        ('<ForEach vector_in="{v}"><Action ID="A"/></ForEach>', "--nodes moveit_pro"),
        ('<Sleep msec="1"/>', "--abstract time"),
        ('<Precondition if="a"><Action ID="A"/></Precondition>', "--abstract blackboard"),
    ],
)
def test_sem_refusal_names_the_option(xml: str, option: str) -> None:
    # --no-profiles: a project's kinds are then enabled only by the option the error names
    # (with no option the profile is found by itself: tests/formats/test_fmt_btcpp_profiles.py)
    with pytest.raises(UnsupportedError, match=option):
        BTRunner(doc_of(xml, no_profiles=True), Script({}))


def test_sem_groot_root_and_lowercase_inverter() -> None:
    text = (
        '<root><BehaviorTree ID="Main"><Root><inverter><Action ID="A"/></inverter></Root>'
        "</BehaviorTree></root>"
    )
    loaded = api.load_text(text, "btcpp")
    assert any("'inverter'" in w and "Inverter" in w for w in loaded.warnings)
    assert run(loaded.model, {"A": ["success"]}, 1) == [(["A"], "FAILURE")]  # type: ignore[arg-type]


def test_sem_abstractions_are_named_in_the_report() -> None:
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="Main"><PipelineSequence>'
        '<RateController hz="1"><Action ID="Plan"/></RateController><Action ID="Go"/>'
        "</PipelineSequence></BehaviorTree></root>"
    )
    loaded = api.load_text(text, "btcpp", options={"nodes": ["nav2"]})
    outcome = api.convert_loaded(loaded)
    assert outcome.equivalent
    assert outcome.report is not None
    sentences = outcome.report.stats["abstractions"]
    assert len(sentences) == 1 and sentences[0].startswith("RateController may skip its child")


def test_sem_blockers_are_all_reported() -> None:
    doc = doc_of(
        '<Sequence><Sleep msec="1"/><Mystery><Action ID="A"/><Action ID="B"/>'
        '</Mystery><Timeout msec="1"><Action ID="C"/></Timeout></Sequence>'
    )
    found = api.conversion_blockers(doc)
    assert [b.element.split()[0] for b in found if b.element] == [
        "<Sleep>",
        "<Mystery>",
        "<Timeout>",
    ]
    with pytest.raises(UnsupportedError, match=r"and 2 more blocker"):
        api.convert_loaded(api.Loaded(doc, None, "btcpp"))


def test_sem_node_file_alias_semantics_and_kind(tmp_path) -> None:
    nodes = tmp_path / "nodes.yaml"
    nodes.write_text(
        "nodes:\n  MyRetry: {alias: RetryUntilSuccessful}\n"
        "  MyPipe: {semantics: PipelineSequence}\n"
        "  IsOk: {kind: condition}\n",
        encoding="utf-8",
    )
    xml = '<MyPipe><IsOk/><MyRetry num_attempts="2"><Action ID="A"/></MyRetry></MyPipe>'
    loaded = api.load_text(
        f'<root BTCPP_format="4"><BehaviorTree ID="M">{xml}</BehaviorTree></root>',
        "btcpp",
        options={"nodes": [str(nodes)]},
    )
    doc = loaded.model
    assert isinstance(doc, BTDocument)
    root = doc.main.root
    assert root is not None and root.type == "MyPipe" and root.semantics == "PipelineSequence"
    assert root.children[1].type == "RetryUntilSuccessful"  # the alias renames
    assert any("MyRetry" in w for w in loaded.warnings)
    # IsOk is a condition the pipeline asks on every tick; the retry's synchronous failure
    # wakes the tree up, so tickOnce re-ticks the root (docs/semantics.md §3)
    trace = run(doc, {"IsOk": ["success"] * 3, "A": ["failure", "running", "success"]}, 2)
    assert trace == [(["IsOk", "A", "IsOk", "A"], "RUNNING"), (["IsOk", "A"], "SUCCESS")]


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("nodes:\n  X: {alias: NoSuchKind}\n", "unknown node kind 'NoSuchKind'"),
        ("nodes:\n  X: {kind: control}\n", "kind must be action or condition"),
        ("nodes: [1, 2\n", "malformed node file"),
        # an alias bomb: refused at the first alias, before anything is built
        (
            "a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
            "nodes: [*b, *b, *b, *b, *b, *b, *b, *b, *b]\n",
            "malformed node file: YAML aliases .* are not allowed",
        ),
        ("nodes:" + " [" * 5000 + "\n", "malformed node file: YAML nested deeper than"),
        ("other: 1\n", "unknown key"),
    ],
)
def test_sem_node_file_errors_are_located(tmp_path, content: str, message: str) -> None:
    nodes = tmp_path / "bad.yaml"
    nodes.write_text(content, encoding="utf-8")
    with pytest.raises(InputError, match=message) as caught:
        doc_of('<Action ID="A"/>', nodes=[str(nodes)])
    assert caught.value.location is not None and "bad.yaml" in str(caught.value.location)


def test_sem_unknown_profile_is_refused() -> None:
    with pytest.raises(InputError, match="unknown node profile 'nav3'"):
        doc_of('<Action ID="A"/>', nodes=["nav3"])
    with pytest.raises(InputError, match="unknown abstraction 'clock'"):
        doc_of('<Action ID="A"/>', abstract=["clock"])
