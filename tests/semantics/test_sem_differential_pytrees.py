"""Differential test: our interpreter vs py_trees 2.6 on its subset of node types.

Sequence/ReactiveSequence/Fallback/ReactiveFallback (memory True/False), Inverter,
ForceSuccess/ForceFailure (FailureIsSuccess/SuccessIsFailure), AlwaysSuccess/AlwaysFailure and
inlined SubTrees. Same outcome script: same leaf ticks and root result on every tick.
"""

from __future__ import annotations

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics.bt_interpreter import BTRunner
from fsmbt.semantics.engines.pytrees_engine import PyTreesRunner
from support.random_trees import (
    PYTREES_CONTROLS,
    PYTREES_DECORATORS,
    OutcomeScript,
    random_tree,
)

TICKS = 8


@settings(max_examples=400, deadline=None, derandomize=True)
@given(st.integers(min_value=0, max_value=2**31 - 1))
def test_sem_pytrees_traces_match(seed: int) -> None:
    doc = random_tree(
        random.Random(seed),
        controls=PYTREES_CONTROLS,
        decorators=PYTREES_DECORATORS + ("SubTree",),
        max_nodes=16,
    )
    script = OutcomeScript(seed)
    ours = BTRunner(doc, script)
    theirs = PyTreesRunner(doc, script.fresh())
    for _ in range(TICKS):
        assert theirs.tick_once() == ours.tick_once(), seed


def test_sem_pytrees_rejects_types_it_lacks() -> None:
    leaf = BTNode("Act", NodeKind.ACTION, name="a")
    doc = BTDocument.single(BTNode("SequenceWithMemory", NodeKind.CONTROL, children=[leaf]))
    with pytest.raises(UnsupportedError, match="SequenceWithMemory"):
        PyTreesRunner(doc, OutcomeScript(0))
