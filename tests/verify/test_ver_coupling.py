"""Stages coupled by reactive parents (``verify/coupling.py``; docs/semantics.md §4d, "Coupled
stages"): the bound never exceeds the interpreter's own fewest leaves before a node's first
tick, it raises the bound where earlier stages must pass again, and the two searches it rests
on give what a plain search of every (state, calls, passes) gives."""

from __future__ import annotations

import heapq
import itertools
import sys
from pathlib import Path

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.compiled import FAILURE, SUCCESS
from fsmbt.verify import coupling
from fsmbt.verify.approach import Standalone, approach
from fsmbt.verify.lower_bound import TickCosts
from support.lower_bound_samples import first_ticks
from support.pernode_trees import pernode_tree

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402

#: Leaves the interpreter's breadth-first search answers here (deeper than the other tests':
#: a coupled stage passes several times before a node's first tick).
DEPTH, STATES = 14, 200_000


def _samples() -> list[BTDocument]:
    """Memory, mixed, decorated (retries and repeats over leaves) and reactive-over-plain trees
    of 12-30 leaves, and trees with Parallel nodes and retrying or repeating decorators over
    controls (``pernode_tree``: the segments of rule 1)."""
    docs = [
        family_tree(family, leaves, 900 + seed)
        for seed in range(8)
        for family in ("memory", "mixed", "decorated", "reactive-plain")
        for leaves in (12, 20, 30)
    ]
    return docs + [pernode_tree(7, 7_000 + seed) for seed in range(60)]


def test_the_coupled_bound_never_exceeds_the_interpreters_fewest_leaves() -> None:
    """``P(U)`` <= the interpreter's fewest leaves before every node it is seen ticking; the
    coupling raises it on some nodes, where it meets the fewest on most, and the approach (a
    real run, never shorter than the fewest) is that short on most of them. A coupled cost one
    too high fails the first assertion."""
    checked = raised = met = approached = 0
    for doc in _samples():
        tree, seen, _root = first_ticks(doc, DEPTH, STATES)
        costs = TickCosts(tree)
        for nid, fewest in seen.items():
            bound = costs.before(nid)
            assert bound is not None and bound <= fewest, (tree.nodes[nid].path, bound, fewest)
            checked += 1
            if bound > (costs.before(nid, coupled=False) or 0):
                raised += 1
                met += bound == fewest
                found = approach(tree, nid)
                approached += found is not None and len(found) == fewest
    assert checked >= 3_000
    assert raised >= 35  # 47 when written (3 331 nodes)
    assert met >= raised * 2 // 3  # 36 of 47 when written
    assert approached >= raised // 2  # 34 of 47 when written


def _tree(root: BTNode) -> CompiledTree:
    return CompiledTree(BTDocument.single(root))


def _leaf(kind: str, name: str) -> BTNode:
    return BTNode("Check" if kind == "Check" else "Do", _KINDS[kind], name=name)


def _control(kind: str, *children: BTNode) -> BTNode:
    return BTNode(kind, NodeKind.CONTROL, children=list(children))


_KINDS = {"Do": NodeKind.ACTION, "Check": NodeKind.CONDITION}


def _plain(alone: Standalone, passing: frozenset[int]) -> tuple[list[int], list[int]]:
    """``D(t)`` and ``H(m)`` by a Dijkstra over every (state, calls, passes) - no dominance
    between labels, no early stop - as an independent reading of rule 4."""
    cap, most = coupling.TICK_CAP, coupling.EXTRA_PASSES
    never = 10**9
    profile = [never] * (cap + 1)
    counts = [never] * (most + 1)
    counter = itertools.count()
    start = (alone.interp.initial(), 0, 0, False)  # (state, calls, passes, first passed)
    heap = [(0, next(counter), start)]
    done = set()
    while heap:
        cost, _n, label = heapq.heappop(heap)
        if label in done:
            continue
        done.add(label)
        snap, calls, passes, passed = label
        for kind, _outcome, after, status in alone.moves(snap, True):
            spent = cost + (kind == "leaf")
            more = calls + (kind == "tick" and not passed)
            if more > cap:
                continue
            if status in passing:
                if not passed:
                    for t in range(more, cap + 1):
                        profile[t] = min(profile[t], spent)
                counts[passes] = min(counts[passes], spent)
                if passes == most:
                    continue
                heapq.heappush(heap, (spent, next(counter), (after, more, passes + 1, True)))
            else:
                heapq.heappush(heap, (spent, next(counter), (after, more, passes, passed)))
    return profile[1:], counts


def _small_subtrees() -> list[BTNode]:
    """The subtrees of 2-4 leaves of seeded memory, mixed, decorated and reactive-over-plain
    trees (each a stage some node has)."""
    found = []
    for seed in range(3):
        for family in ("memory", "mixed", "decorated", "reactive-plain"):
            tree = CompiledTree(family_tree(family, 10, 300 + seed))
            for node in tree.nodes:
                leaves = sum(1 for n in node.source.walk() if n.is_leaf)
                if node.children and 2 <= leaves <= 4:
                    found.append(node.source)
    return found


def test_the_searches_give_what_a_plain_search_gives() -> None:
    """``tick_profile`` (a Dijkstra that drops a label whose state was settled with fewer
    calls) and ``pass_counts``, both over canonical snapshots (docs/semantics.md §4a), against
    ``_plain`` over faithful ones, on small stages with memory, reactive re-ticks, fallbacks
    and decorators: the same ``D(t)`` for every ``t`` and the same ``H(m)``."""
    stages = [
        _control("SequenceWithMemory", _leaf("Do", "a"), _leaf("Do", "b"), _leaf("Check", "c")),
        _control(
            "ReactiveSequence",
            _leaf("Check", "c"),
            _control("SequenceWithMemory", _leaf("Do", "a"), _leaf("Do", "b")),
        ),
        _control(
            "Fallback",
            _control("SequenceWithMemory", _leaf("Do", "a"), _leaf("Check", "c")),
            _leaf("Do", "b"),
        ),
    ]
    compared = 0
    for stage in stages + _small_subtrees():
        for passing in (frozenset({SUCCESS}), frozenset({FAILURE})):
            alone = Standalone(_tree(stage), 0)
            profile, _used = coupling.tick_profile(alone, passing, 10**6)
            counts, _more = coupling.pass_counts(alone, passing, 10**6)
            expected_profile, expected_counts = _plain(alone, passing)
            assert profile == expected_profile, (stage.type, passing)
            assert counts == expected_counts, (stage.type, passing)
            compared += 1
    assert compared >= 80  # 94 when written: 47 stages, both passing sets; canonical states
    # merge faithful ones on 80 of the 88 subtree searches (fewer labels settled)
