"""The LEBT protocol (docs/semantics.md, 'The LEBT protocol') in four runtimes against the FSM, on hand-built LEBTs.

For each FSM (the paper's A–J example among them) the LEBT is built by hand from a nesting of
selector subtrees; random event sequences are fed to the FSM's macro-step machine, our
interpreter (``LEBTMachine``), BehaviorTree.CPP (behaviortreepy) and py_trees. All four must run
the same actions in the same order, and the BT must be terminated exactly when the FSM is in a
final state.
"""

from __future__ import annotations

import random

import pytest

from fsmbt.model.fsm import FSM
from fsmbt.semantics.engines.btcpp_engine import BTCppLebtRunner
from fsmbt.semantics.engines.pytrees_engine import PyTreesLebtRunner
from fsmbt.semantics.lebt.machine import LEBTMachine
from fsmbt.semantics.machine import FINAL, FSMMachine
from support.random_trees import Structure, lebt_from_structure

SEQUENCES = 40
LENGTH = 14


def _fsm(
    name: str,
    edges: list[tuple[str, str, str]],
    finals: str = "",
    *,
    initial: str,
    initial_event: str | None = None,
    silent: str = "",
) -> FSM:
    fsm = FSM(name=name, start_name="Start" if initial_event else None, initial_event=initial_event)
    names: list[str] = [initial]
    for s, _, t in edges:
        names += [s, t]
    for state in dict.fromkeys(names):
        fsm.add_state(
            state,
            final=state in finals.split(),
            action=None if state in silent.split() else f"do_{state}",
        )
    fsm.initial = initial
    for s, e, t in edges:
        fsm.add_transition(s, e, t)
    return fsm


def _paper() -> tuple[FSM, list[Structure]]:
    pairs = ["AB", "AC", "AD", "AF", "BC", "BD", "CD", "DE", "EC", "ED", "EG", "GH", "FI", "IJ"]
    fsm = _fsm(
        "paper",
        [(a, f"event{a}{b}", b) for a, b in pairs],
        "H J",
        initial="A",
        initial_event="eventStartA",
    )
    structure = [
        ("A", [("B", []), ("F", [("I", [("J", [])])])]),
        ("C", []),
        ("D", [("E", [("G", [("H", [])])])]),
    ]
    return fsm, structure


CASES: dict[str, tuple[FSM, list[Structure]]] = {
    "paper_A_J": _paper(),
    "linear": (
        _fsm("linear", [("S0", "next", "S1"), ("S1", "next", "S2")], "S2", initial="S0"),
        [("S0", [("S1", [("S2", [])])])],
    ),
    "self_loop": (
        _fsm("self_loop", [("A", "a", "A"), ("A", "b", "B")], "B", initial="A"),
        [("A", [("B", [])])],
    ),
    "two_cycle": (
        _fsm("two_cycle", [("A", "go", "B"), ("B", "back", "A")], initial="A"),
        [("A", [("B", [])])],
    ),
    "branch": (
        _fsm("branch", [("A", "x", "B"), ("A", "y", "C")], "B C", initial="A"),
        [("A", [("B", []), ("C", [])])],
    ),
    "shared_target": (
        _fsm("shared", [("A", "x", "C"), ("A", "y", "B"), ("B", "z", "C")], "C", initial="A"),
        [("A", [("B", [])]), ("C", [])],
    ),
    "traffic_light": (
        _fsm(
            "traffic",
            [
                ("Red", "t", "Green"),
                ("Green", "t", "Yellow"),
                ("Yellow", "t", "Red"),
                ("Green", "e", "Red"),
            ],
            initial="Red",
        ),
        [("Red", [("Green", [("Yellow", [])])])],
    ),
    "initial_event": (
        _fsm("init_event", [("A", "x", "B")], "B", initial="A", initial_event="go"),
        [("A", [("B", [])])],
    ),
    "ring": (
        _fsm(
            "ring",
            [("A", "n", "B"), ("B", "n", "C"), ("C", "n", "D"), ("D", "n", "A")],
            initial="A",
        ),
        [("A", [("B", [("C", [("D", [])])])])],
    ),
    "all_loops": (
        _fsm(
            "all_loops",
            [("A", "a", "B"), ("B", "b", "C"), ("C", "c", "B"), ("C", "d", "A"), ("A", "e", "C")],
            initial="A",
        ),
        [("A", []), ("B", []), ("C", [])],
    ),
    "silent_state": (
        _fsm(
            "silent",
            [("A", "n", "B"), ("B", "n", "C"), ("C", "n", "A"), ("B", "stop", "End")],
            "End",
            initial="A",
            silent="B",
        ),
        [("A", [("B", [("C", []), ("End", [])])])],
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_sem_lebt_runtimes_agree_with_the_fsm(case: str) -> None:
    fsm, structure = CASES[case]
    doc = lebt_from_structure(fsm, structure)
    reference = FSMMachine(fsm)
    alphabet = list(reference.alphabet) + ["unknown_event"]
    ours = LEBTMachine(doc, alphabet)
    rng = random.Random(case)
    compared = 0
    for _ in range(SEQUENCES):
        f_state, f_out = reference.start()
        o_state, o_out = ours.start()
        btcpp, pytrees = BTCppLebtRunner(doc), PyTreesLebtRunner(doc)
        assert f_out == o_out == btcpp.initial() == pytrees.initial()
        for step in range(LENGTH):
            event = rng.choice(alphabet)
            f_state, f_out = reference.step(f_state, event)
            o_state, o_out = ours.step(o_state, event)
            c_out, p_out = btcpp.macro_step(event), pytrees.macro_step(event)
            assert f_out == o_out == c_out == p_out, (case, step, event, f_state)
            final = reference.status(f_state) == FINAL
            assert (
                (ours.status(o_state) == FINAL) == final == btcpp.terminated == pytrees.terminated
            ), (case, step, event, f_state)
            compared += 1
    assert compared == SEQUENCES * LENGTH


def test_sem_lebt_paper_example_walkthrough() -> None:
    """The paper's A–J by hand: a move to a loop state (A->C) takes two ticks; an event
    without a transition is ignored; reaching H terminates the BT."""
    fsm, structure = CASES["paper_A_J"]
    machine = LEBTMachine(lebt_from_structure(fsm, structure), FSMMachine(fsm).alphabet)
    state, out = machine.start()
    assert out == ()
    state, out = machine.step(state, "eventStartA")
    assert out == ("do_A",)
    state, out = machine.step(state, "eventAC")  # C is a loop state: two ticks
    assert out == ("do_C",) and machine.status(state) != FINAL
    state, out = machine.step(state, "eventAB")  # no transition from C: ignored
    assert out == ()
    for event, action in [
        ("eventCD", "do_D"),
        ("eventDE", "do_E"),
        ("eventEG", "do_G"),
        ("eventGH", "do_H"),
    ]:
        state, out = machine.step(state, event)
        assert out == (action,)
    assert machine.status(state) == FINAL


def _random_fsm(rng: random.Random, index: int) -> FSM:
    """2–12 states, self-loops and shared targets, maybe an initial event and finals."""
    n = rng.randint(2, 12)
    names = [f"S{i}" for i in range(n)]
    events = [f"e{i}" for i in range(rng.randint(1, 4))]
    edges: list[tuple[str, str, str]] = []
    for i in range(1, n):  # keep every state reachable
        edges.append((names[rng.randrange(i)], "", names[i]))
    for _ in range(rng.randint(0, 2 * n)):
        edges.append((rng.choice(names), "", rng.choice(names)))
    used: set[tuple[str, str]] = set()
    labelled = []
    for source, _, target in edges:
        free = [e for e in events + [f"x{len(used)}"] if (source, e) not in used]
        event = rng.choice(free)
        used.add((source, event))
        labelled.append((source, event, target))
    finals = " ".join(
        s for s in names[1:] if rng.random() < 0.2 and all(src != s for src, _, _ in labelled)
    )
    return _fsm(
        f"random{index}",
        labelled,
        finals,
        initial="S0",
        initial_event="start" if rng.random() < 0.5 else None,
    )


def test_sem_converter_lebts_run_alike_in_every_runtime() -> None:
    """LEBTs from the project's converter (``fsmbt.convert.lebt``) on 30 random FSMs: the
    interpreter, BehaviorTree.CPP and py_trees agree with the FSM on random event sequences."""
    from fsmbt.convert.lebt import fsm_to_lebt

    rng = random.Random(2024)
    for index in range(30):
        fsm = _random_fsm(rng, index)
        doc = fsm_to_lebt(fsm).model
        reference = FSMMachine(fsm)
        ours = LEBTMachine(doc, reference.alphabet)
        for _ in range(5):
            f_state, f_out = reference.start()
            o_state, o_out = ours.start()
            btcpp, pytrees = BTCppLebtRunner(doc), PyTreesLebtRunner(doc)
            assert f_out == o_out == btcpp.initial() == pytrees.initial()
            for _ in range(12):
                event = rng.choice(reference.alphabet)
                f_state, f_out = reference.step(f_state, event)
                o_state, o_out = ours.step(o_state, event)
                assert f_out == o_out == btcpp.macro_step(event) == pytrees.macro_step(event), (
                    fsm.name,
                    event,
                )
                assert (
                    (reference.status(f_state) == FINAL)
                    == (ours.status(o_state) == FINAL)
                    == btcpp.terminated
                    == pytrees.terminated
                ), (fsm.name, event)
