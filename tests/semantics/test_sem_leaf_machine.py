"""The leaf-execution machine (docs/semantics.md, 'The leaf-execution machine'): exploration, loop mode, and agreement with the
real engine: random walks through the machine replayed in BehaviorTree.CPP."""

from __future__ import annotations

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.bt_interpreter import BTRuntimeError
from fsmbt.semantics.engines.btcpp_engine import BTCppRunner
from fsmbt.semantics.leaf_machine import (
    LIVELOCK,
    LeafMachine,
    RootResult,
    StateLimitError,
    explore,
    leaf_label,
)
from fsmbt.semantics.machine import FINAL, RUNNING
from support.random_trees import random_tree


def act(name: str) -> BTNode:
    return BTNode("Act", NodeKind.ACTION, name=name)


def cond(name: str) -> BTNode:
    return BTNode("Cond", NodeKind.CONDITION, name=name)


def seq_fallback() -> BTDocument:
    return BTDocument.single(
        BTNode(
            "Sequence",
            NodeKind.CONTROL,
            children=[
                cond("c"),
                BTNode("Fallback", NodeKind.CONTROL, children=[act("a"), act("b")]),
            ],
        )
    )


def test_sem_leaf_machine_explores_a_small_tree() -> None:
    machine = LeafMachine(seq_fallback())
    explored = explore(machine)
    assert explored.start_outputs == ("c",)
    assert machine.inputs(explored.start) == ("success", "failure")
    after_c, out = explored.transitions[explored.start]["success"]
    assert out == ("a",) and machine.inputs(after_c) == ("success", "failure", "running")
    assert explored.transitions[explored.start]["failure"] == (RootResult("FAILURE"), ("FAILURE",))
    # a running leaf under a non-reactive parent is ticked again
    resumed, out = explored.transitions[after_c]["running"]
    assert out == ("a",) and machine.describe(resumed) == "a@1/0"
    finals = [s for s in explored.states if explored.statuses[s] == FINAL]
    assert {s.result for s in finals} == {"SUCCESS", "FAILURE"}
    graph = explored.to_networkx()
    assert graph.number_of_nodes() == len(explored)
    assert graph.number_of_edges() == sum(len(m) for m in explored.transitions.values())


def test_sem_loop_mode_outputs_result_then_first_leaf() -> None:
    machine = LeafMachine(seq_fallback(), loop=True)
    state, out = machine.start()
    state, out = machine.step(state, "failure")
    assert out == ("FAILURE", "c") and machine.status(state) == RUNNING
    explored = explore(machine)
    assert all(status == RUNNING for status in explored.statuses.values())


def test_sem_reactive_parent_restarts_at_its_first_child() -> None:
    doc = BTDocument.single(
        BTNode("ReactiveSequence", NodeKind.CONTROL, children=[cond("c"), act("a")])
    )
    machine = LeafMachine(doc)
    state, _ = machine.start()
    state, out = machine.step(state, "success")
    state, out = machine.step(state, "running")
    assert out == ("c",)


def test_sem_internal_leaves_are_not_observed_and_livelock_is_reported() -> None:
    doc = BTDocument.single(
        BTNode(
            "Sequence",
            NodeKind.CONTROL,
            children=[BTNode("AlwaysSuccess", NodeKind.ACTION), act("a")],
        )
    )
    assert LeafMachine(doc).start()[1] == ("a",)
    stuck = BTDocument.single(
        BTNode(
            "KeepRunningUntilFailure",
            NodeKind.DECORATOR,
            children=[BTNode("AlwaysSuccess", NodeKind.ACTION)],
        )
    )
    state, out = LeafMachine(stuck).start()
    assert out == (LIVELOCK,) and state == RootResult(LIVELOCK)


def test_sem_leaf_label_is_name_else_type() -> None:
    assert leaf_label(BTNode("MoveTo", NodeKind.ACTION, name="go")) == "go"
    assert leaf_label(BTNode("MoveTo", NodeKind.ACTION)) == "MoveTo"


def test_sem_explore_stops_at_the_state_limit() -> None:
    with pytest.raises(StateLimitError):
        explore(LeafMachine(seq_fallback()), max_states=2)


class _Replay:
    """Feeds BehaviorTree.CPP the outcomes chosen in the machine, in order; once they run out
    it records the leaf the engine asked for next and answers ``failure`` (the walk ends)."""

    def __init__(self, outcomes: list[str]) -> None:
        self.outcomes = list(outcomes)
        self.labels: list[str] = []
        self.exhausted_at: int | None = None

    def __call__(self, node: BTNode, path: str) -> str:
        if self.exhausted_at is None:
            self.labels.append(leaf_label(node))
        if not self.outcomes:
            if self.exhausted_at is None:
                self.exhausted_at = len(self.labels)
            return "failure"
        return self.outcomes.pop(0)


@settings(max_examples=150, deadline=None, derandomize=True)
@given(st.integers(min_value=0, max_value=2**31 - 1))
def test_sem_random_walks_replay_identically_in_btcpp(seed: int) -> None:
    """Walk the loop-mode machine with random outcomes; BehaviorTree.CPP (tickExactlyOnce,
    re-ticked while RUNNING) must tick the same leaves and return the same root results."""
    doc = random_tree(random.Random(seed), max_nodes=14)
    machine = LeafMachine(doc, loop=True)
    rng = random.Random(seed)
    state, outputs = machine.start()
    observed = list(outputs)
    chosen: list[str] = []
    errored = False
    for _ in range(25):
        inputs = machine.inputs(state)
        if not inputs:  # LIVELOCK: the engine would spin; nothing to replay beyond here
            break
        symbol = rng.choice(list(inputs))
        try:
            state, outputs = machine.step(state, symbol)
        except BTRuntimeError:  # BehaviorTree.CPP throws here too: compare up to it
            errored = True
            break
        chosen.append(symbol)
        observed.extend(outputs)
    livelock = LIVELOCK in observed
    if livelock:
        observed = observed[: observed.index(LIVELOCK)]
    replay = _Replay(chosen)
    engine = BTCppRunner(doc, replay, exactly_once=True)
    engine_seen: list[str] = []
    for _ in range(2_000):
        before = len(replay.labels)
        try:
            record = engine.tick_once()
        except RuntimeError:
            assert errored, seed
            break
        engine_seen.extend(replay.labels[before:])
        if replay.exhausted_at is not None:
            break  # this tick's result came after the walk ended
        if record.result != "RUNNING":
            engine_seen.append(record.result)
        if (livelock or errored) and not replay.outcomes and len(engine_seen) >= len(observed):
            break
    assert engine_seen[: len(observed)] == observed, seed
    assert len(engine_seen) >= len(observed)
