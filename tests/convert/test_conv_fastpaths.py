"""The converters' fast paths give exactly what the straightforward definitions give: the
one-pass inlining + compression vs ``compress(inline_subtrees(...))``, the leaf writer vs the
``fsmbt.semantics.lebt.spec`` classes, and the figures counted while building vs walking the result."""

from __future__ import annotations

import gc

from fsmbt.convert import convert
from fsmbt.convert.compress import compress, inline_and_compress, inline_subtrees, tree_depth
from fsmbt.convert.perf import gc_paused
from fsmbt.generate import random_bt, random_fsm
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE, GuardSpec, StateSpec
from support.conv_helpers import paper_aj_fsm


def _with_subtrees(seed: int) -> BTDocument:
    """A random BT whose first control child is moved into its own tree behind a SubTree."""
    doc = random_bt(seed, scenario="basic", extended=seed % 2 == 1, max_nodes=40)
    root = doc.main.root
    assert root is not None
    for index, child in enumerate(root.children):
        if child.kind is NodeKind.CONTROL:
            doc.trees["Inner"] = BehaviorTree("Inner", child)
            root.children[index] = BTNode(
                type="SubTree", kind=NodeKind.SUBTREE, attrs={"ID": "Inner"}
            )
            break
    return doc


def test_one_pass_preparation_equals_the_two_pass_definition() -> None:
    for seed in range(150):
        doc = _with_subtrees(seed)
        inlined = inline_subtrees(doc)
        expected = compress(inlined)
        got = inline_and_compress(doc)
        assert got.compression.root == expected.root, seed
        assert got.compression.depth_before == expected.depth_before == tree_depth(inlined)
        assert got.compression.depth_after == expected.depth_after
        assert got.compression.merged == expected.merged
        assert got.leaves == sum(1 for n in expected.root.walk() if n.is_leaf)


def test_leaf_ports_equal_the_spec_classes_and_counts_equal_a_walk() -> None:
    fsm = paper_aj_fsm()
    fsm.add_state("odd;na/me\\x")
    fsm.add_transition("B", "ev/;x", "odd;na/me\\x")
    models = [fsm] + [
        random_fsm(seed, scenario="game", min_states=2, max_states=30) for seed in range(60)
    ]
    for model in models:
        result = convert(model)
        root = result.model.main.root
        for node in root.walk():
            if node.type == GUARD_TYPE:
                assert GuardSpec.from_attrs(node.attrs).to_attrs() == node.attrs
            elif node.type == STATE_TYPE:
                assert StateSpec.from_attrs(node.attrs).to_attrs() == node.attrs
        assert result.stats["nodes"] == sum(1 for _ in root.walk())
        assert result.stats["depth"] == tree_depth(root)


def test_gc_paused_restores_the_callers_setting() -> None:
    assert gc.isenabled()
    with gc_paused():
        assert not gc.isenabled()
        with gc_paused():
            assert not gc.isenabled()
        assert not gc.isenabled()
    assert gc.isenabled()
    gc.disable()
    try:
        with gc_paused():
            pass
        assert not gc.isenabled()
    finally:
        gc.enable()
