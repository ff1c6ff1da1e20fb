"""The per-node conversion of regions (``convert/bt_pernode``; issue 27 item 1): each region
written as one small sub-machine per node, its memory as data, never explored.

Proof obligation (docs/semantics.md §4d): the flat meaning of the result is the tree's
leaf-execution machine. The whole-product check discharges it on every tree here (and the
per-node check, ``verify/pernode.py``, proves most of them on its own; it never proves one
the whole product refutes: tests/verify/test_ver_pernode.py): seeded
trees of the bench families (``benchmarks/bench_reactive.py``: memory, mixed, reactive-plain,
decorated) at small sizes and trees over every kind the module writes
(``tests/support/pernode_trees.py``), each converted with ``pernode=True``. Counts are printed
(``pytest -s``). The checker is not vacuous here: a converter that forgets the halt resets
is caught, and one-transition mutants of the per-node sub-machines are told apart.
"""

from __future__ import annotations

import copy
import random
import sys
from collections import Counter
from pathlib import Path

from fsmbt.convert.bt_pernode import NODE_ATTR, PERNODE_MIN_LOG2, pernode_estimate
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.pernode.writer import Writer
from fsmbt.formats import dumps
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import ASSIGN, COND
from fsmbt.verify.compositional import compositional_report
from fsmbt.verify.native import check
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import PER_NODE
from support.pernode_trees import pernode_tree

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402

FAMILIES = ("memory", "mixed", "reactive-plain", "decorated")


def generated(count: int, seed: int) -> list[tuple[str, BTDocument]]:
    """``count`` seeded small trees: the bench families, then every kind (alternating)."""
    rng = random.Random(seed)
    docs: list[tuple[str, BTDocument]] = []
    for index in range(count):
        leaves = rng.randint(2, 9)
        if index % 2 == 0:
            family = FAMILIES[(index // 2) % len(FAMILIES)]
            docs.append((f"{family}{index}", family_tree(family, leaves, seed * 10_000 + index)))
        else:  # at most 7 leaves: a Parallel's product of completed sets grows fast
            docs.append((f"kinds{index}", pernode_tree(min(leaves, 7), seed * 10_000 + index)))
    return docs


def whole_product(doc: BTDocument, fsm: FSM) -> bool:
    source, result, _mode = machines_for(doc, fsm)
    return check(source, result).equivalent


def pernode_machines(fsm: FSM) -> list[FSM]:
    return [
        state.regions[0]
        for _path, _machine, state in fsm.walk()
        if state.regions and state.regions[0].name.startswith("pernode_")
    ]


def test_pernode_regions_are_proven_on_2000_generated_trees() -> None:
    tally: Counter[str] = Counter()
    for label, doc in generated(2000, seed=27):
        try:
            result = bt_to_hfsm(doc, pernode=True)
        except FsmbtError as exc:  # a Parallel's own region too large: not this module's
            tally[f"refused {type(exc).__name__}"] += 1
            continue
        written = result.stats["pernode_regions"]
        tally["per-node regions"] += written
        tally["trees with one"] += bool(written)
        assert whole_product(doc, result.model), label
        tally["proven"] += 1
        report, _why = compositional_report(doc, result.model)  # agrees: tests/verify too
        tally["also proven per node"] += report is not None and report.method == PER_NODE
    print(f"\n[per-node conversion] {dict(tally)}")
    assert tally["proven"] >= 1900 and tally["trees with one"] >= 1500
    assert tally["also proven per node"] >= 1200


def test_a_converter_without_halt_resets_is_caught(monkeypatch) -> None:
    """Halting a child must reset its subtree's memory: without it, trees differ."""
    monkeypatch.setattr(Writer, "halt", lambda self, nid: [])
    differ = 0
    for _label, doc in generated(200, seed=5):
        try:
            result = bt_to_hfsm(doc, pernode=True)
        except FsmbtError:
            continue
        differ += not whole_product(doc, result.model)
    assert differ >= 10


def test_one_transition_mutants_of_pernode_machines_are_told_apart() -> None:
    """A retargeted transition or a dropped guard in a per-node sub-machine: the checker tells
    most apart (a few are harmless: a guard whose other branch is never taken)."""
    rng = random.Random(3)
    tally: Counter[tuple[str, bool]] = Counter()
    for _label, doc in generated(200, seed=9):
        try:
            model = bt_to_hfsm(doc, pernode=True).model
        except FsmbtError:
            continue
        mutant = copy.deepcopy(model)
        machines = pernode_machines(mutant)
        if not machines:
            continue
        sub = machines[0]
        transition = rng.choice(sub.transitions)
        if COND in transition.attrs and rng.random() < 0.5:
            del transition.attrs[COND]
            operator = "drop guard"
        else:
            transition.target = rng.choice([s for s in sub.states if s != transition.target])
            operator = "retarget"
        try:
            tally[(operator, whole_product(doc, mutant))] += 1
        except FsmbtError:
            tally[(operator, False)] += 1  # e.g. an eventless cycle without a leaf
    print(f"\n[per-node mutants] {dict(tally)}")
    caught = tally[("retarget", False)] + tally[("drop guard", False)]
    assert caught >= 0.6 * sum(tally.values())


def test_small_trees_keep_the_compact_form_byte_for_byte() -> None:
    """Below the estimate's threshold the default is the compact form, unchanged."""
    compared = 0
    for label, doc in generated(300, seed=11):
        if pernode_estimate(doc.main.root) >= PERNODE_MIN_LOG2:
            continue
        try:
            default = bt_to_hfsm(doc)
            compact = bt_to_hfsm(doc, pernode=False)
        except FsmbtError:
            continue
        assert dumps(default.model, "scxml") == dumps(compact.model, "scxml"), label
        assert default.stats["pernode_regions"] == 0
        compared += 1
    assert compared >= 100


def test_big_trees_are_written_per_node_linear_in_the_tree() -> None:
    """A 3 000-node mixed tree converts without exploring its regions: states, variables and
    transitions at most a small multiple of the nodes, every state tagged with its node."""
    doc = family_tree("mixed", 2000, 3000)
    nodes = sum(1 for _t, _n in doc.nodes())
    result = bt_to_hfsm(doc)
    assert result.stats["pernode_regions"] >= 1
    machines = pernode_machines(result.model)
    states = sum(len(m.states) for m in machines)
    transitions = sum(len(m.transitions) for m in machines)
    assert states <= 3 * nodes and transitions <= 8 * nodes
    assert result.stats["data_variables"] <= 2 * nodes
    for machine in machines:
        for state in machine.states.values():
            assert state.final or NODE_ATTR in state.attrs
        assert any(ASSIGN in t.attrs for t in machine.transitions)
