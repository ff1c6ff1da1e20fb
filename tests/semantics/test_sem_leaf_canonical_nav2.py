"""Canonical states on trees with Nav2's kinds (``leaf_canonical``) against the faithful interpreter.

The widened class (docs/semantics.md §4a) adds PipelineSequence, RecoveryNode, RoundRobin, the
gated controllers (RateController & co, PathLongerOnApproach), GoalUpdater, Repeat and
RetryUntilSuccessful to the Sequence/Fallback families. These tests draw random trees over every
kind of the class (the kinds read from the node registry by their tick rule) and check: lockstep
random walks (same outputs, statuses, inputs after every step, with and without ``loop``); the
native checker proving the canonical machine equivalent to the faithful one (every input
sequence); the same checker verdict against converted HFSMs and their mutants; and that the
reduction really merges states on these kinds. The two Nav2 corpus trees of issue 12 are checked
the same way when the corpus is present.
"""

from __future__ import annotations

import random

import pytest

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.leaf_canonical import canonical_rules, is_canonical_class
from fsmbt.semantics.leaf_machine import LeafMachine
from fsmbt.semantics.nodes import all_nodes
from fsmbt.verify import native
from support.canonical_checks import lockstep, proved_equivalent, same_verdicts_against_hfsm
from support.corpus import CORPUS
from support.random_trees import LEAVES, TreeGenerator

#: Controls of the class, from the registry (the rule decides, not a list here).
CONTROLS = tuple(
    sorted(
        n.name for n in all_nodes() if n.kind is NodeKind.CONTROL and n.handler in canonical_rules()
    )
)
#: Decorators of the class whose gate (if any) does not return SKIPPED.
DECORATORS = tuple(
    sorted(
        n.name
        for n in all_nodes()
        if n.kind is NodeKind.DECORATOR
        and n.handler in canonical_rules()
        and (n.gate is None or n.gate.closed != "SKIPPED")
    )
)
NAV2 = ("PipelineSequence", "RecoveryNode", "RoundRobin", "RateController")


def test_the_class_holds_nav2_kinds() -> None:
    assert set(NAV2) <= set(CONTROLS) | set(DECORATORS)
    assert {"PathLongerOnApproach", "GoalUpdater", "RetryUntilSuccessful"} <= set(DECORATORS)
    assert "SkipUnlessUpdated" not in DECORATORS and "Parallel" not in CONTROLS


class _Nav2Generator(TreeGenerator):
    """Random trees over the class; Nav2's kinds are drawn twice as often (small, depth ≤ 5)."""

    def node(self, depth: int) -> BTNode:
        self.counter += 1
        rng = self.rng
        if depth >= 5 or self.counter >= self.max_nodes or rng.random() < 0.28:
            return self.leaf()
        if rng.random() < 0.35:
            kind = rng.choice(self.decorators)
            child = self.node(depth + 1)
            if kind == "SubTree":
                sub_id = f"Sub{len(self.subtrees)}"
                self.subtrees[sub_id] = child
                return BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": sub_id})
            attrs: dict[str, str] = {}
            if kind == "Repeat":
                attrs["num_cycles"] = str(rng.choice([0, 1, 2, -1]))
            elif kind == "RetryUntilSuccessful":
                attrs["num_attempts"] = str(rng.choice([0, 1, 2, -1]))
            spec = next(n for n in all_nodes() if n.name == kind)
            semantics = kind if spec.requires is not None else None
            return BTNode(
                kind, NodeKind.DECORATOR, attrs=attrs, children=[child], semantics=semantics
            )
        kind = rng.choice(self.controls)
        count = 2 if kind == "RecoveryNode" else rng.randint(1, 4)
        children = [self.node(depth + 1) for _ in range(count)]
        attrs = {}
        if kind == "RecoveryNode":
            attrs["number_of_retries"] = str(rng.choice([0, 1, 2]))
        elif kind == "RoundRobin":
            attrs["wrap_around"] = rng.choice(["true", "false"])
        return BTNode(kind, NodeKind.CONTROL, attrs=attrs, children=children)


def nav2_tree(seed: int, max_nodes: int = 16, leaves: tuple[str, ...] = LEAVES) -> BTDocument:
    controls = CONTROLS + NAV2[:3]
    decorators = DECORATORS + ("SubTree", "RateController")
    return _Nav2Generator(random.Random(seed), controls, decorators, leaves, max_nodes).document()


def nav2_documents(count: int, **kwargs: object) -> list[BTDocument]:
    """Seeded class trees that use at least one of Nav2's kinds and take the canonical path."""
    docs = []
    for seed in range(count):
        doc = nav2_tree(seed, **kwargs)  # type: ignore[arg-type]
        machine = LeafMachine(doc)
        types = {node.type for node in machine.tree.nodes}
        if machine.canonical and types & set(NAV2):
            docs.append(doc)
    return docs


@pytest.mark.parametrize("loop", [False, True])
def test_nav2_canonical_and_faithful_agree_in_lockstep(loop: bool) -> None:
    rng = random.Random(99 + loop)
    docs = nav2_documents(300)
    assert len(docs) >= 150
    for doc in docs:
        lockstep(doc, loop, rng)


@pytest.mark.parametrize("loop", [False, True])
def test_checker_proves_nav2_canonical_equivalent_to_faithful(loop: bool) -> None:
    """Every input sequence, not a sample: the product of the two machines is explored."""
    docs = nav2_documents(220)
    smaller = sum(proved_equivalent(doc, loop) for doc in docs)
    assert smaller > len(docs) // 4  # the reduction does merge states on these kinds


def test_larger_nav2_trees_proved_equivalent() -> None:
    """Bigger trees (up to 28 nodes) reach deeper interleavings of pipelines and gates."""
    docs = nav2_documents(60, max_nodes=28)
    assert len(docs) >= 25
    for doc in docs:
        canon, faithful = LeafMachine(doc, loop=True), LeafMachine(doc, loop=True, generic=True)
        assert native.check(faithful, canon, mode="lockstep").equivalent


def test_checker_verdict_same_on_both_machines() -> None:
    rng = random.Random(11)
    checked = caught = 0
    for doc in nav2_documents(80, max_nodes=20, leaves=("Action", "Condition")):
        pairs, failing = same_verdicts_against_hfsm(doc, rng)
        checked += pairs
        caught += failing
    assert checked >= 40 and caught > 0


def _action(name: str) -> BTNode:
    return BTNode(name, NodeKind.ACTION, name=name)


def test_a_pipeline_keeps_what_it_rereads() -> None:
    """Under a PipelineSequence a finished action is ticked again without a reset (it returns
    its old SUCCESS): that status is read and must survive, and so must the status of the
    RateController's child (not reset on completion). The running action's RUNNING is read by
    no one (re-ticking asks the environment either way), and the RateController is on the
    stack (asking its gate): its status comes back when it returns."""
    root = BTNode(
        "PipelineSequence",
        NodeKind.CONTROL,
        children=[
            _action("select"),
            BTNode(
                "RateController",
                NodeKind.DECORATOR,
                children=[_action("plan")],
                semantics="RateController",
            ),
            _action("follow"),
        ],
    )
    doc = BTDocument.single(root)
    canon = LeafMachine(doc, loop=True)
    assert canon.canonical
    state, _ = canon.start()  # about to tick "select"
    state, _ = canon.step(state, "success")  # "plan" (the first tick after IDLE is free)
    state, _ = canon.step(state, "success")  # "follow"
    state, outs = canon.step(state, "running")  # next tick: select keeps SUCCESS, gate asked
    assert outs == ("RateController.gate",)
    statuses = dict(state[0])  # type: ignore[index]
    ids = {node.label: node.id for node in canon.tree.nodes}
    assert statuses[ids["select"]] == statuses[ids["plan"]] == 2
    assert ids["follow"] not in statuses and ids["RateController"] not in statuses


def test_trees_outside_the_class_stay_faithful() -> None:
    root = BTNode(
        "RecoveryNode",
        NodeKind.CONTROL,
        children=[
            BTNode("RunOnce", NodeKind.DECORATOR, children=[_action("a")]),
            _action("b"),
        ],
    )
    machine = LeafMachine(BTDocument.single(root))
    assert not machine.canonical and not is_canonical_class(machine.tree)


NAV2_TREES = CORPUS / "bt" / "nav2"
ISSUE_12 = (
    "navigate_to_pose_w_replanning_goal_patience_and_recovery.xml",
    "navigate_w_routing_global_planning_and_control_w_recovery.xml",
)


@pytest.mark.skipif(not NAV2_TREES.is_dir(), reason="the corpus is not present (FSMBT_CORPUS)")
@pytest.mark.parametrize("name", ISSUE_12)
def test_issue_12_trees_take_the_canonical_path_and_agree(name: str) -> None:
    """The two Nav2 trees of issue 12 take the canonical path and agree with the faithful
    machine on random walks (state counts and the full product proof: benchmarks/bench_nav2.py)."""
    from fsmbt import api

    options = {
        "nodes": ["nav2"],
        "node_models": [str(NAV2_TREES / "models" / "nav2_tree_nodes.xml")],
    }
    doc = api.load(NAV2_TREES / name, options=options).model
    assert isinstance(doc, BTDocument)
    canon = LeafMachine(doc)
    assert canon.canonical
    rng = random.Random(5)
    for _ in range(20):
        lockstep(doc, False, rng)
