"""The fast leaf-execution machine (``leaf_fast``) against the interpreter path of ``LeafMachine``.

Differential: for plain Sequence/Fallback trees both paths must give the same outputs, statuses
and inputs on random outcome walks (lockstep, with and without ``loop``), and the native checker
must give the same verdict against the converted HFSM and against mutated HFSMs.
"""

from __future__ import annotations

import random

import pytest

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.generate import random_bt
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.leaf_fast import is_plain_tree
from fsmbt.semantics.leaf_machine import LeafMachine
from fsmbt.verify import native
from fsmbt.verify.mutations import mutants
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import REACHABILITY
from support.canonical_checks import walk_alike
from support.random_trees import random_tree

PLAIN_SEEDS = range(200)
PLAIN_TREE_SEEDS = range(150)  # random_trees: Sequence/Fallback + SubTree, tiny trees
WALK_STEPS = 80


def plain_random_tree(seed: int) -> BTDocument:
    return random_tree(
        random.Random(seed),
        controls=("Sequence", "Fallback"),
        decorators=("SubTree",),
        leaves=("Action", "Condition"),
    )


def plain_documents() -> list[BTDocument]:
    docs = [random_bt(seed=seed, extended=False) for seed in PLAIN_SEEDS]
    docs += [plain_random_tree(seed) for seed in PLAIN_TREE_SEEDS]
    return docs


def lockstep(doc: BTDocument, loop: bool, rng: random.Random) -> None:
    fast = LeafMachine(doc, loop=loop)
    slow = LeafMachine(doc, loop=loop, generic=True)
    assert fast.fast and not slow.fast
    walk_alike(fast, slow, rng, WALK_STEPS)


@pytest.mark.parametrize("loop", [False, True])
def test_fast_and_generic_agree_in_lockstep(loop: bool) -> None:
    rng = random.Random(1234 + loop)
    docs = plain_documents()
    assert len(docs) >= 300
    for doc in docs:
        lockstep(doc, loop, rng)


#: Reachability speaks about *states* ("every source state is reached faithfully"), and the
#: interpreter path splits one leaf into several snapshots (a running leaf, or one reached after
#: different siblings finished, differs in node statuses) where the fast path has one state per
#: leaf: a mutant that breaks one way into a leaf fails it on the generic path only. The overall
#: verdict is trace-level (same inputs, outputs and statuses after every input sequence), so it,
#: and the other four properties with their counterexamples, must be identical.
STATE_LEVEL = REACHABILITY


def _summary(report) -> dict:
    """The verdict and each trace-level property's truth with its counterexample's trace."""
    out: dict = {"equivalent": report.equivalent}
    for name, prop in report.properties.items():
        if name == STATE_LEVEL:
            continue
        trace = None
        if prop.counterexample is not None:
            trace = [
                (
                    s.input,
                    tuple(s.source_outputs),
                    tuple(s.result_outputs),
                    s.source_status,
                    s.result_status,
                )
                for s in prop.counterexample
            ]
        out[name] = (prop.holds, trace)
    return out


def _verdicts(doc: BTDocument, result, loop: bool) -> tuple[dict, dict]:
    source, target, mode = machines_for(doc, result, loop=loop)
    assert isinstance(source, LeafMachine) and source.fast
    generic = LeafMachine(doc, loop=loop, generic=True)
    return (
        _summary(native.check(source, target, mode="lockstep")),
        _summary(native.check(generic, target, mode="lockstep")),
    )


@pytest.mark.parametrize("loop", [False, True])
def test_checker_verdict_same_on_both_paths(loop: bool) -> None:
    rng = random.Random(99 + loop)
    checked = mutated_failures = 0
    for seed in range(40):
        doc = random_bt(seed=seed, extended=False, max_nodes=30)
        hfsm = bt_to_hfsm(doc, loop=loop).model
        fast, generic = _verdicts(doc, hfsm, loop)
        assert fast == generic
        assert fast["equivalent"]  # the converter is correct
        for mutant in mutants(hfsm, seed=rng.randrange(1000), per_operator=1):
            fast, generic = _verdicts(doc, mutant.model, loop)
            assert fast == generic, mutant.description
            mutated_failures += not fast["equivalent"]
            checked += 1
    assert checked >= 40 and mutated_failures > 0  # the mutants do catch something


def _leaf(name: str, kind: NodeKind = NodeKind.ACTION) -> BTNode:
    return BTNode("Act", kind, name=name)


@pytest.mark.parametrize(
    "root",
    [
        BTNode(
            "ReactiveSequence",
            NodeKind.CONTROL,
            children=[
                _leaf("a"),
                BTNode("Sequence", NodeKind.CONTROL, children=[_leaf("b"), _leaf("c")]),
            ],
        ),
        BTNode("SequenceWithMemory", NodeKind.CONTROL, children=[_leaf("a"), _leaf("b")]),
        BTNode(
            "Sequence",
            NodeKind.CONTROL,
            children=[
                BTNode(
                    "Repeat", NodeKind.DECORATOR, attrs={"num_cycles": "2"}, children=[_leaf("a")]
                ),
                _leaf("b"),
            ],
        ),
        BTNode(
            "Fallback",
            NodeKind.CONTROL,
            children=[_leaf("a"), BTNode("AlwaysSuccess", NodeKind.ACTION)],
        ),
        BTNode("Parallel", NodeKind.CONTROL, children=[_leaf("a"), _leaf("b")]),
    ],
    ids=["plain-under-reactive", "with-memory", "loop-decorator", "always-success", "parallel"],
)
def test_trees_outside_the_class_take_the_generic_path(root: BTNode) -> None:
    assert not LeafMachine(BTDocument.single(root)).fast


def test_plain_trees_take_the_fast_path() -> None:
    assert LeafMachine(BTDocument.single(_leaf("only"))).fast
    assert all(LeafMachine(doc).fast for doc in plain_documents()[::25])


def test_deep_tree_builds_without_recursion() -> None:
    """100 000 nested Sequences (alternating with Fallbacks): O(N) tables, no recursion."""
    depth = 100_000
    node = _leaf("bottom")
    for i in range(depth):
        node = BTNode(
            "Sequence" if i % 2 else "Fallback",
            NodeKind.CONTROL,
            children=[node, _leaf(f"x{i}", NodeKind.CONDITION)],
        )
    machine = LeafMachine(BTDocument.single(node))
    assert machine.fast
    state, outputs = machine.start()
    assert outputs == ("bottom",)
    # bottom fails: its Fallback parent (i = 0) goes on to x0
    state, outputs = machine.step(state, "failure")
    assert outputs == ("x0",)


# -- the static table widened: reactive nodes over reactive/plain-free subtrees, status maps ----
STATIC_CONTROLS = ("Sequence", "Fallback", "ReactiveSequence", "ReactiveFallback")
STATIC_DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "SubTree")


def static_documents(count: int = 400) -> list[BTDocument]:
    docs = [
        random_tree(
            random.Random(10_000 + seed),
            controls=STATIC_CONTROLS,
            decorators=STATIC_DECORATORS,
            leaves=("Action", "Condition"),
            max_nodes=18,
        )
        for seed in range(count)
    ]
    return [
        doc for doc in docs if LeafMachine(doc).fast and not is_plain_tree(LeafMachine(doc).tree)
    ]


@pytest.mark.parametrize("loop", [False, True])
def test_static_reactive_tables_agree_in_lockstep(loop: bool) -> None:
    rng = random.Random(777 + loop)
    docs = static_documents()
    assert len(docs) >= 60
    for doc in docs:
        lockstep(doc, loop, rng)


@pytest.mark.parametrize("loop", [False, True])
def test_checker_proves_static_reactive_tables_equivalent(loop: bool) -> None:
    """Every input sequence: the product of the table machine and the faithful one."""
    for doc in static_documents(200):
        report = native.check(
            LeafMachine(doc, loop=loop, generic=True), LeafMachine(doc, loop=loop), mode="lockstep"
        )
        assert report.equivalent, report.verdicts()


def test_reactive_restart_goes_to_the_topmost_reactive_first_leaf() -> None:
    inner = BTNode(
        "ReactiveFallback",
        NodeKind.CONTROL,
        children=[_leaf("c", NodeKind.CONDITION), _leaf("run")],
    )
    root = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[
            _leaf("first"),
            BTNode(
                "ReactiveSequence",
                NodeKind.CONTROL,
                children=[_leaf("guard", NodeKind.CONDITION), inner],
            ),
        ],
    )
    machine = LeafMachine(BTDocument.single(root))
    assert machine.fast
    state, outputs = machine.start()
    assert outputs == ("first",)
    state, outputs = machine.step(state, "success")
    assert outputs == ("guard",)
    state, outputs = machine.step(state, "success")
    assert outputs == ("c",)
    state, outputs = machine.step(state, "failure")
    assert outputs == ("run",)
    # running: the plain root resumes its child 1, the ReactiveSequence restarts at 'guard'
    state, outputs = machine.step(state, "running")
    assert outputs == ("guard",)
