"""The linear-time FSM -> BT path (issue 19): the index-based analysis gives what the
definitions of docs/conversion.md ('FSM -> BT: the loop-execution BT') give, written here
plainly on names; a 2 000-state generated machine's LEBT is proven equivalent by the native
checker; the collector promotion of ``convert/perf.py`` loses nothing; the flat edge arrays
give the same LEBT however the transitions of the sources are interleaved in the file."""

from __future__ import annotations

import gc
import weakref

import pytest

from fsmbt.api import convert_model, verify_models
from fsmbt.convert.compress import tree_depth
from fsmbt.convert.perf import gc_paused
from fsmbt.convert.structure import analyse
from fsmbt.generate import random_fsm
from fsmbt.model.bt import BTNode
from fsmbt.model.fsm import FSM, State
from fsmbt.semantics.lebt.spec import DEFAULT_START, GUARD_TYPE, NO_EVENT, GuardSpec


def _definition(fsm: FSM) -> dict[str, object]:
    """The LEBT structure straight from the definitions, on state names (quadratic is fine)."""
    start = fsm.start_name or DEFAULT_START
    live = [t for t in fsm.transitions if not fsm.states[t.source].final]
    reached, frontier = {fsm.initial}, [fsm.initial]
    while frontier:
        state = frontier.pop()
        for t in live:
            if t.source == state and t.target not in reached:
                reached.add(t.target)
                frontier.append(t.target)
    reachable = [name for name in fsm.states if name in reached]
    kept: list[tuple[str, str, str]] = []  # (source, event, target), first per (source, event)
    for source in reachable:
        events: list[str] = []
        for t in live:
            if t.source == source and t.event not in events:
                events.append(t.event)
                kept.append((source, t.event, t.target))
    guard_pairs = {name: [] for name in reachable}
    first_event = fsm.initial_event if fsm.initial_event is not None else NO_EVENT
    guard_pairs[fsm.initial].append((start, first_event))
    for source, event, target in kept:
        guard_pairs[target].append((source, event))
    predecessors = {
        name: list(dict.fromkeys(s for s, _e in pairs)) for name, pairs in guard_pairs.items()
    }
    loops = [name for name in reachable if len(predecessors[name]) >= 2]
    roots = [fsm.initial] + [name for name in loops if name != fsm.initial]
    children: dict[str, list[str]] = {name: [] for name in reachable}
    for source in reachable:
        for t in live:
            if t.source != source or t.target in roots:
                continue
            if predecessors[t.target] == [source] and t.target not in children[source]:
                children[source].append(t.target)
    return {
        "roots": roots,
        "loop_states": loops,
        "children": children,
        "guard_pairs": guard_pairs,
        "exits": {s: [e for src, e, _t in kept if src == s] for s in reachable},
        "predecessors": predecessors,
        "unreachable": [name for name in fsm.states if name not in reached],
    }


def _awkward(seed: int) -> FSM:
    """A generated machine plus what the generator never makes: a second transition on the
    same event (nondeterministic: the first wins), transitions out of a final state, an
    unreachable cycle of two states leading into the machine, a self-loop on the entry state."""
    fsm = random_fsm(seed, scenario=("basic", "robot", "game")[seed % 3], max_states=25)
    names = list(fsm.states)
    fsm.add_transition(names[0], "again", names[0])
    for t in list(fsm.transitions[:3]):
        fsm.add_transition(t.source, t.event, names[-1])  # duplicate event: never fires
    finals = [name for name, state in fsm.states.items() if state.final]
    if finals:
        fsm.add_transition(finals[0], "late", names[0])  # out of a final state: never fires
    fsm.add_state(State("Island1"))
    fsm.add_state(State("Island2"))
    fsm.add_transition("Island1", "hop", "Island2")
    fsm.add_transition("Island2", "hop", names[len(names) // 2])
    fsm.add_transition("Island2", "back", "Island1")  # an unreachable cycle
    return fsm


def _declared_backwards(fsm: FSM) -> FSM:
    """The same machine with its states declared in reverse order (the initial state kept):
    states are entered from states declared after them, which the reachability pass's
    sequential shortcut cannot take, so the breadth-first search runs."""
    flipped = FSM(name=fsm.name, start_name=fsm.start_name, initial_event=fsm.initial_event)
    for state in reversed(list(fsm.states.values())):
        flipped.add_state(state)
    flipped.initial = fsm.initial
    flipped.transitions = list(fsm.transitions)
    return flipped


@pytest.mark.parametrize("seed", range(120))
def test_index_based_analysis_equals_the_definitions(seed: int) -> None:
    fsm = _awkward(seed) if seed % 2 else random_fsm(seed, max_states=40)
    if seed % 3 == 0:
        fsm = _declared_backwards(fsm)
    structure = analyse(fsm)
    expected = _definition(fsm)
    for field, value in expected.items():
        assert getattr(structure, field) == value, (seed, field)
    assert structure.entry == fsm.initial


def test_a_state_entered_only_by_a_transition_that_never_fires_is_left_out() -> None:
    fsm = FSM(name="shadowed")
    for name in ("A", "B", "C"):
        fsm.add_state(name)
    fsm.add_transition("A", "go", "B")
    fsm.add_transition("A", "go", "C")  # same event: the first transition wins, C never runs
    fsm.add_transition("B", "back", "A")
    result = convert_model(fsm, style="lebt", hierarchy="flatten")
    root = result.model.main.root
    leaves = [node.name for node in root.walk() if node.is_leaf]
    assert "C" not in leaves and "Enter_C" not in leaves
    assert result.stats["nodes"] == sum(1 for _ in root.walk())
    assert verify_models(fsm, result.model).equivalent


@pytest.mark.parametrize("shape", ["mixed", "chain"])
def test_generated_2000_state_fsm_lebt_is_proven_equivalent(shape: str) -> None:
    fsm = random_fsm(19, 2000, "basic", shape=shape, extra_edges=1000 if shape == "mixed" else 0)
    result = convert_model(fsm, style="lebt")
    root = result.model.main.root
    assert result.stats["states"] == 2000
    assert result.stats["nodes"] == sum(1 for _ in root.walk())
    assert result.stats["depth"] == tree_depth(root)
    report = verify_models(fsm, result.model, "native")
    assert report.equivalent, [n for n, p in report.properties.items() if not p.holds]


def test_escaping_is_kept_when_only_the_initial_event_needs_it() -> None:
    fsm = FSM(name="esc", start_name="Start", initial_event="go;now/x")
    fsm.add_state("A")
    fsm.add_state("B")
    fsm.add_transition("A", "e", "B")
    fsm.add_transition("B", "f", "A")
    root = convert_model(fsm, style="lebt").model.main.root
    guard = next(n for n in root.walk() if n.type == GUARD_TYPE and n.name == "Enter_A")
    assert guard.attrs["pairs"] == "Start/go\\;now\\/x;B/f"
    assert GuardSpec.from_attrs(guard.attrs).pairs[0] == ("Start", "go;now/x")


def test_promotion_on_exit_loses_no_garbage_and_respects_frozen_objects() -> None:
    class Cell:
        def __init__(self) -> None:
            self.me = self

    gc.collect()
    freed: list[str] = []
    kept: list[list[int]] = []
    with gc_paused():
        kept.extend([i] for i in range(3 * gc.get_threshold()[0]))  # enough for a young pass
        cell = Cell()
        probe = weakref.ref(cell)
        weakref.finalize(cell, freed.append, "cell")
        del cell  # a reference cycle: only the cyclic collector can free it
        assert not gc.isenabled()
    assert gc.isenabled()
    assert gc.get_count()[0] < gc.get_threshold()[0]  # nothing left for a young pass
    kept.append([[] for _ in range(10)])  # allocations that would trigger that pass
    assert probe() is not None  # promoted to the oldest generation, not traversed yet
    gc.collect()
    assert probe() is None and freed == ["cell"]

    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        with gc_paused():
            [object() for _ in range(10)]
        assert gc.get_freeze_count() == frozen  # the caller's frozen objects stay frozen
    finally:
        gc.unfreeze()


def test_the_builders_positional_node_fields_are_btnodes_field_order() -> None:
    from dataclasses import fields

    from fsmbt.convert.lebt import NODE_FIELDS
    from fsmbt.model.bt import BTNode

    assert tuple(f.name for f in fields(BTNode))[: len(NODE_FIELDS)] == NODE_FIELDS


def _sources_listed_backwards(fsm: FSM) -> FSM:
    """The same machine with its transitions listed by source in reverse declaration order,
    each source's own transitions kept in their order (so the LEBT must not change): the
    analysis cannot take them as they come and sorts them by source."""
    order = {name: position for position, name in enumerate(fsm.states)}
    listed = FSM(name=fsm.name, start_name=fsm.start_name, initial_event=fsm.initial_event)
    for state in fsm.states.values():
        listed.add_state(state)
    listed.initial = fsm.initial
    listed.transitions = sorted(fsm.transitions, key=lambda t: -order[t.source])  # stable
    return listed


@pytest.mark.parametrize("seed", range(40))
def test_the_lebt_does_not_depend_on_how_the_sources_transitions_are_interleaved(
    seed: int,
) -> None:
    fsm = _awkward(seed) if seed % 2 else random_fsm(seed, max_states=60)
    grouped = convert_model(fsm, style="lebt", hierarchy="flatten")
    backwards = convert_model(_sources_listed_backwards(fsm), style="lebt", hierarchy="flatten")
    assert backwards.model.main.root == grouped.model.main.root
    assert backwards.stats == grouped.stats
    structure = analyse(_sources_listed_backwards(fsm))
    assert list(structure.kept_sources) == sorted(structure.kept_sources)
    nodes = list(grouped.model.main.root.walk())
    assert all(isinstance(child, BTNode) for node in nodes for child in node.children)
    assert grouped.stats["nodes"] == len(nodes)
