"""NuSMV and the native checker agree on all five properties (issue 5, item 5).

Pairs: hand-built trees over every encoded node type, generated pairs (random FSMs -> LEBT,
random BTs -> FSM, both loop modes), and the mutation suite's mutants of each. Pairs the NuSMV
encoding rejects (``UnsupportedError``, docs/nusmv.md) or the converters cannot convert are
counted apart. ``FSMBT_NUSMV_PAIRS`` sets how many generated pairs run (default 300: with the
attached/alone product and ``-mono`` a small pair costs ~0.3 s of NuSMV); ``FSMBT_NUSMV_EXAMPLES=1``
adds examples/ (the paper's A-J LEBT alone takes ~50 s in NuSMV, the robot BT ~8 s).
"""

from __future__ import annotations

import os
import random
from pathlib import Path

import pytest

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError, UnsupportedError
from fsmbt.verify import verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.nusmv import check

REPO = Path(__file__).resolve().parents[2]
PAIRS = int(os.environ.get("FSMBT_NUSMV_PAIRS", "300"))
MUTATED = 4  # generated pairs whose mutants are checked too (the hand-built ones all are)
CONTROLS = ("Sequence", "Fallback", "ReactiveSequence", "ReactiveFallback",
            "SequenceWithMemory")
DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "KeepRunningUntilFailure")


def _leaf(name: str, condition: bool = False) -> BTNode:
    return BTNode(name, NodeKind.CONDITION if condition else NodeKind.ACTION, name=name)


def _node(kind: str, *children: BTNode) -> BTNode:
    node_kind = NodeKind.DECORATOR if kind in DECORATORS else NodeKind.CONTROL
    return BTNode(kind, node_kind, children=list(children))


def _random_bt(rng: random.Random, leaves: int) -> BTDocument:
    counter = iter(range(1000))

    def build(budget: int, depth: int) -> BTNode:
        if budget <= 1 or depth > 3:
            name = f"l{next(counter)}"
            return _leaf(name, rng.random() < 0.4)
        if rng.random() < 0.2:
            return _node(rng.choice(DECORATORS[:3]), build(budget, depth + 1))
        parts = rng.randint(2, min(3, budget))
        sizes = [budget // parts] * parts
        sizes[0] += budget - sum(sizes)
        return _node(rng.choice(CONTROLS), *(build(s, depth + 1) for s in sizes))

    return BTDocument.single(build(leaves, 0))


def _hand_built() -> list[BTDocument]:
    a, b, c, d = (_leaf("a", True), _leaf("b"), _leaf("c"), _leaf("d"))
    trees = [
        _node("Sequence", a, _node("Fallback", b, c)),
        _node("ReactiveSequence", _leaf("a", True), _node("SequenceWithMemory", _leaf("b"),
                                                           _leaf("c"))),
        _node("ReactiveFallback", _leaf("a", True), _node("Inverter", _leaf("b")), _leaf("c")),
        _node("Fallback", _node("SequenceWithMemory", _leaf("a"), _leaf("b")), _leaf("c")),
        _node("Sequence", _node("ForceSuccess", _leaf("a")), _node("ForceFailure", _leaf("b")),
              d),
        _node("KeepRunningUntilFailure", _node("Sequence", _leaf("a", True), _leaf("b"))),
        _node("AsyncSequence", _leaf("a"), _leaf("b")),
    ]
    docs = [BTDocument.single(t) for t in trees]
    sub = BTDocument.single(_node("Sequence", _leaf("x", True),
                                  BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Inner"})))
    from fsmbt.model.bt import BehaviorTree

    sub.trees["Inner"] = BehaviorTree("Inner", _node("Fallback", _leaf("y"), _leaf("z")))
    docs.append(sub)
    return docs


def _pairs():
    """(label, source, result, loop) for every pair the test compares."""
    from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
    from fsmbt.convert.lebt import fsm_to_lebt
    from fsmbt.generate.generator import random_fsm

    def bt_pairs(label, doc, loop, with_mutants=True):
        try:
            fsm = bt_to_hfsm(doc, loop=loop).model
        except FsmbtError:
            return
        yield label, doc, fsm, loop
        if not with_mutants:
            return
        for m in mutants(fsm, per_operator=1)[:1]:
            yield f"{label}/fsm-{m.operator}", doc, m.model, loop
        for m in mutants(doc, per_operator=1)[:2]:
            yield f"{label}/bt-{m.operator}", m.model, fsm, loop

    def fsm_pairs(label, fsm, with_mutants=True):
        try:
            bt = fsm_to_lebt(fsm).model
        except FsmbtError:
            return
        yield label, fsm, bt, False
        if not with_mutants:
            return
        for m in mutants(bt, per_operator=1)[:2]:
            yield f"{label}/lebt-{m.operator}", fsm, m.model, False
        for m in mutants(fsm, per_operator=1)[:1]:
            yield f"{label}/fsm-{m.operator}", m.model, bt, False

    for i, doc in enumerate(_hand_built()):
        for loop in (False, True):
            yield from bt_pairs(f"hand{i}-loop{int(loop)}", doc, loop)
    rng = random.Random(5)
    made = 0
    while made < PAIRS:
        if made % 2 == 0:
            fsm = random_fsm(rng.randrange(10**9), min_states=2, max_states=4)
            group = list(fsm_pairs(f"gen-fsm{made}", fsm, made < MUTATED))
        else:
            group = list(bt_pairs(f"gen-bt{made}", _random_bt(rng, rng.randint(2, 4)),
                                  rng.random() < 0.5, made < MUTATED))
        made += 1
        yield from group
    if os.environ.get("FSMBT_NUSMV_EXAMPLES") == "1":
        from fsmbt.formats.registry import read_model

        for path in sorted((REPO / "examples").iterdir()):
            try:
                model = read_model(path)
            except FsmbtError:
                continue
            if isinstance(model, BTDocument):
                yield from bt_pairs(path.name, model, False)
            else:
                yield from fsm_pairs(path.name, model)


def test_engines_agree_on_all_five_properties(nusmv_binary):
    agreed, unsupported, disagreements = 0, 0, []
    failing_verdicts = 0
    for label, source, result, loop in _pairs():
        try:
            smv = check(source, result, loop=loop)
        except UnsupportedError:
            unsupported += 1
            continue
        native = verify(source, result, loop=loop)
        if smv.verdicts() != native.verdicts():
            disagreements.append((label, native.verdicts(), smv.verdicts()))
        else:
            agreed += 1
            failing_verdicts += sum(not v for v in native.verdicts().values())
    print(f"\nNuSMV/native agreement: {agreed} pairs agree, {len(disagreements)} disagree, "
          f"{unsupported} unsupported by the encoding; {failing_verdicts} failing verdicts")
    assert not disagreements, disagreements[:5]
    assert agreed >= PAIRS
    assert failing_verdicts > 0  # the mutants really exercise failing properties


def test_engines_agree_on_the_robot_example_and_a_mutant(nusmv_binary):
    """The paper's robot BT and its HFSM (about 8 s of NuSMV), plus one wrong HFSM: the two
    engines give the same five verdicts on both. The A-J LEBT (about 50 s) stays behind
    FSMBT_NUSMV_EXAMPLES=1."""
    from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
    from fsmbt.formats.registry import read_model

    doc = read_model(REPO / "examples" / "robot_bt.xml")
    hfsm = bt_to_hfsm(doc).model
    wrong = next(m.model for m in mutants(hfsm, per_operator=1) if m.operator == "retarget_transition")
    for result, expected in ((hfsm, True), (wrong, False)):
        smv, native = check(doc, result), verify(doc, result)
        assert smv.verdicts() == native.verdicts()
        assert native.equivalent is expected
