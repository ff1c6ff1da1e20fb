"""The mutation suite's families of equivalent pairs, shared by the checker's mutation tests
(test_ver_mutations.py) and the NuSMV/native agreement test (tests/verify/nusmv), so both mutate
exactly the same pairs.

Each family is a list of equivalent ``(source, result)`` pairs; ``FAMILIES`` names the side
``run_family`` mutates for each (``mutants(target, seed=index, per_operator=4)``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.generate.generator import random_bt, random_fsm
from fsmbt.model import FSM, BTDocument, BTNode, NodeKind, State
from fsmbt.semantics.leaf_machine import LeafMachine
from fsmbt.verify.mutations import Mutant, mutants
from support.random_trees import lebt_from_structure
from support.ver_models import paper_fsm, renamed_copy

PAPER_STRUCTURE = [
    ("A", [("B", []), ("F", [("I", [("J", [])])])]),
    ("C", []),
    ("D", [("E", [("G", [("H", [])])])]),
]
PER_OPERATOR = 4  # mutants per operator and pair, as run_family draws them


def leaf(name: str, kind: NodeKind = NodeKind.ACTION) -> BTNode:
    return BTNode("Act" if kind is NodeKind.ACTION else "Check", kind, name=name)


def small_bt_and_leaf_fsm() -> tuple[BTDocument, FSM]:
    """Sequence(c1?, Fallback(a1, a2)) and its leaf FSM, derived by hand."""
    root = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[
            leaf("c1", NodeKind.CONDITION),
            BTNode("Fallback", NodeKind.CONTROL, children=[leaf("a1"), leaf("a2")]),
        ],
    )
    fsm = FSM(name="leaf_fsm")
    for name in ("c1", "a1", "a2"):
        fsm.add_state(name)
    fsm.add_state(State("S", action="SUCCESS", final=True))
    fsm.add_state(State("F", action="FAILURE", final=True))
    for a, e, b in [
        ("c1", "success", "a1"),
        ("c1", "failure", "F"),
        ("a1", "success", "S"),
        ("a1", "failure", "a2"),
        ("a1", "running", "a1"),
        ("a2", "success", "S"),
        ("a2", "failure", "F"),
        ("a2", "running", "a2"),
    ]:
        fsm.add_transition(a, e, b)
    return BTDocument.single(root), fsm


def leaf_fsm_by_exploration(doc: BTDocument) -> FSM:
    """The BT's leaf-execution machine written out as an FSM (one state per machine state)."""
    machine = LeafMachine(doc)
    start, outputs = machine.start()
    names: dict[object, str] = {}
    fsm = FSM(name="explored")
    queue = [(start, outputs)]
    names[start] = "q0"
    fsm.add_state(State("q0", action=outputs[-1], final=machine.status(start) != "running"))
    while queue:
        state, _ = queue.pop(0)
        for symbol in machine.inputs(state):
            nxt, outs = machine.step(state, symbol)
            if nxt not in names:
                names[nxt] = f"q{len(names)}"
                fsm.add_state(
                    State(names[nxt], action=outs[-1], final=machine.status(nxt) != "running")
                )
                queue.append((nxt, outs))
            fsm.add_transition(names[state], symbol, names[nxt])
    return fsm


def fsm_pairs() -> list[tuple[FSM, FSM]]:
    pairs = [(paper_fsm(), renamed_copy(paper_fsm()))]
    for seed in range(4):
        fsm = random_fsm(f"mut:{seed}", min_states=4, max_states=9)
        pairs.append((fsm, renamed_copy(fsm)))
    return pairs


def lebt_pairs() -> list[tuple[FSM, BTDocument]]:
    pairs = [(paper_fsm(), lebt_from_structure(paper_fsm(), PAPER_STRUCTURE))]
    for seed in range(3):
        fsm = random_fsm(f"lebt:{seed}", min_states=4, max_states=8)
        pairs.append((fsm, fsm_to_lebt(fsm).model))
    return pairs


def bt_pairs() -> list[tuple[BTDocument, FSM]]:
    pairs = [small_bt_and_leaf_fsm()]
    for seed in range(4):
        doc = random_bt(f"mutbt:{seed}", depth=3, breadth=3, max_nodes=14)
        pairs.append((doc, leaf_fsm_by_exploration(doc)))
    return pairs


def converted_bt_pairs() -> list[tuple[BTDocument, FSM]]:
    pairs = []
    for seed in range(2):
        doc = random_bt(f"conv:{seed}", depth=4, breadth=3, max_nodes=16)
        pairs.append((doc, bt_to_hfsm(doc).model))
    return pairs


#: (family name, its pairs, the side run_family mutates) as test_ver_mutations runs them.
FAMILIES: list[tuple[str, Callable[[], list], str]] = [
    ("FSM vs FSM", fsm_pairs, "result"),
    ("FSM vs LEBT", lebt_pairs, "result"),
    ("mutated BT vs leaf FSM", bt_pairs, "source"),
    ("BT vs mutated leaf FSM", bt_pairs, "result"),
    ("mutated BT vs converted HFSM", converted_bt_pairs, "source"),
    ("BT vs mutated converted HFSM", converted_bt_pairs, "result"),
]


def family_mutants(pairs: list, mutate: str) -> Iterator[tuple[int, int, Mutant, object, object]]:
    """``(pair index, mutant index, mutant, source, result)`` with the mutant in place, in the
    order and with the seeds ``run_family`` uses."""
    for index, (source_model, result_model) in enumerate(pairs):
        target = result_model if mutate == "result" else source_model
        for k, mutant in enumerate(mutants(target, seed=index, per_operator=PER_OPERATOR)):
            if mutate == "result":
                yield index, k, mutant, source_model, mutant.model
            else:
                yield index, k, mutant, mutant.model, result_model
