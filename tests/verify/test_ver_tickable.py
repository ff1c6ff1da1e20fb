"""Nodes the tree never ticks (``verify/tickable.py``; docs/semantics.md §4d, "Dead nodes").

Two claims, each against something the analysis does not use:
- *sound*: no node it calls dead is ever ticked by fsmbt's interpreter running the whole
  tree (every reachable snapshot explored, every leaf outcome offered at every request);
- *what it buys*: a one-transition mutant of the per-node machine inside a dead node's
  fragment is proven equivalent per node exactly when the whole product proves it, and a
  mutant that lets the parent enter a dead child is never proven (the whole product refutes
  it). Counts are printed (``pytest -s``).
"""

from __future__ import annotations

import copy
import random
import sys
from collections import Counter
from pathlib import Path

from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.compress import inline_and_compress
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledTree, LeafRequest
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify.compositional import compositional_report, tree_regions
from fsmbt.verify.pernode import NODE_ATTR
from fsmbt.verify.report import PER_NODE
from fsmbt.verify.tickable import never_ticked
from support.pernode_mutants import BOUND, pernode_machine, whole
from support.pernode_trees import pernode_tree

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402

#: Most snapshots the concrete exploration of one tree holds (a tree past it is skipped).
CONCRETE_LIMIT = 60_000


def merged(doc: BTDocument) -> CompiledTree:
    """The tree as the per-node check reads a region headed by its root (lemma M's merge)."""
    return CompiledTree(BTDocument.single(inline_and_compress(doc).compression.root))


def ticked_nodes(tree: CompiledTree) -> set[int] | None:
    """Every node id the interpreter ticks in some run of ``tree`` (ticks repeated forever,
    every outcome at every leaf), from an exhaustive search of its snapshots; ``None`` past
    ``CONCRETE_LIMIT``. A node is ticked when it is on the call stack: the leaves requested
    and every ancestor of theirs, plus internal leaves met on the way (their frames)."""
    interp = BTInterpreter(tree, exactly_once=True)
    start = interp.initial()
    seen = {(start, None)}
    todo: list[tuple[object, object]] = [(start, None)]
    ticked: set[int] = {0}
    while todo:
        snap, request = todo.pop()
        if request is None:
            moves = [interp.advance(interp.begin_tick(snap), None)]
        else:
            node = tree.nodes[request]
            outcomes = [SUCCESS, FAILURE] + ([RUNNING] if not node.is_condition else [])
            moves = [interp.advance(snap, o) for o in outcomes]
        for nxt, event in moves:
            for frame in nxt[2]:
                ticked.add(frame[0])
            key = (nxt, event.node.id if isinstance(event, LeafRequest) else None)
            if key[1] is not None:
                ticked.add(key[1])
            if key[0][2] == () and key[1] is None:
                key = ((nxt[0], nxt[1], (), False), None)
            if key not in seen:
                if len(seen) >= CONCRETE_LIMIT:
                    return None
                seen.add(key)
                todo.append(key)
    return ticked


def sample(count: int, seed: int) -> list[BTDocument]:
    rng = random.Random(seed)
    docs = []
    for index in range(count):
        if index % 2:
            docs.append(pernode_tree(rng.randint(3, 8), seed * 1000 + index))
        else:
            docs.append(family_tree("decorated", rng.randint(4, 12), seed * 1000 + index))
    return docs


def test_no_dead_node_is_ever_ticked_by_the_interpreter() -> None:
    tally: Counter[str] = Counter()
    for doc in sample(160, seed=31):
        tree = merged(doc)
        ticked = ticked_nodes(tree)
        if ticked is None:
            tally["past the limit"] += 1
            continue
        dead = never_ticked(tree)
        assert not dead & ticked, [tree.nodes[d].path for d in dead & ticked]
        tally["trees"] += 1
        tally["nodes"] += len(tree.nodes)
        tally["dead"] += len(dead)
        tally["never ticked"] += len(tree.nodes) - len(ticked)
    print(f"\n[tickable] {dict(tally)}")
    assert tally["trees"] >= 120
    assert tally["dead"] >= 60  # the sample has dead code to find
    # what the over-approximation misses (concretely dead, called live) stays small
    assert tally["dead"] >= 0.8 * tally["never ticked"], dict(tally)


def _dead_paths(doc: BTDocument) -> tuple[set[str], set[str]] | None:
    """(paths of dead nodes, paths of their live parents) when the whole tree is one region
    written per node (else ``None``)."""
    regions = tree_regions(doc)
    if len(regions) != 1 or regions[0] is not doc.main.root:
        return None
    tree = merged(doc)
    dead = never_ticked(tree)
    parents = {tree.nodes[tree.nodes[d].parent].path for d in dead} - {
        tree.nodes[d].path for d in dead
    }
    return {tree.nodes[d].path for d in dead}, parents


def test_mutants_inside_dead_fragments_are_proven_and_entering_one_is_not() -> None:
    rng = random.Random(5)
    tally: Counter[str] = Counter()
    for doc in sample(240, seed=37):
        paths = _dead_paths(doc)
        if not paths or not paths[0]:
            continue
        dead, parents = paths
        try:
            with limits.changed(conversion_max_states=BOUND):
                model = bt_to_hfsm(doc, pernode=True, max_states=BOUND).model
        except FsmbtError:
            continue
        sub = pernode_machine(model)
        if sub is None:
            continue
        inside = [t for t in sub.transitions if sub.states[t.source].attrs.get(NODE_ATTR) in dead]
        entries = {
            t.target
            for t in sub.transitions
            if sub.states[t.target].attrs.get(NODE_ATTR) in dead
            and sub.states[t.source].attrs.get(NODE_ATTR) not in dead
        }
        into = [t for t in sub.transitions if sub.states[t.source].attrs.get(NODE_ATTR) in parents]
        cases: list[tuple[str, int, str]] = []
        if inside:  # retargeted within its own node's fragment: the side conditions hold
            t = inside[rng.randrange(len(inside))]
            tag = sub.states[t.source].attrs.get(NODE_ATTR)
            same = [n for n, st in sub.states.items() if st.attrs.get(NODE_ATTR) == tag]
            cases.append(("inside", sub.transitions.index(t), rng.choice(same)))
        if into and entries:
            t = rng.randrange(len(into))
            cases.append(("into", sub.transitions.index(into[t]), rng.choice(sorted(entries))))
        for kind, index, target in cases:
            mutant = copy.deepcopy(model)
            msub = pernode_machine(mutant)
            assert msub is not None
            if msub.transitions[index].target == target:
                continue
            msub.transitions[index].target = target
            verdict = whole(doc, mutant)
            if verdict is None:
                continue
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, mutant, max_states=BOUND)
            proved = report is not None and report.method == PER_NODE and report.equivalent
            tally[f"{kind}: whole {verdict}, per node {'proved' if proved else 'not'}"] += 1
            if proved:
                assert verdict is True, f"per node proved a {kind} mutant the whole product refutes"
            if kind == "inside" and verdict is True:
                assert proved, f"a mutant inside a dead fragment left to the whole product: {_why}"
    print(f"\n[dead fragments] {dict(tally)}")
    assert tally["inside: whole True, per node proved"] >= 20
    assert sum(v for k, v in tally.items() if k.startswith("into: whole False")) >= 10
