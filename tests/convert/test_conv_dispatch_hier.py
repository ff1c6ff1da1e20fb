"""The hierarchical dispatch form (docs/semantics.md §12a): a hierarchical event-driven machine
keeps its composite states (a SubTree each, the composite's own transitions written once),
is proven equivalent to its source, reads back as the source's flattening, and a mutant of
each is refuted; constructs the form cannot keep fall back to the flat form with a warning
naming the state and the cause; the tree grows with the machine, not with its flattening."""

from __future__ import annotations

import re

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.generate.hierarchical import random_hfsm
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM, State
from fsmbt.semantics.engines.btcpp_load import check_loads
from fsmbt.verify import verify
from support.corpus import CORPUS

KEPT = (
    "fsm/commons_scxml/state-01.scxml",
    "fsm/scion_tests/hierarchy__hier0.scxml",
    "fsm/scion_tests/hierarchy__hier1.scxml",
    "fsm/scion_tests/hierarchy_documentOrder__test0.scxml",
)
PARALLEL = (
    "fsm/scion_tests/more-parallel__test0.scxml",
    "fsm/scion_tests/parallel__test0.scxml",
    "fsm/scion_tests/parallel__test1.scxml",
)
_ACTION = re.compile(r'(<DispatchEntry [^>]*action=")([^"]*)(")')


def _corpus(name: str) -> FSM:
    path = CORPUS / name
    if not path.exists():
        pytest.skip(f"corpus file {name} not here (set FSMBT_CORPUS)")
    model = api.load(path).model
    assert isinstance(model, FSM)
    return model


def _proven_and_read_back(fsm: FSM) -> str:
    """Convert, prove, read back; the tree's text."""
    result = convert(fsm, style="dispatch")
    assert result.stats["form"] == "hierarchical" and result.warnings == []
    text = dumps(result.model, "btcpp")
    doc = loads(text, "btcpp")  # what BehaviorTree.CPP reads
    assert verify(fsm, doc).equivalent
    back = convert(doc)
    assert isinstance(back.model, FSM) and back.warnings == []
    assert verify(doc, back.model).equivalent and verify(fsm, back.model).equivalent
    flat = flatten(fsm)
    # flat, or hierarchical when the composites could be rebuilt: its flattening either way
    read = flatten(back.model)
    states = {s.name: (s.action, s.final) for s in read.states.values()}
    # the flattening's observable states: the same names, actions and finality
    assert states == {n: (flat.states[n].action, flat.states[n].final) for n in states}
    assert len(states) == len(flat.states)
    return text


def _refuted(fsm: FSM, text: str) -> None:
    """A mutant - the last entered state's action renamed - is NOT EQUIVALENT."""
    hits = list(_ACTION.finditer(text))
    assert hits
    last = hits[-1]
    mutant = text[: last.start(2)] + "mutant_action" + text[last.end(2) :]
    assert not verify(fsm, loads(mutant, "btcpp")).equivalent


@pytest.mark.parametrize("name", KEPT)
def test_corpus_hierarchical_scxml_keeps_its_hierarchy(name: str) -> None:
    fsm = _corpus(name)
    text = _proven_and_read_back(fsm)
    assert 'SubTree name="' in text and 'ID="MainTree"' in text
    back = convert(loads(text, "btcpp"))
    assert back.model.is_hierarchical and back.stats["composites"] == 1  # rebuilt
    _refuted(fsm, text)


@pytest.mark.parametrize("seed", range(6))
def test_bt_to_fsm_rebuilds_the_composite_states_of_machines_without_completions(
    seed: int,
) -> None:
    fsm = random_hfsm(seed, 30, completions=0.0)
    text = _proven_and_read_back(fsm)
    back = convert(loads(text, "btcpp"))
    assert isinstance(back.model, FSM) and back.model.is_hierarchical
    composites = sum(1 for _p, _m, s in fsm.walk() if s.is_composite)
    assert back.stats["composites"] == composites
    assert verify(back.model, fsm).equivalent  # FSM against FSM: both flattened


@pytest.mark.parametrize("name", PARALLEL)
def test_parallel_states_fall_back_to_the_flat_form_with_the_state_named(name: str) -> None:
    fsm = _corpus(name)
    result = convert(fsm, style="dispatch")
    assert "form" not in result.stats and result.stats["flattened"] is True
    (warning,) = result.warnings
    assert "flattened" in warning and "state 'p' is parallel" in warning
    assert verify(fsm, result.model).equivalent


@pytest.mark.parametrize("seed", range(12))
def test_generated_hierarchical_machines_are_proven_and_mutants_refuted(seed: int) -> None:
    fsm = random_hfsm(seed, 30)
    _refuted(fsm, _proven_and_read_back(fsm))


def _conflict_machine() -> FSM:
    """``A`` holds ``a1 -e-> a2``; ``A -e-> B``: the child's transition wins (W3C)."""
    inner = FSM("A")
    inner.add_state("a1")
    inner.add_state("a2")
    inner.initial = "a1"
    inner.add_transition("a1", "e", "a2")
    fsm = FSM("conflict")
    fsm.add_state(State("A", action=None, regions=[inner]))
    fsm.add_state("B")
    fsm.initial = "A"
    fsm.add_transition("A", "e", "B")
    fsm.add_transition("B", "back", "A")
    return fsm


def test_a_descendant_transition_takes_priority_and_the_swapped_order_is_refuted() -> None:
    fsm = _conflict_machine()
    text = _proven_and_read_back(fsm)
    # the composite's tree tries the child's dispatch first; swap the two children
    doc = loads(text, "btcpp")
    fallback = doc.trees["A"].root
    assert fallback is not None and fallback.type == "ReactiveFallback"
    fallback.children.reverse()
    report = verify(fsm, doc)
    assert not report.equivalent


def test_done_state_completion_is_followed_when_built() -> None:
    inner = FSM("A")
    inner.add_state("a1")
    inner.add_state("fin", final=True)
    inner.initial = "a1"
    inner.add_transition("a1", "finish", "fin")
    fsm = FSM("done")
    fsm.add_state(State("A", action=None, regions=[inner]))
    fsm.add_state("B")
    fsm.add_state("End", final=True)
    fsm.initial = "A"
    fsm.add_transition("A", None, "B", exit="fin")  # done.state.A
    fsm.add_transition("B", "stop", "End")
    text = _proven_and_read_back(fsm)
    # a1 --finish--> goes straight on to B: the final sub-state is never observed
    assert 'state="B"' in text and 'state="A/fin"' not in text


def test_the_tree_grows_with_the_machine_not_with_its_flattening() -> None:
    def machine(children: int, own: int) -> FSM:
        inner = FSM("C")
        for i in range(children):
            inner.add_state(f"c{i}")
        inner.initial = "c0"
        for i in range(children - 1):
            inner.add_transition(f"c{i}", "next", f"c{i + 1}")
        fsm = FSM("wide")
        fsm.add_state(State("C", action=None, regions=[inner]))
        for k in range(own):
            fsm.add_state(f"t{k}")
            fsm.add_transition("C", f"go{k}", f"t{k}")
            fsm.add_transition(f"t{k}", "back", "C")
        fsm.initial = "C"
        return fsm

    sizes = {}
    for n, k in ((10, 10), (20, 10), (10, 20)):
        fsm = machine(n, k)
        hier = convert(fsm, style="dispatch")
        flat = convert(flatten(fsm), style="dispatch")
        assert verify(fsm, hier.model).equivalent
        sizes[(n, k)] = (int(hier.stats["nodes"]), int(flat.stats["nodes"]))
    # flat: every child carries the composite's k transitions (n*k); hierarchical: n + k
    for (n, k), (hier_nodes, flat_nodes) in sizes.items():
        assert flat_nodes > n * k
        assert hier_nodes < 12 * (n + k)
    assert sizes[(20, 10)][0] - sizes[(10, 10)][0] < sizes[(20, 10)][1] - sizes[(10, 10)][1]


def test_deep_nesting_stays_shallow_per_tree_and_loads() -> None:
    depth = 30
    fsm = FSM("deep")
    machine = fsm
    for level in range(depth):
        inner = FSM(f"L{level}")
        machine.add_state(State(f"L{level}", action=None, regions=[inner]))
        machine.add_state(f"x{level}")
        machine.initial = f"L{level}"
        machine.add_transition(f"L{level}", f"out{level}", f"x{level}")
        machine.add_transition(f"x{level}", f"in{level}", f"L{level}")
        machine = inner
    machine.add_state("leaf")
    machine.initial = "leaf"
    result = convert(fsm, style="dispatch")
    assert result.stats["form"] == "hierarchical"
    assert int(result.stats["depth"]) <= 8  # per BehaviorTree; the SubTree chain is 30 long
    assert result.stats["subtrees"] == depth
    assert check_loads(dumps(result.model, "btcpp")).loaded  # BehaviorTree.CPP 4.8.2
    assert verify(fsm, result.model).equivalent


def test_unkept_constructs_are_named() -> None:
    fsm = _conflict_machine()
    fsm.states["B"].regions = []
    fsm.add_transition("B", None, "A")  # eventless out of an atomic state
    result = convert(fsm, style="dispatch")
    assert result.stats.get("flattened") is True
    assert any("state 'B' has an eventless transition" in w for w in result.warnings)


def test_auto_keeps_the_hierarchy_and_hierarchy_flatten_asks_for_the_flat_form() -> None:
    fsm = _conflict_machine()
    kept = convert(fsm)  # style auto: an event-driven machine gets the dispatch form
    assert kept.stats["style"] == "dispatch" and kept.stats["form"] == "hierarchical"
    flat = convert(fsm, hierarchy="flatten")
    assert "form" not in flat.stats and flat.stats["flattened"] is True
    assert any("--hierarchy flatten" in w for w in flat.warnings)
    assert verify(fsm, kept.model).equivalent and verify(fsm, flat.model).equivalent


@pytest.mark.parametrize("parallel", [False, True])
def test_the_subtree_tests_generator_machines_are_proven(parallel: bool) -> None:
    """A second, independent generator (tests/support/conv_hfsm_gen.py: inner final states
    with completions, shared events, self-loops, parallel states)."""
    from support.conv_hfsm_gen import random_hfsm as other_hfsm

    forms = set()
    for seed in range(10):
        fsm = other_hfsm(seed, parallel=parallel)
        result = convert(fsm, style="dispatch")
        forms.add(result.stats.get("form", "flat"))
        if result.stats.get("flattened"):
            assert any("is parallel" in w for w in result.warnings)
        doc = loads(dumps(result.model, "btcpp"), "btcpp")
        assert verify(fsm, doc).equivalent
        assert verify(fsm, convert(doc).model).equivalent
    assert "hierarchical" in forms
