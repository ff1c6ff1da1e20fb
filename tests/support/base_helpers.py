"""Shared pieces of the baseline tests: generated sets, the converter, the checker."""

from __future__ import annotations

from fsmbt.convert.engines import converter_for
from fsmbt.generate.generator import random_bt, random_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.verify import verify

SCENARIOS = ("basic", "robot", "game")
SET_SIZE = 300


def convert(engine: str, model):
    return converter_for(engine, model)(model)


def generated_fsms(n: int = SET_SIZE):
    for i in range(n):
        yield i, random_fsm(seed=f"baseline-fsm-{i}", scenario=SCENARIOS[i % 3])


def generated_bts(n: int = SET_SIZE):
    for i in range(n):
        yield i, random_bt(seed=f"baseline-bt-{i}", scenario=SCENARIOS[i % 3])


def not_equivalent_seeds(engine: str, models) -> list[int]:
    failures = []
    for i, model in models:
        report = verify(model, convert(engine, model).model)
        if not report.equivalent:
            failures.append(i)
    return failures


def leaf(name: str, condition: bool = False) -> BTNode:
    return BTNode(type=name, kind=NodeKind.CONDITION if condition else NodeKind.ACTION)


def ctrl(kind: str, *children: BTNode) -> BTNode:
    return BTNode(type=kind, kind=NodeKind.CONTROL, children=list(children))


def plain_under_reactive() -> BTDocument:
    """ReactiveSequence(c1, Sequence(c2, a3)): after a3 runs, the next tick re-checks c1 and then
    RESUMES a3 (the plain Sequence remembers its running child) - memory one state per leaf
    cannot hold."""
    return BTDocument.single(
        ctrl("ReactiveSequence", leaf("c1", True), ctrl("Sequence", leaf("c2", True), leaf("a3")))
    )
