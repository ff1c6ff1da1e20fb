"""Canonical leaf-execution states (``leaf_canonical``) against the faithful interpreter.

The reduction (docs/semantics.md §4a) claims that a canonical snapshot has the same future as
the faithful one. Checked three ways on random trees of the canonical class (its kinds read
from the node registry): lockstep random walks (same outputs, statuses, inputs after every
step, with and without ``loop``); the native checker proving the canonical machine equivalent
to the faithful one (every input sequence, not a sample); and the checker giving the same
verdict against the converted HFSM and its mutants on both machines. The canonical machine must
never have more states than the faithful one, and must have fewer on reactive trees.
"""

from __future__ import annotations

import random

import pytest
from hypothesis import given, settings

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics.leaf_canonical import canonical_rules, is_canonical_class
from fsmbt.semantics.leaf_machine import LeafMachine, explore
from fsmbt.semantics.nodes import all_nodes
from fsmbt.verify import native
from support.canonical_checks import lockstep, proved_equivalent, same_verdicts_against_hfsm
from support.random_trees import bt_documents, random_tree

#: The class, from the registry: controls ticked by the canonical rules that take any number of
#: children (the generator draws 1-4; RecoveryNode's two are drawn in
#: test_sem_leaf_canonical_nav2.py, with the decorators of the widened class), status maps,
#: SubTree.
CLASS_CONTROLS = tuple(
    sorted(
        n.name
        for n in all_nodes()
        if n.kind is NodeKind.CONTROL
        and n.handler in canonical_rules()
        and n.children is None
        and n.child_counts is None
    )
)
CLASS_DECORATORS = tuple(sorted(n.name for n in all_nodes() if n.result_map is not None)) + (
    "SubTree",
)
CLASS_LEAVES = ("Action", "Condition", "Action", "Condition", "AlwaysSuccess", "AlwaysFailure")


def class_tree(
    seed: int, max_nodes: int = 16, leaves: tuple[str, ...] = CLASS_LEAVES
) -> BTDocument:
    return random_tree(
        random.Random(seed),
        controls=CLASS_CONTROLS,
        decorators=CLASS_DECORATORS,
        leaves=leaves,
        max_nodes=max_nodes,
    )


def canonical_documents(count: int = 250) -> list[BTDocument]:
    docs = [class_tree(seed) for seed in range(count)]
    return [doc for doc in docs if not LeafMachine(doc).fast]  # plain trees have the table


def test_the_class_holds_reactive_memory_and_async_kinds() -> None:
    # the registry, not this test, decides the class; it must contain these families
    assert {"ReactiveSequence", "ReactiveFallback", "SequenceWithMemory"} <= set(CLASS_CONTROLS)
    assert "Parallel" not in CLASS_CONTROLS and "Inverter" in CLASS_DECORATORS


def test_the_class_is_stated_by_the_families_rules() -> None:
    # each family module marks its rules (FamilyRule.canonical); the class they make is the
    # one the rule lists in leaf_canonical.py held before the rules moved (issue 25)
    assert canonical_rules() == {
        "sequence",
        "reactive",
        "pipeline",
        "recovery",
        "round_robin",
        "simple_decorator",
        "repeat",
        "retry",
        "gated",
        "pass_through",
        "pass_through_keep",
    }


@pytest.mark.parametrize("loop", [False, True])
def test_canonical_and_faithful_agree_in_lockstep(loop: bool) -> None:
    rng = random.Random(4321 + loop)
    docs = canonical_documents()
    assert len(docs) >= 100
    for doc in docs:
        lockstep(doc, loop, rng)


@pytest.mark.parametrize("loop", [False, True])
def test_checker_proves_canonical_equivalent_to_faithful(loop: bool) -> None:
    """Every input sequence, not a sample: the product of the two machines is explored."""
    docs = canonical_documents(160)
    smaller = sum(proved_equivalent(doc, loop) for doc in docs)
    assert smaller > len(docs) // 8  # the reduction does merge states


@settings(max_examples=60, deadline=None)
@given(
    bt_documents(
        controls=CLASS_CONTROLS, decorators=CLASS_DECORATORS, leaves=CLASS_LEAVES, max_nodes=20
    )
)
def test_canonical_equivalent_on_hypothesis_trees(doc: BTDocument) -> None:
    try:
        canon = LeafMachine(doc)
    except UnsupportedError:
        return
    faithful = LeafMachine(doc, generic=True)
    assert native.check(faithful, canon, mode="lockstep").equivalent


def test_checker_verdict_same_on_both_machines() -> None:
    rng = random.Random(7)
    checked = caught = 0
    for seed in range(300, 340):
        # environment leaves only: the HFSM of an all-internal branch is an eventless cycle
        doc = class_tree(seed, max_nodes=24, leaves=("Action", "Condition"))
        if not LeafMachine(doc).canonical:
            continue
        pairs, failing = same_verdicts_against_hfsm(doc, rng)
        checked += pairs
        caught += failing
    assert checked >= 40 and caught > 0


def _wide_reactive(width: int) -> BTDocument:
    """ReactiveSequence of ReactiveFallbacks (condition, Sequence(action)): the shape of Nav2
    trees; the plain Sequence under a reactive node keeps it off the static table."""
    kids = [
        BTNode(
            "ReactiveFallback",
            NodeKind.CONTROL,
            children=[
                BTNode("Check", NodeKind.CONDITION, name=f"c{i}"),
                BTNode(
                    "Sequence",
                    NodeKind.CONTROL,
                    children=[BTNode("Do", NodeKind.ACTION, name=f"a{i}")],
                ),
            ],
        )
        for i in range(width)
    ]
    return BTDocument.single(BTNode("ReactiveSequence", NodeKind.CONTROL, children=kids))


def test_reactive_tree_has_one_state_per_leaf() -> None:
    doc = _wide_reactive(12)
    assert LeafMachine(doc).canonical
    canon, faithful = explore(LeafMachine(doc)), explore(LeafMachine(doc, generic=True))
    assert len(canon) == 24 + 2  # one per leaf, plus SUCCESS and FAILURE
    assert len(faithful) > 4 * len(canon)


def test_trees_outside_the_class_stay_faithful() -> None:
    root = BTNode(
        "Parallel",
        NodeKind.CONTROL,
        children=[BTNode("Do", NodeKind.ACTION, name="a"), BTNode("Do", NodeKind.ACTION, name="b")],
    )
    machine = LeafMachine(BTDocument.single(root))
    assert not machine.canonical and not is_canonical_class(machine.tree)
