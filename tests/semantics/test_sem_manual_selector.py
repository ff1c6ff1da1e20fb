"""ManualSelector (BehaviorTree.CPP manual_node.cpp; docs/semantics.md, "ManualSelector").

The person's pick is an environment input, asked through chained choice conditions
``<label>.pick_<i>``, ``<label>.pick_SUCCESS``, ``<label>.pick_FAILURE`` (none: RUNNING). The
rule is checked against hand-made traces (BehaviorTree.CPP 4.8.2 does not build the node: it
needs ncurses, so the real engine cannot run it), the NuSMV encoding against the native checker,
and the corpus example end to end.
"""

from __future__ import annotations

import pytest

from fsmbt import api
from fsmbt.formats import loads
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.semantics.bt_interpreter import (
    IDLE,
    RUNNING,
    BTInterpreter,
    BTRunner,
    LeafRequest,
    TickDone,
)
from fsmbt.verify.nusmv.binary import find_nusmv
from support.corpus import CORPUS


def act(name: str) -> BTNode:
    return BTNode("Act", NodeKind.ACTION, name=name)


def manual(*children: BTNode, name: str = "m", **attrs: str) -> BTNode:
    return BTNode(
        "ManualSelector", NodeKind.CONTROL, name=name, attrs=dict(attrs), children=list(children)
    )


class Plan:
    """Outcomes per leaf label, consumed in order (a KeyError: a leaf asked unexpectedly)."""

    def __init__(self, **plans: str) -> None:
        self.plans = {k.replace("__", "."): v.split() for k, v in plans.items()}

    def __call__(self, node: BTNode, path: str) -> str:
        return self.plans[node.label].pop(0)

    def used_up(self) -> bool:
        return not any(self.plans.values())


def run(root: BTNode, ticks: int, **plans: str) -> list[tuple[list[str], str]]:
    plan = Plan(**plans)
    runner = BTRunner(BTDocument.single(root), plan)
    records = [runner.tick_once() for _ in range(ticks)]
    assert plan.used_up()
    return [([f"{leaf[0]}={leaf[2]}" for leaf in r.leaves], r.result) for r in records]


def test_manual_the_person_picks_a_child_or_a_status_on_every_tick() -> None:
    tree = manual(act("a"), act("b"))
    trace = run(
        tree,
        5,
        m__pick_1="success failure success failure failure",
        m__pick_2="success failure failure",
        m__pick_SUCCESS="success failure",
        m__pick_FAILURE="failure",
        a="running success",
        b="success",
    )
    assert trace == [
        (["m.pick_1=success", "a=running"], "RUNNING"),
        # asked again although a is RUNNING; b picked; a is not halted
        (["m.pick_1=failure", "m.pick_2=success", "b=success"], "SUCCESS"),
        (["m.pick_1=success", "a=success"], "SUCCESS"),
        (["m.pick_1=failure", "m.pick_2=failure", "m.pick_SUCCESS=success"], "SUCCESS"),
        (
            [
                "m.pick_1=failure",
                "m.pick_2=failure",
                "m.pick_SUCCESS=failure",
                "m.pick_FAILURE=failure",
            ],
            "RUNNING",
        ),
    ]


def test_manual_a_child_left_running_is_resumed_not_restarted() -> None:
    """The interpreter's leaf request shows onRunning (prev RUNNING) for a child left RUNNING
    by an earlier pick, and a completed child answers its old status without being asked."""
    interp = BTInterpreter(BTDocument.single(manual(act("a"), act("b"))))
    snap = interp.initial()
    answers = {
        "m.pick_1": [2, 3, 2, 2],  # SUCCESS, FAILURE, SUCCESS, SUCCESS
        "m.pick_2": [2],
        "a": [1, 2],  # RUNNING, then SUCCESS
        "b": [2],
    }
    asked: list[tuple[str, int]] = []
    results = []
    for _ in range(4):
        snap = interp.begin_tick(snap)
        snap, step = interp.advance(snap)
        while isinstance(step, LeafRequest):
            asked.append((step.node.label, step.prev))
            snap, step = interp.advance(snap, answers[step.node.label].pop(0))
        assert isinstance(step, TickDone)
        results.append(step.status)
    assert asked == [
        ("m.pick_1", IDLE),
        ("a", IDLE),  # onStart
        ("m.pick_1", IDLE),  # a choice keeps no status
        ("m.pick_2", IDLE),
        ("b", IDLE),
        ("m.pick_1", IDLE),
        ("a", RUNNING),  # onRunning: a was never halted
        ("m.pick_1", IDLE),
        # a completed with SUCCESS and was never reset: ticked again it returns SUCCESS unasked
    ]
    assert results == [1, 2, 2, 2]


def test_manual_repeat_last_selection_asks_once_then_reticks_the_same_child() -> None:
    tree = manual(act("a"), act("b"), repeat_last_selection="true")
    # two children and repeat: one question (pick_1), its "no" picks child 2
    trace = run(tree, 3, m__pick_1="failure", b="running running success")
    assert trace == [
        (["m.pick_1=failure", "b=running"], "RUNNING"),
        (["b=running"], "RUNNING"),
        (["b=success"], "SUCCESS"),
    ]


def test_manual_repeat_last_selection_survives_a_halt() -> None:
    """previously_executed_idx_ is never reset (manual_node.cpp's halt() keeps it)."""
    root = BTNode(
        "ReactiveSequence",
        NodeKind.CONTROL,
        children=[
            BTNode("Cond", NodeKind.CONDITION, name="ok"),
            manual(act("a"), act("b"), repeat_last_selection="1"),
        ],
    )
    trace = run(root, 3, ok="success failure success", m__pick_1="success", a="running running")
    assert trace == [
        (["ok=success", "m.pick_1=success", "a=running"], "RUNNING"),
        (["ok=failure"], "FAILURE"),  # the ManualSelector is halted, a with it
        (["ok=success", "a=running"], "RUNNING"),  # no question: a again, from onStart
    ]


def test_manual_without_children_the_person_picks_a_status() -> None:
    tree = BTNode("Sequence", NodeKind.CONTROL, children=[manual(name="you"), act("after")])
    trace = run(
        tree,
        3,
        you__pick_SUCCESS="success failure failure",
        you__pick_FAILURE="failure failure",
        after="success",
    )
    assert trace == [
        (["you.pick_SUCCESS=success", "after=success"], "SUCCESS"),
        (["you.pick_SUCCESS=failure", "you.pick_FAILURE=failure"], "RUNNING"),
        (["you.pick_SUCCESS=failure", "you.pick_FAILURE=failure"], "RUNNING"),
    ]


def test_manual_repeat_last_selection_from_the_blackboard_or_garbage_is_refused() -> None:
    with pytest.raises(InputError, match="blackboard"):
        BTInterpreter(BTDocument.single(manual(act("a"), repeat_last_selection="{flag}")))
    with pytest.raises(InputError, match="not a boolean"):
        BTInterpreter(BTDocument.single(manual(act("a"), repeat_last_selection="maybe")))


def test_manual_reader_warns_that_btcpp_refuses_a_childless_control() -> None:
    warnings: list[str] = []
    loads(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><ManualSelector name="x"/>'
        "</BehaviorTree></root>",
        "btcpp",
        warnings=warnings,
    )
    assert any("4.8.2" in w and "without children" in w for w in warnings)


TREES = {
    "statuses_and_children": """<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence>
      <Check/><ManualSelector name="pick"><Go name="g1"/><Go name="g2"/>
      <ManualSelector name="inner"/></ManualSelector><Done/></Sequence></BehaviorTree></root>""",
    "repeat": """<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><Check/>
      <ManualSelector name="pick" repeat_last_selection="true"><Go name="g1"/><Go name="g2"/>
      </ManualSelector><Done/></Sequence></BehaviorTree></root>""",
    "repeat_one_child_reactive": """<root BTCPP_format="4"><BehaviorTree ID="M">
      <ReactiveSequence><IsOk/><ManualSelector name="pick" repeat_last_selection="1">
      <Go name="g1"/></ManualSelector></ReactiveSequence></BehaviorTree></root>""",
}


@pytest.mark.parametrize("name", sorted(TREES))
def test_manual_conversion_is_proven_by_both_checkers(name: str) -> None:
    if find_nusmv() is None:
        pytest.skip("NuSMV is not available (scripts/build_nusmv.sh)")
    source = api.load_text(TREES[name], "btcpp").model
    result = api.convert_model(source)
    report = api.verify_models(source, result.model, engine="both")
    assert report.equivalent, report


def test_manual_nusmv_tells_apart_a_tree_with_another_pick_set() -> None:
    """The encoding is not vacuous: with repeat_last_selection the statuses are not offered,
    so the FSM of the plain tree is not equivalent to it, in both checkers."""
    if find_nusmv() is None:
        pytest.skip("NuSMV is not available (scripts/build_nusmv.sh)")
    plain = api.load_text(TREES["statuses_and_children"], "btcpp").model
    other = TREES["statuses_and_children"].replace(
        '<ManualSelector name="pick">', '<ManualSelector name="pick" repeat_last_selection="1">'
    )
    repeated = api.load_text(other, "btcpp").model
    converted = api.convert_model(plain).model
    for engine in ("native", "nusmv"):
        assert not api.verify_models(repeated, converted, engine=engine).equivalent


def test_manual_corpus_example_converts_and_verifies() -> None:
    path = CORPUS / "bt" / "btcpp_tutorials" / "ex03_ncurses_manual_selector.xml"
    if not path.exists():
        pytest.skip("corpus not present")
    outcome = api.convert_file(path)
    assert outcome.equivalent is True
    assert any("without children" in w for w in outcome.warnings)
