"""The macro-step tree encoding (``verify/nusmv/encode_macro.py``; docs/nusmv.md, "Trees by
macro steps") against the native checker and the micro-step encoding, with real NuSMV.

24 seeded random trees of 5-40 leaves over Sequence, Fallback, ReactiveSequence, ReactiveFallback,
SequenceWithMemory, Inverter, ForceSuccess, ForceFailure and SubTree, each against its HFSM
(``bt_to_hfsm``) and against a one-transition mutant of the flattened HFSM: the macro
encoding's five verdicts equal the native checker's; a failing invariant's counterexample is
replayed on the native machines and differs there; on the small trees the micro-step
encoding's verdicts equal the macro encoding's on the four properties other than
reachability. Reachability is compared with the native checker only: the micro-step
encoding's state identity is every variable of the interpreter's snapshot, finer than the
native checker's canonical states (docs/semantics.md §4a), so a mutant can reach a "state"
alone there that the native checker counts as reached (seen on mutants of 5-10 leaves); the
macro encoding's identity is the canonical one, and it agrees with the native checker on every
pair here. Mutants of trees with a WithMemory index keep their trees to 12
leaves: their reachability is the frozen-copy spec (a transitive closure, ~12 s at 20 leaves;
docs/nusmv.md says the limit). ``FSMBT_TEST_SEED`` draws another sample.
"""

from __future__ import annotations

import copy
import os
import random

import pytest

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM
from fsmbt.verify import nusmv, verify
from fsmbt.verify.native import replay
from fsmbt.verify.nusmv import reach
from fsmbt.verify.nusmv.encode_macro import ENCODING_NAME, MacroBTEncoder, leaf_count
from fsmbt.verify.nusmv.smv import Symbols
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import REACHABILITY
from support.random_trees import TreeGenerator

SEED = int(os.environ.get("FSMBT_TEST_SEED", "27"))
CONTROLS = ("Sequence", "Fallback", "ReactiveSequence", "ReactiveFallback", "SequenceWithMemory")
DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "SubTree")
MICRO_UP_TO = 10  # leaves: the micro-step encoding is run beside it up to this size
INVARIANTS = ("completeness", "no_additional_behavior", "termination_consistency")


def _trees(rng: random.Random, count: int) -> list[BTDocument]:
    """``count`` random trees of 5-40 leaves of the macro class, sizes spread over the range:
    a root control over 1-3 trees of ``TreeGenerator`` (depth <= 5, one shared SubTree
    table)."""
    found: list[BTDocument] = []
    ranges = [(5, 8), (8, 12), (12, 18), (18, 25), (25, 40)]
    while len(found) < count:
        low, high = ranges[len(found) * len(ranges) // count]
        gen = TreeGenerator(rng, CONTROLS, DECORATORS, ("Action", "Condition"), 0)
        parts = []
        for _ in range(1 if high <= 12 else rng.randint(2, 3)):
            gen.counter, gen.max_nodes = 0, rng.choice([15, 25, 40])
            parts.append(gen.node(0))
        root = parts[0]
        if len(parts) > 1:
            root = BTNode(rng.choice(CONTROLS), NodeKind.CONTROL, children=parts)
        doc = BTDocument.single(root)
        for sub_id, sub_root in gen.subtrees.items():
            doc.trees[sub_id] = BehaviorTree(sub_id, sub_root)
        if low <= leaf_count(doc) <= high:
            found.append(doc)
    return found


def _mutant(flat: FSM, rng: random.Random) -> FSM:
    mutant = copy.deepcopy(flat)
    transition = mutant.transitions[rng.randrange(len(mutant.transitions))]
    transition.target = rng.choice([s for s in mutant.states if s != transition.target])
    return mutant


def _has_memory(doc: BTDocument) -> bool:
    stack = [doc.main.root, *(t.root for t in doc.trees.values())]
    while stack:
        node = stack.pop()
        if node.type == "SequenceWithMemory" and len(node.children) > 1:
            return True
        stack.extend(node.children)
    return False


def test_macro_agrees_with_native_and_micro(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED)
    failing = compared_micro = memory_listed = 0
    sizes = []
    for doc in _trees(rng, 24):
        leaves = leaf_count(doc)
        sizes.append(leaves)
        flat = flatten(bt_to_hfsm(doc).model)
        copy_report = nusmv.check(doc, flat, tree_encoding=nusmv.MACRO)
        assert copy_report.stats["nusmv_tree_encoding"] == ENCODING_NAME
        assert copy_report.equivalent, (leaves, copy_report.verdicts())
        assert copy_report.verdicts() == verify(doc, flat).verdicts()
        mutant = _mutant(flat, rng)
        native = verify(doc, mutant)
        macro = nusmv.check(doc, mutant, tree_encoding=nusmv.MACRO)
        assert macro.verdicts() == native.verdicts(), (leaves, native.verdicts())
        failing += not native.equivalent
        if not native.equivalent and macro.properties[REACHABILITY].holds:
            # a failing pair's reachability from NuSMV's listing, a tree with memory too (its
            # canonical memories listed through their copies, specs.listing_mirrors), never
            # the frozen-copy spec that gave up past ~12 leaves with memory
            assert macro.properties[REACHABILITY].detail == reach.STATES_DETAIL
            memory_listed += _has_memory(doc)
        source, result, _mode = machines_for(doc, mutant)
        for name in INVARIANTS:
            verdict = macro.properties[name]
            if not verdict.holds:
                assert verdict.counterexample, name
                inputs = [str(step.input) for step in verdict.counterexample[1:]]
                assert replay(source, result, inputs).differs, (name, inputs)
        if leaves <= MICRO_UP_TO:
            micro = nusmv.check(doc, mutant, tree_encoding=nusmv.MICRO)
            assert micro.stats["nusmv_tree_encoding"] != ENCODING_NAME
            mine = {k: v for k, v in macro.verdicts().items() if k != REACHABILITY}
            theirs = {k: v for k, v in micro.verdicts().items() if k != REACHABILITY}
            assert mine == theirs, leaves
            compared_micro += 1
    assert failing >= 5 and compared_micro >= 3, (failing, compared_micro, sizes)
    assert memory_listed >= 2, memory_listed
    assert max(sizes) >= 25 and min(sizes) <= 8, sizes


def _leaf(name: str, kind: NodeKind = NodeKind.ACTION) -> BTNode:
    return BTNode("Check" if kind is NodeKind.CONDITION else "Do", kind, name=name)


def test_wake_up_under_a_reactive_node(nusmv_binary, monkeypatch) -> None:
    """docs/semantics.md §3: ReactiveSequence(c, SequenceWithMemory(a, b)) ticks c a c b when
    c and a succeed (the WithMemory node's wake-up returns RUNNING, the reactive node restarts
    at c). A machine that goes on to b after a, without c again, is not equivalent; NuSMV says
    so with the native checker, and the tree's own HFSM is equivalent."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    memory = BTNode("SequenceWithMemory", NodeKind.CONTROL, children=[_leaf("a"), _leaf("b")])
    root = BTNode(
        "ReactiveSequence", NodeKind.CONTROL, children=[_leaf("c", NodeKind.CONDITION), memory]
    )
    doc = BTDocument.single(root)
    flat = flatten(bt_to_hfsm(doc).model)
    assert nusmv.check(doc, flat, tree_encoding=nusmv.MACRO).equivalent
    skipping = copy.deepcopy(flat)
    after_a = [
        t
        for t in skipping.transitions
        if skipping.states[t.source].action == "a" and t.event == "success"
    ]
    assert after_a
    b_state = next(n for n, s in skipping.states.items() if s.action == "b")
    after_a[0].target = b_state
    native = verify(doc, skipping)
    macro = nusmv.check(doc, skipping, tree_encoding=nusmv.MACRO)
    assert not native.equivalent
    assert macro.verdicts() == native.verdicts()


def test_other_kinds_are_refused_by_name_and_left_to_the_micro_steps(
    nusmv_binary, monkeypatch
) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    root = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[
            _leaf("a"),
            BTNode("Parallel", NodeKind.CONTROL, children=[_leaf("b"), _leaf("c")]),
        ],
    )
    doc = BTDocument.single(root)
    with pytest.raises(UnsupportedError, match="Parallel"):
        MacroBTEncoder(doc, "source", Symbols("in_"), Symbols("out_"), loop=False)
    flat = flatten(bt_to_hfsm(doc).model)
    with pytest.raises(UnsupportedError, match="Parallel"):
        nusmv.check(doc, flat, tree_encoding=nusmv.MACRO)
    report = nusmv.check(doc, flat)  # AUTO: the micro-step encoding
    assert report.stats["nusmv_tree_encoding"] == "micro-step tree (encode_bt)"
    assert report.equivalent


def test_loop_agrees_with_native(nusmv_binary, monkeypatch) -> None:
    """With ``loop`` (the root ticked again after its result, outputs ``(result, first
    leaf)``): the HFSMs ``bt_to_hfsm(loop=True)`` writes and their one-transition mutants, the
    five verdicts equal to the native checker's (trees the converter refuses with ``loop`` are
    left out, counted)."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED + 3)
    checked = failing = 0
    for doc in _trees(rng, 16):
        try:
            hfsm = bt_to_hfsm(doc, loop=True).model
        except UnsupportedError:
            continue
        flat = flatten(hfsm)
        for result in (flat, _mutant(flat, rng)):
            native = verify(doc, result, loop=True)
            macro = nusmv.check(doc, result, loop=True, tree_encoding=nusmv.MACRO)
            assert macro.verdicts() == native.verdicts(), (leaf_count(doc), native.verdicts())
            failing += not native.equivalent
        checked += 1
    assert checked >= 4 and failing >= 2, (checked, failing)
