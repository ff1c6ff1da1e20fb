"""NuSMV against the native checker on the state-variable trees of the BSD and CHDS baselines
(issue 27, item 2; fsmbt.verify.nusmv.encode_sv, docs/nusmv.md "State-variable trees").

Seeded random FSMs (``generate.random_fsm``) converted with ``--style bsd`` and ``--style
chds``, each against its own conversion (equivalent) and against the conversion of its
one-transition mutants (``verify.mutations``: ``retarget_transition``, ``drop_transition``): every
one of the five verdicts must be the same on both engines, and at least one pair per style must
be not equivalent (so the agreement is not only on "equivalent"). A hand-written tree whose
macro step never settles must get the native checker's livelock ``InputError`` from NuSMV too;
one that runs more actions in a step than the encoding's slots is refused, naming the limit.
"""

from __future__ import annotations

import pytest

from fsmbt.convert.baselines.bsd import fsm_to_bsd
from fsmbt.convert.baselines.chds import fsm_to_chds
from fsmbt.convert.baselines.common import control, leaf_node, sv_node_models
from fsmbt.generate.generator import random_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.semantics import state_variable_runtime as sv
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.verify import nusmv, verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.nusmv.encode_sv import MAX_ACTIONS, SvLeafFacts

STYLES = {"bsd": fsm_to_bsd, "chds": fsm_to_chds}
SEEDS = (3, 11, 27)
OPERATORS = ("retarget_transition", "drop_transition")


def _pairs(style: str) -> list[tuple[str, FSM, BTDocument]]:
    convert = STYLES[style]
    pairs = []
    for seed in SEEDS:
        fsm = random_fsm(seed, n_states=3 + seed % 3)
        pairs.append((f"seed {seed} copy", fsm, convert(fsm).model))
        for mutant in mutants(fsm, seed=seed, per_operator=1):
            if mutant.operator in OPERATORS:
                label = f"seed {seed} {mutant.operator}: {mutant.description}"
                pairs.append((label, fsm, convert(mutant.model).model))
    return pairs


@pytest.mark.parametrize("style", sorted(STYLES))
def test_nusmv_agrees_with_native_on_generated_pairs(nusmv_binary, monkeypatch, style) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    failing = 0
    for label, fsm, tree in _pairs(style):
        native = verify(fsm, tree)
        other = nusmv.check(fsm, tree)
        assert other.verdicts() == native.verdicts(), (style, label)
        if not native.equivalent:
            failing += 1
            # counterexamples in the user's terms: the FSM's events and the tree's states
            states = {n.attrs.get("state") for _t, n in tree.nodes()} | set(fsm.states)
            events = set(fsm.events())
            traces = [p.counterexample for p in other.properties.values() if p.counterexample]
            assert traces, (style, label)
            for trace in traces:
                assert trace[0].input is None
                assert all(step.input in events for step in trace[1:]), (label, trace)
                assert all(step.result_state in states for step in trace), (label, trace)
    assert failing >= 2, f"{style}: the mutants gave only {failing} failing pairs"


def test_engine_both_agrees_on_a_mutant(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    fsm = random_fsm(5, n_states=4)
    mutant = next(m for m in mutants(fsm, seed=5) if m.operator == "retarget_transition")
    tree = fsm_to_bsd(mutant.model).model
    report = verify(fsm, tree, engine="both")  # EngineDisagreement if any verdict differs
    assert report.engine == "native+nusmv"
    assert report.equivalent is verify(fsm, tree).equivalent


def _state(name: str, *, initial: bool = False, action: str = "", then: str = "") -> BTNode:
    """A BSD-like subtree for ``name``: its test, its entry action, then an unguarded
    ``SvAssign`` to ``then`` (or the mode's controller when ``then`` is empty)."""
    last = (
        leaf_node(sv.ASSIGN, f"{name}_to_{then}", target=then)
        if then
        else leaf_node(sv.MODE, f"{name}_mode", state=name, action="", final="false")
    )
    return control(
        "ReactiveSequence",
        f"{name}_subtree",
        [
            leaf_node(sv.IS_STATE, f"Is_{name}", state=name, initial=str(initial).lower()),
            leaf_node(sv.ENTRY_ACTION, name, state=name, action=action),
            last,
        ],
    )


def _tree(*subtrees: BTNode) -> BTDocument:
    doc = BTDocument.single(control("ReactiveFallback", "Root", list(subtrees)))
    doc.node_models.update(sv_node_models((sv.IS_STATE, sv.ENTRY_ACTION, sv.ASSIGN, sv.MODE)))
    return doc


def _fsm(*actions: str) -> FSM:
    fsm = FSM(name="plain")
    for i, action in enumerate(actions):
        fsm.add_state(State(f"s{i}", action=action))
    fsm.initial = "s0"
    return fsm


def test_livelock_is_the_native_input_error(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    # a -> b -> a -> ... without any event: the start's settle never ends
    tree = _tree(_state("a", initial=True, action="x", then="b"), _state("b", action="y", then="a"))
    with pytest.raises(InputError) as native:
        verify(_fsm("x"), tree)
    with pytest.raises(InputError) as other:
        nusmv.check(_fsm("x"), tree)
    assert not isinstance(other.value, UnsupportedError)
    assert str(other.value) == str(native.value)
    assert "livelock" in str(other.value)


def test_more_actions_per_step_than_the_slots_is_refused(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    # the start runs a's, b's and c's entry actions (a -> b -> c, then c's mode keeps running):
    # three actions in one macro step, one more than the encoding's slots
    chain = [f"a{i}" for i in range(MAX_ACTIONS + 1)]
    subtrees = [
        _state(
            name,
            initial=i == 0,
            action=f"act_{name}",
            then=chain[i + 1] if i + 1 < len(chain) else "",
        )
        for i, name in enumerate(chain)
    ]
    tree = _tree(*subtrees)
    fsm = _fsm("act_a0")
    native = verify(fsm, tree)  # the native checker decides it (not equivalent: more outputs)
    assert not native.equivalent
    with pytest.raises(UnsupportedError, match=f"at most {MAX_ACTIONS} actions per macro step"):
        nusmv.check(fsm, tree)


def test_the_unguarded_cycle_check() -> None:
    """CHDS's assigns sit behind an SvGuard in a reactive sequence: no livelock spec; an
    assign behind only an SvIsState (the livelock tree above) keeps the native bound."""
    fsm = random_fsm(3, n_states=5)
    chds = fsm_to_chds(fsm).model
    loop = _tree(_state("a", initial=True, action="x", then="b"), _state("b", then="a"))
    assert not SvLeafFacts.of(CompiledTree(chds), _leaves(chds)).may_livelock
    assert SvLeafFacts.of(CompiledTree(loop), _leaves(loop)).may_livelock


def _leaves(doc: BTDocument) -> dict[int, sv.SvLeaf]:
    return dict(sv.StateVariableMachine(doc, ()).leaves)
