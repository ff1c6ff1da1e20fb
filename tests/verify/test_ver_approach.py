"""Stages before a node's first tick (``verify/approach.py``; docs/semantics.md §4d, "Stages";
docs/verification.md §3): the standalone distances never exceed the interpreter's own fewest
leaves before a node is ticked, they add to the per-node bound where it was weak, and the
approach is a real run that ticks its target first at its last outcome."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledTree, LeafRequest
from fsmbt.semantics.compiled import RUNNING
from fsmbt.verify import approach as approach_module
from fsmbt.verify.approach import StageBounds, approach, stages
from fsmbt.verify.lower_bound import TickCosts
from support.lower_bound_samples import first_ticks
from support.pernode_trees import seeded_trees

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402


def _trees() -> list:
    """Small seeded trees of every sample family, and memory / mixed trees of 8-14 leaves
    (where an earlier sibling needs several ticks to pass)."""
    docs = seeded_trees(40, seed=77)
    for index, family in enumerate(("memory", "mixed") * 6):
        docs.append(family_tree(family, 8 + index % 7, 500 + index))
    return docs


def _ancestor_reach(costs: TickCosts, tree: CompiledTree, nid: int) -> int:
    """The per-node bound's ``P(U)`` before stages: the sum of ``reach`` alone."""
    total, node = 0, tree.nodes[nid]
    while node.parent is not None:
        total += costs.reach[node.parent][node.index]
        node = tree.nodes[node.parent]
    return total


def test_stage_distances_never_exceed_the_interpreters_fewest_leaves() -> None:
    """For every node the interpreter is seen ticking within its search: the stages' sum <=
    the fewest leaves before it, and so is the combined ``P(U)``; the stages raise ``P(U)``
    above ``reach`` alone on some nodes and meet the fewest leaves on many (a stage distance
    one too high fails the first assertion)."""
    checked = raised = tight = 0
    for doc in _trees():
        tree, seen, _root = first_ticks(doc)
        costs = TickCosts(tree)
        for nid, fewest in seen.items():
            staged = sum(costs.stages.per_ancestor(nid).values())
            combined = costs.before(nid)
            assert staged <= fewest, (tree.nodes[nid].path, staged, fewest)
            assert combined is not None and combined <= fewest
            checked += 1
            raised += combined > _ancestor_reach(costs, tree, nid)
            tight += staged == fewest
    assert checked >= 500
    assert raised >= 40  # 82 when written
    assert tight >= checked * 3 // 4  # 495 of 541 when written


def _leaves_until_ticked(tree: CompiledTree, target: int, outcomes: list[int]) -> int | None:
    """Feed ``outcomes`` to the interpreter as the leaf machine does (a new tick after RUNNING,
    a stop after SUCCESS or FAILURE); the number answered when ``target`` is first seen on
    the ticking path (``None``: never)."""
    interp = BTInterpreter(tree)
    snap, event = interp.advance(interp.begin_tick(interp.initial()), None)
    for answered in range(len(outcomes) + 1):
        while not isinstance(event, LeafRequest):
            if event.status != RUNNING:
                return None
            snap, event = interp.advance(interp.begin_tick(snap), None)
        if any(frame[0] == target for frame in snap[2]):
            return answered
        if answered == len(outcomes):
            return None
        snap, event = interp.advance(snap, outcomes[answered])
    return None


def test_the_approach_ticks_its_target_first_at_its_end() -> None:
    """``approach`` is a real run: the interpreter reaches the target exactly after its last
    outcome, never before, and no run is shorter than the fewest leaves."""
    driven = exact = 0
    for doc in _trees():
        tree, seen, _root = first_ticks(doc)
        for nid, fewest in seen.items():
            if nid == 0 or not stages(tree, nid):
                continue
            found = approach(tree, nid)
            if found is None:
                continue
            assert _leaves_until_ticked(tree, nid, found) == len(found)
            assert len(found) >= fewest
            driven += 1
            exact += len(found) == fewest
    assert driven >= 300
    assert exact >= driven * 9 // 10  # 334 of 334 when written


def test_past_the_budget_a_stage_claims_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    """With no state budget left every stage counts 0 (no claim), and ``P(U)`` falls back to
    ``reach`` alone."""
    doc = family_tree("memory", 12, 501)
    tree = CompiledTree(doc)
    deepest = max(range(len(tree.nodes)), key=lambda n: len(stages(tree, n)))
    assert sum(StageBounds(tree).per_ancestor(deepest).values()) > 0
    monkeypatch.setattr(approach_module, "BOUND_BUDGET", 0)
    assert sum(StageBounds(tree).per_ancestor(deepest).values()) == 0
