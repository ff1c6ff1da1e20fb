"""The fast LEBT runtime (``fsmbt.semantics.lebt.fast``) against the generic interpreter path (``LEBTRuntime``).

Both paths of ``LEBTMachine`` run the same trees on the same random event sequences; outputs,
statuses, blackboard ``state``, last root result and the running state leaf must agree at every
step, and the checker's verdicts (and explored state counts) must be the same. Trees outside
the strict grammar (mutants that turn a Sequence into a Fallback, add an Inverter, drop a leaf,
wrap in a SubTree ...) must be refused by the grammar test and run on the generic path.
"""

from __future__ import annotations

import copy
import random

import pytest

from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.generate.generator import random_fsm
from fsmbt.model import FSM, BTDocument, BTNode, NodeKind
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.lebt.fast import strict_lebt_sels
from fsmbt.semantics.lebt.machine import LEBTMachine
from fsmbt.semantics.lebt.spec import STATE_TYPE
from fsmbt.semantics.status import NodeStatus
from fsmbt.verify.mutations import mutants
from fsmbt.verify.native import check
from fsmbt.verify.pairing import LEBTWithActiveInputs, machines_for

NODE_RUNNING = NodeStatus.RUNNING
UNKNOWN_EVENT = "no_such_event"
#: operators whose every mutant leaves the strict grammar / stays inside it
SHAPE_BREAKING = {"sequence_to_fallback", "fallback_to_sequence", "invert_condition", "drop_leaf"}
SHAPE_KEEPING = {"retarget_transition", "drop_guard_pair", "change_action", "flip_final"}


def both_paths(doc: BTDocument, alphabet: list[str]) -> tuple[LEBTMachine, LEBTMachine]:
    fast = LEBTMachine(doc, alphabet)
    generic = LEBTMachine(doc, alphabet, generic=True)
    assert not generic.fast
    return fast, generic


def running_leaves(machine: LEBTMachine, state) -> set[int]:  # type: ignore[no-untyped-def]
    states = machine.runtime.leaves.states
    return {nid for nid, status in state.snapshot[0] if status == NODE_RUNNING and nid in states}


def exits_by_state(doc: BTDocument) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for _tree, node in doc.nodes():
        if node.type == STATE_TYPE:
            raw = node.attrs.get("exits", "")
            out.setdefault(node.attrs.get("state", ""), []).extend(raw.split(";") if raw else [])
    return out


def assert_same_runs(
    doc: BTDocument, alphabet: list[str], rng: random.Random, *, runs: int = 3, length: int = 25
) -> int:
    """Lockstep random runs; events favour the current state's exits so runs go deep.
    Also checks that fast and generic states correspond one to one. Returns steps taken."""
    fast, generic = both_paths(doc, alphabet)
    assert fast.fast
    exits = exits_by_state(doc)
    offered = list(alphabet) + [UNKNOWN_EVENT]
    fast_to_generic: dict = {}
    generic_to_fast: dict = {}
    steps = 0

    def compare(f, g, out_f, out_g, where) -> None:  # type: ignore[no-untyped-def]
        assert out_f == out_g, where
        assert fast.status(f) == generic.status(g), where
        assert (f.bb_state, f.last_result) == (g.bb_state, g.last_result), where
        assert running_leaves(fast, f) == running_leaves(generic, g), where
        assert fast_to_generic.setdefault(f, g) == g, where
        assert generic_to_fast.setdefault(g, f) == f, where

    for run in range(runs):
        f, out_f = fast.start()
        g, out_g = generic.start()
        compare(f, g, out_f, out_g, ("start", run))
        trail: list[str] = []
        for _ in range(length):
            here = exits.get(f.bb_state)
            if here and rng.random() < 0.7:
                event = rng.choice(here)
            else:
                event = rng.choice(offered)
            trail.append(event)
            f, out_f = fast.step(f, event)
            g, out_g = generic.step(g, event)
            compare(f, g, out_f, out_g, trail)
            steps += 1
    return steps


def assert_same_verdicts(fsm: FSM, doc: BTDocument) -> bool:
    src, wrapped, _mode = machines_for(fsm, doc)
    assert isinstance(wrapped, LEBTWithActiveInputs) and wrapped.machine.fast
    generic = LEBTWithActiveInputs(LEBTMachine(doc, wrapped.alphabet, generic=True))
    fast_report, generic_report = check(src, wrapped), check(src, generic)
    assert fast_report.verdicts() == generic_report.verdicts()
    for key in ("result_states", "product_states", "product_edges"):
        assert fast_report.stats[key] == generic_report.stats[key], key
    return fast_report.equivalent


def alphabet_of(fsm: FSM, doc: BTDocument) -> list[str]:
    _src, wrapped, _mode = machines_for(fsm, doc)
    return list(wrapped.alphabet)  # type: ignore[attr-defined]


def test_sem_fast_matches_generic_on_converter_lebts() -> None:
    rng = random.Random(20261123)
    equivalent = steps = 0
    sizes = []
    for seed in range(200):
        fsm = random_fsm(f"lebtfast:{seed}", min_states=2, max_states=60)
        doc = fsm_to_lebt(fsm).model
        sizes.append(len(fsm.states))
        steps += assert_same_runs(doc, alphabet_of(fsm, doc), rng)
        if seed % 2 == 0:
            equivalent += assert_same_verdicts(fsm, doc)
    assert min(sizes) <= 5 and max(sizes) >= 45  # the size range is really covered
    assert equivalent == 100  # the converter is correct: every checked pair is equivalent
    assert steps == 200 * 3 * 25


def mutant_pairs() -> list[tuple[FSM, BTDocument]]:
    pairs = []
    for seed in range(10):
        fsm = random_fsm(f"lebtfastmut:{seed}", min_states=3, max_states=9)
        pairs.append((fsm, fsm_to_lebt(fsm).model))
    return pairs


def test_sem_fast_matches_generic_on_mutants() -> None:
    rng = random.Random(7)
    kept: dict[str, int] = {}
    refused: dict[str, int] = {}
    differing = 0
    for fsm, doc in mutant_pairs():
        alphabet = alphabet_of(fsm, doc)
        for mutant in mutants(doc, seed=3, per_operator=None):
            strict = strict_lebt_sels(CompiledTree(mutant.model)) is not None
            tally = kept if strict else refused
            tally[mutant.operator] = tally.get(mutant.operator, 0) + 1
            if mutant.operator in SHAPE_BREAKING:
                assert not strict, mutant
            if mutant.operator in SHAPE_KEEPING:
                assert strict, mutant
            if not strict:
                assert not LEBTMachine(mutant.model, alphabet).fast
                continue
            assert_same_runs(mutant.model, alphabet, rng, runs=2, length=15)
            differing += not assert_same_verdicts(fsm, mutant.model)
    assert SHAPE_KEEPING <= set(kept) and "swap_children" in kept
    assert SHAPE_BREAKING <= set(refused) and "swap_children" in refused
    assert differing > 0  # the fast path also reproduces non-equivalent verdicts


def selector(
    guard_pairs: str,
    state: str,
    final: bool = False,
    exits: str = "",
    children: list[BTNode] | None = None,
) -> BTNode:
    guard = BTNode("LebtGuard", NodeKind.CONDITION, attrs={"target": state, "pairs": guard_pairs})
    leaf = BTNode(
        "LebtState",
        NodeKind.ACTION,
        attrs={
            "state": state,
            "action": f"do_{state}",
            "final": "true" if final else "false",
            "exits": exits,
        },
    )
    body = (
        leaf
        if children is None
        else BTNode("Sequence", NodeKind.CONTROL, children=[leaf, *children])
    )
    return BTNode("Fallback", NodeKind.CONTROL, children=[guard, body])


def tiny_lebt() -> BTDocument:
    """A -go-> B (chain), B -back-> A (loop), B -end-> C final, A final-free."""
    b = selector("A/go", "B", exits="back;end", children=[selector("B/end", "C", final=True)])
    root = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[selector("S/;A/back", "A", exits="go", children=[b])],
    )
    # A has in-degree 2 (init and back): it is a root selector, the loop target
    root.children[0].children[0].attrs["pairs"] = "S/;B/back"
    return BTDocument.single(root)


@pytest.mark.parametrize(
    "change",
    [
        "reactive_root",
        "subtree",
        "extra_child",
        "always_success",
        "inverter",
        "guard_after_body",
        "body_without_state",
    ],
)
def test_sem_grammar_refuses_other_shapes(change: str) -> None:
    doc = tiny_lebt()
    assert strict_lebt_sels(CompiledTree(doc)) is not None
    doc = copy.deepcopy(doc)
    root = doc.main.root
    assert root is not None
    sel = root.children[0]
    if change == "reactive_root":
        root.type = "ReactiveSequence"
    elif change == "subtree":
        inner = BTDocument.single(copy.deepcopy(sel), tree_id="Inner")
        doc.trees["Inner"] = inner.main
        root.children[0] = BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Inner"})
    elif change == "extra_child":
        sel.children.append(copy.deepcopy(sel.children[1]))
    elif change == "always_success":
        root.children.append(BTNode("AlwaysSuccess", NodeKind.ACTION))
    elif change == "inverter":
        sel.children[0] = BTNode("Inverter", NodeKind.DECORATOR, children=[sel.children[0]])
    elif change == "guard_after_body":
        sel.children.reverse()
    elif change == "body_without_state":
        body = sel.children[1]
        body.children = body.children[1:]
    assert strict_lebt_sels(CompiledTree(doc)) is None
    assert not LEBTMachine(doc, ["go", "back", "end"]).fast


def test_sem_fast_tiny_lebt_by_hand() -> None:
    """The hand-written example: the loop back to A leaves the nested structure and the second
    tick enters A; the final state C terminates the tree."""
    machine, generic = both_paths(tiny_lebt(), ["go", "back", "end"])
    assert machine.fast
    state, out = machine.start()
    assert out == ("do_A",) and machine.status(state) == "running"
    for event, expected in [
        ("end", ()),
        ("go", ("do_B",)),
        ("back", ("do_A",)),
        ("go", ("do_B",)),
        ("end", ("do_C",)),
    ]:
        state, out = machine.step(state, event)
        assert out == expected, event
    assert machine.status(state) == "final" and state.running is None
    assert_same_runs(tiny_lebt(), ["go", "back", "end"], random.Random(1), runs=5, length=20)
