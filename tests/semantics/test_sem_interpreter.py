"""Unit tests of the BehaviorTree.CPP v4 tick rules the interpreter implements.

Each rule is also checked against the real engine (behaviortreepy) where the engine can run it,
so a test documents a rule *and* proves it is BehaviorTree.CPP's.
"""

from __future__ import annotations

import pytest

from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.semantics.bt_interpreter import BTInterpreter, BTRunner, LeafRequest
from fsmbt.semantics.engines.btcpp_engine import BTCppRunner


def act(name: str) -> BTNode:
    return BTNode("Act", NodeKind.ACTION, name=name)


def cond(name: str) -> BTNode:
    return BTNode("Cond", NodeKind.CONDITION, name=name)


def ctl(kind: str, *children: BTNode, **attrs: str) -> BTNode:
    return BTNode(kind, NodeKind.CONTROL, attrs=dict(attrs), children=list(children))


def dec(kind: str, child: BTNode, **attrs: str) -> BTNode:
    return BTNode(kind, NodeKind.DECORATOR, attrs=dict(attrs), children=[child])


class Plan:
    """Outcomes per leaf label, consumed in order."""

    def __init__(self, **plans: str) -> None:
        self.plans = {k: v.split() for k, v in plans.items()}

    def __call__(self, node: BTNode, path: str) -> str:
        return self.plans[node.label].pop(0)


def both(root: BTNode, ticks: int, exactly_once: bool = False, **plans: str):
    """Run in the interpreter and in BehaviorTree.CPP; assert equal; return the records."""
    doc = BTDocument.single(root)
    ours = BTRunner(doc, Plan(**plans), exactly_once=exactly_once)
    theirs = BTCppRunner(doc, Plan(**plans), exactly_once=exactly_once)
    records = [ours.tick_once() for _ in range(ticks)]
    assert [theirs.tick_once() for _ in range(ticks)] == records
    return [([leaf[0] for leaf in r.leaves], r.result) for r in records]


def test_sem_tick_once_reticks_on_wake_up_but_exactly_once_does_not() -> None:
    """docs/semantics.md, 'Tick granularity': SequenceWithMemory emits a wake-up after a synchronous success."""
    tree = ctl("ReactiveSequence", cond("c"), ctl("SequenceWithMemory", act("a"), act("b")))
    plans = {"c": "success " * 6, "a": "success", "b": "running success"}
    assert both(tree, 2, **plans) == [(["c", "a", "c", "b"], "RUNNING"), (["c", "b"], "SUCCESS")]
    assert both(tree, 3, exactly_once=True, **plans) == [
        (["c", "a"], "RUNNING"),
        (["c", "b"], "RUNNING"),
        (["c", "b"], "SUCCESS"),
    ]


def test_sem_sequence_resumes_running_child_and_restarts_after_failure() -> None:
    tree = ctl("Sequence", act("a"), act("b"))
    assert both(tree, 3, a="success success", b="running failure success") == [
        (["a", "b"], "RUNNING"),
        (["b"], "FAILURE"),
        (["a", "b"], "SUCCESS"),
    ]


def test_sem_sequence_with_memory_keeps_its_index_after_failure() -> None:
    tree = ctl("SequenceWithMemory", act("a"), act("b"))
    result = both(tree, 2, exactly_once=True, a="success", b="failure success")
    assert result == [(["a"], "RUNNING"), (["b"], "FAILURE")]
    plain = both(ctl("Sequence", act("a"), act("b")), 2, a="success success", b="failure success")
    assert plain == [(["a", "b"], "FAILURE"), (["a", "b"], "SUCCESS")]


def test_sem_reactive_sequence_rechecks_conditions_and_halts_running_child() -> None:
    tree = ctl("ReactiveSequence", cond("c"), act("a"))
    assert both(tree, 2, c="success failure", a="running") == [
        (["c", "a"], "RUNNING"),
        (["c"], "FAILURE"),
    ]


def test_sem_parallel_thresholds_and_all_but_negative_values() -> None:
    tree = ctl("Parallel", act("a"), act("b"), act("c"), success_count="-2", failure_count="2")
    # "-2" = all but one: two successes suffice
    assert both(tree, 1, a="success", b="running", c="success") == [(["a", "b", "c"], "SUCCESS")]
    assert both(tree, 2, a="failure", b="running running", c="running failure") == [
        (["a", "b", "c"], "RUNNING"),
        (["b", "c"], "FAILURE"),
    ]


def test_sem_parallel_all_counts_failures() -> None:
    tree = ctl("ParallelAll", act("a"), act("b"), max_failures="2")
    assert both(tree, 2, a="failure", b="running success") == [
        (["a", "b"], "RUNNING"),
        (["b"], "SUCCESS"),
    ]


def test_sem_run_once_skips_afterwards() -> None:
    tree = dec("Repeat", ctl("Sequence", dec("RunOnce", act("a")), act("b")), num_cycles="2")
    assert both(tree, 1, a="success", b="success success") == [(["a", "b", "b"], "SUCCESS")]


def test_sem_retry_and_repeat_counters() -> None:
    assert both(
        dec("RetryUntilSuccessful", act("a"), num_attempts="2"), 1, a="failure failure"
    ) == [(["a", "a"], "FAILURE")]
    assert both(dec("Repeat", act("a"), num_cycles="3"), 1, a="success success failure") == [
        (["a", "a", "a"], "FAILURE")
    ]


def test_sem_stateful_action_keeps_a_stale_status_under_while_do_else() -> None:
    """An action ticked while still SUCCESS returns it without asking (StatefulActionNode)."""
    tree = ctl("WhileDoElse", act("cond_action"), act("body"))
    assert both(tree, 2, cond_action="success", body="running success") == [
        (["cond_action", "body"], "RUNNING"),
        (["body"], "SUCCESS"),
    ]


def test_sem_subtree_is_expanded() -> None:
    doc = BTDocument.single(
        ctl("Sequence", BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Sub"}), act("b"))
    )
    doc.trees["Sub"] = BehaviorTree("Sub", ctl("Fallback", cond("c"), act("a")))
    record = BTRunner(doc, Plan(c="failure", a="success", b="success")).tick_once()
    assert [leaf[:2] for leaf in record.leaves] == [("c", "0/0/0"), ("a", "0/0/1"), ("b", "1")]
    assert record.result == "SUCCESS"


@pytest.mark.parametrize(
    "node",
    [
        dec("Delay", act("a"), delay_msec="10"),
        dec("Timeout", act("a"), msec="10"),
        BTNode("Sleep", NodeKind.ACTION, attrs={"msec": "5"}),
        ctl("MyCustomControl", act("a")),
        dec("MyCustomDecorator", act("a")),
        BTNode("Act", NodeKind.ACTION, name="x", attrs={"_skipIf": "flag"}),
        dec("Repeat", act("a"), num_cycles="{n}"),
    ],
)
def test_sem_unsupported_nodes_are_rejected_with_their_location(node: BTNode) -> None:
    node.location = SourceLocation("tree.xml", 7, 3)
    with pytest.raises(UnsupportedError) as info:
        BTInterpreter(BTDocument.single(node))
    assert "tree.xml:7:3" in str(info.value) and node.type in str(info.value)


def test_sem_invalid_trees_are_input_errors() -> None:
    with pytest.raises(InputError, match="unknown tree"):
        BTInterpreter(BTDocument.single(BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "X"})))
    doc = BTDocument.single(BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "MainTree"}))
    with pytest.raises(UnsupportedError, match="recursion"):
        BTInterpreter(doc)
    with pytest.raises(InputError, match="threshold"):
        BTInterpreter(BTDocument.single(ctl("Parallel", act("a"), success_count="3")))


def test_sem_deep_tree_needs_no_recursion() -> None:
    node = act("leaf")
    for _ in range(100_000):
        node = dec("Inverter", node)
    record = BTRunner(BTDocument.single(node), Plan(leaf="success")).tick_once()
    assert record.result == "SUCCESS" and record.leaves[0][0] == "leaf"


def test_sem_snapshots_are_hashable_and_replayable() -> None:
    interp = BTInterpreter(BTDocument.single(ctl("Sequence", act("a"), act("b"))))
    snap, event = interp.advance(interp.begin_tick(interp.initial()))
    assert isinstance(event, LeafRequest) and event.node.label == "a"
    again, event2 = interp.advance(snap, 2)  # SUCCESS: b is next
    replay, event3 = interp.advance(snap, 2)
    assert hash(again) == hash(replay) and again == replay and event2 == event3
