"""NuSMV's encoding of the dispatch form (docs/nusmv.md, "The dispatch form"; issue 27 item 2)
agrees with the native pairing "FSM ~ dispatch BT (macro steps)" in both orders: seeded
generated machines (flat form §12 and hierarchical form §12a) are EQUIVALENT, one-change
mutants of the source FSM against the original tree and a hand-edited tree (a wrong
``_onSuccess`` digit) are NOT EQUIVALENT with the same verdict per property and a
counterexample named by the FSM's states; trees with nodes the encoding does not model are
refused naming the node. Real NuSMV (built by scripts/setup.sh)."""

from __future__ import annotations

import random

import pytest

from fsmbt.convert import convert
from fsmbt.convert.engines import nusmv_refusal
from fsmbt.formats import dumps, loads
from fsmbt.generate.generator import random_fsm
from fsmbt.generate.hierarchical import random_hfsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.verify import verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.nusmv import check
from fsmbt.verify.nusmv.binary import find_nusmv
from fsmbt.verify.report import Report, TraceStep

pytestmark = pytest.mark.skipif(find_nusmv() is None, reason="NuSMV not built (scripts/setup.sh)")


def _dispatch(fsm: FSM) -> BTDocument:
    tree = convert(fsm, style="dispatch").model
    assert isinstance(tree, BTDocument)
    return tree


def _agree(a: FSM | BTDocument, b: FSM | BTDocument) -> tuple[Report, Report]:
    native, smv = verify(a, b), check(a, b)
    assert smv.verdicts() == native.verdicts(), (native.verdicts(), smv.verdicts())
    return native, smv


def _names(fsm: FSM) -> set[str]:
    return set(flatten(fsm).states) | {"start"}


def _assert_decoded(report: Report, fsm: FSM, tree_side: str) -> None:
    """A failing property has a counterexample whose tree states are the FSM's state names
    (decoded from the digits), its last step where the two sides part."""
    failing = [p for p in report.properties.values() if not p.holds and p.counterexample]
    assert failing, report.verdicts()
    names = _names(fsm) | {s.name for s in fsm.states.values()}
    for prop in failing:
        trace = prop.counterexample
        assert trace is not None and trace[0].input is None
        for step in trace:
            state = step.result_state if tree_side == "result" else step.source_state
            assert state in names, (state, sorted(names))


SEEDS = range(8)


@pytest.mark.parametrize("seed", SEEDS)
def test_generated_machines_are_equivalent_both_orders(seed: int) -> None:
    rng = random.Random(seed)
    fsm = random_fsm(seed, n_states=rng.choice([3, 5, 8, 12]), start_event=seed % 2 == 0)
    tree = _dispatch(fsm)
    for a, b in ((fsm, tree), (tree, fsm)):
        native, smv = _agree(a, b)
        assert native.equivalent and smv.equivalent


@pytest.mark.parametrize("seed", range(4))
def test_hierarchical_form_is_equivalent_both_orders(seed: int) -> None:
    fsm = random_hfsm(seed, 10)
    result = convert(fsm, style="dispatch")
    assert result.stats["form"] == "hierarchical"  # SubTrees, ReactiveFallback per composite
    assert isinstance(result.model, BTDocument)
    for a, b in ((fsm, result.model), (result.model, fsm)):
        native, smv = _agree(a, b)
        assert native.equivalent and smv.equivalent


@pytest.mark.parametrize("seed", range(4))
def test_mutants_of_the_source_against_the_original_tree(seed: int) -> None:
    """Every operator's mutants (retargeted, dropped transition, changed action, flipped
    final), both orders: the same verdict per property; NOT EQUIVALENT ones with a decoded
    counterexample; at least one retargeted transition refuted per seed."""
    fsm = random_fsm(100 + seed, n_states=6 + seed, start_event=seed % 2 == 1)
    if seed % 3 == 2:
        fsm = flatten(random_hfsm(seed, 8))
    tree = _dispatch(fsm)
    refuted = 0
    for mutant in mutants(fsm, seed=seed, per_operator=2):
        assert isinstance(mutant.model, FSM)
        for a, b, side in ((mutant.model, tree, "result"), (tree, mutant.model, "source")):
            native, smv = _agree(a, b)
            if not native.equivalent:
                assert not smv.equivalent
                _assert_decoded(smv, fsm, side)
                refuted += mutant.operator == "retarget_transition"
    assert refuted >= 1


def test_hierarchical_tree_against_mutants_of_its_source() -> None:
    fsm = random_hfsm(7, 10)
    tree = _dispatch(fsm)
    flat = flatten(fsm)
    changed = 0
    for mutant in mutants(flat, seed=7, per_operator=1):
        assert isinstance(mutant.model, FSM)
        for a, b in ((mutant.model, tree), (tree, mutant.model)):
            native, smv = _agree(a, b)
            changed += not smv.equivalent
    assert changed >= 2


def _chain() -> FSM:
    fsm = FSM("chain")
    for name in "ABCDE":
        fsm.add_state(name, action=f"do_{name}", final=name == "E")
    fsm.initial = "A"
    for src, dst in zip("ABCD", "BCDE"):
        fsm.add_transition(src, f"go_{src}", dst)
    fsm.add_transition("C", "back", "A")
    return fsm


def test_a_wrong_on_success_digit_is_found_with_a_decoded_counterexample() -> None:
    fsm = _chain()
    text = dumps(_dispatch(fsm), "btcpp")
    right = "_onSuccess=\"fsm_d0:='c'\""  # the transition B -go_B-> C writes C's index
    assert text.count(right) == 1
    edited = loads(text.replace(right, "_onSuccess=\"fsm_d0:='d'\""), "btcpp")  # lands in D
    for a, b, side in ((fsm, edited, "result"), (edited, fsm, "source")):
        native, smv = _agree(a, b)
        assert not native.equivalent and not smv.equivalent
        _assert_decoded(smv, fsm, side)
        # a shortest counterexample (go_A, go_B, then an event C and index 'd' treat apart):
        # the same steps and the same decoded names as the native checker's (the index the
        # edited leaf writes is named by that leaf's state port, 'C')
        mine = smv.properties["completeness"].counterexample
        theirs = native.properties["completeness"].counterexample
        assert mine is not None and theirs is not None

        def steps(trace: list[TraceStep]) -> list[tuple[object, ...]]:
            return [
                (t.input, t.source_state, t.result_state, t.source_outputs, t.result_outputs)
                for t in trace
            ]

        assert steps(mine) == steps(theirs)
        assert [t.input for t in mine][:3] == [None, "go_A", "go_B"] and len(mine) == 4


def _wrap_first(doc: BTDocument, parent_type: str, wrapper: BTNode) -> BTDocument:
    """``doc`` with the first child of the first ``parent_type`` node wrapped in ``wrapper``."""
    for _tree, node in doc.nodes():
        if node.type == parent_type:
            wrapper.children = [node.children[0]]
            node.children[0] = wrapper
            return doc
    raise AssertionError(f"no {parent_type}")


@pytest.mark.parametrize(
    ("wrapper", "reason"),
    [
        (BTNode(type="Sequence", kind=NodeKind.CONTROL, name="seq"), "keep memory"),
        (BTNode(type="Inverter", kind=NodeKind.DECORATOR, name="inv"), "go on after"),
        (BTNode(type="Fallback", kind=NodeKind.CONTROL, name="fb"), "keep memory"),
    ],
)
def test_nodes_the_encoding_does_not_model_are_refused(wrapper: BTNode, reason: str) -> None:
    fsm = _chain()
    doc = _wrap_first(_dispatch(fsm), "KeepRunningUntilFailure", wrapper)
    with pytest.raises(UnsupportedError, match=reason) as caught:
        check(fsm, doc)
    assert wrapper.type in str(caught.value.element)
    refusal = nusmv_refusal(doc)
    assert wrapper.type in refusal and reason in refusal


def test_a_dispatch_tree_beside_another_tree_is_refused_by_nusmv() -> None:
    tree = _dispatch(_chain())
    with pytest.raises(UnsupportedError, match="against a state machine only"):
        verify(tree, tree, engine="nusmv")


def test_engine_both_confirms_the_native_verdict() -> None:
    fsm = _chain()
    report = verify(fsm, _dispatch(fsm), engine="both")
    assert report.equivalent and report.engine == "native+nusmv"
