"""Stages before a node's first tick on the benchmark's large mutants (``verify/approach.py``;
docs/verification.md §3, "Stages: a sharper bound and a shorter approach").

For the node the 15 000-node `mixed` mutant's per-node check fails at (``bench_reactive.py
--pernode``: the first per-node region's first guarded transition loses its guard), prints:

- the per-node bound's ``P(U)`` before the stages (``reach`` alone), with them (each stage's
  standalone distance) and with the stages coupled (``verify/coupling.py``: the passes a later
  stage's calls force on the earlier ones), the last at the verdict's default limit and, with
  ``--labels N``, at ``shortest_max_labels`` = N (``FSMBT_MAX_SHORTEST_LABELS``);
- the approach's length (a real run to the node's first tick) and its seconds;
- with ``--astar SECONDS``: an A* search over the source tree's interpreter alone to the
  node's first tick, its heuristic the sum over the stages of each stage's standalone distance
  *from its current state* (admissible: each stage must still pass once, alone, in disjoint
  leaves); when it stops, the least ``f`` on its frontier is a lower bound on the leaves before
  the node's first tick, so the gap the verdict leaves is narrowed further, at a cost no
  verdict can pay (minutes).

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_approach.py [--astar 120] [--labels 400000]``.
"""

from __future__ import annotations

import argparse
import heapq
import itertools
import time

from bench_reactive import family_tree, leaves_for

from fsmbt import limits
from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledTree, LeafRequest
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify.approach import StageBounds, approach, last_descendant, stages
from fsmbt.verify.lower_bound import TickCosts


def _failing_node(tree: CompiledTree, path: str) -> int:
    return next(n.id for n in tree.nodes if n.path == path)


def _astar(tree: CompiledTree, target: int, seconds: float) -> tuple[int, bool, int]:
    """(a lower bound on the leaves before ``target``'s first tick, whether it is exact - the
    target reached -, states expanded)."""
    bounds = StageBounds(tree)
    found = stages(tree, target)
    alone = [bounds.standalone(nid) for nid, _p in found]
    assert all(a is not None for a in alone)
    memo: dict[tuple[int, object], int] = {}
    last = last_descendant(tree, target)

    def h(snap: object) -> int:
        total = 0
        for k, ((_nid, passing), stage) in enumerate(zip(found, alone, strict=True)):
            assert stage is not None
            piece = stage.slice(snap)  # type: ignore[arg-type]
            done = piece[0] and not piece[2] and dict(piece[0]).get(0) in passing
            if done:
                continue  # passed in this tick (its parent keeps its status until the tick ends)
            key = (k, piece)
            if key not in memo:
                memo[key] = stage.search(piece, passing, True)[0]
            total += memo[key]
        return total

    interp = BTInterpreter(tree)

    def settle(snap: object, outcome: int | None) -> tuple[object, object] | None:
        snap, event = interp.advance(snap, outcome)  # type: ignore[arg-type]
        while not isinstance(event, LeafRequest):
            if event.status != RUNNING:
                return None
            snap, event = interp.advance(interp.begin_tick(snap), None)
        return snap, event

    start = settle(interp.begin_tick(interp.initial()), None)
    assert start is not None
    counter = itertools.count()
    heap = [(h(start[0]), 0, next(counter), start[0], start[1])]
    best = {start[0]: 0}
    deadline = time.perf_counter() + seconds
    expanded = 0
    while heap:
        f, g, _n, snap, event = heapq.heappop(heap)
        if best.get(snap, g) < g:
            continue
        if target <= event.node.id <= last:  # type: ignore[attr-defined]
            return g, True, expanded
        if time.perf_counter() > deadline:
            return f, False, expanded
        expanded += 1
        kinds = (SUCCESS, FAILURE) if event.node.is_condition else (SUCCESS, FAILURE, RUNNING)  # type: ignore[attr-defined]
        for outcome in kinds:
            nxt = settle(snap, outcome)
            if nxt is None or best.get(nxt[0], g + 2) <= g + 1:
                continue
            best[nxt[0]] = g + 1
            heapq.heappush(heap, (g + 1 + h(nxt[0]), g + 1, next(counter), nxt[0], nxt[1]))
    return 10**9, True, expanded  # never ticked


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--family", default="mixed")
    parser.add_argument("--size", type=int, default=15000)
    parser.add_argument("--node", default="3/4", help="the failing node's path (bench_reactive)")
    parser.add_argument("--astar", type=float, default=0.0, help="seconds for the A* (0: none)")
    parser.add_argument(
        "--labels", type=int, default=0, help="the coupled bound again at this label limit"
    )
    args = parser.parse_args()
    doc = family_tree(args.family, leaves_for(args.size), args.size)
    tree = CompiledTree(doc)
    target = _failing_node(tree, args.node)
    started = time.perf_counter()
    costs = TickCosts(tree)
    reach_only = 0
    node = tree.nodes[target]
    while node.parent is not None:
        reach_only += costs.reach[node.parent][node.index]
        node = tree.nodes[node.parent]
    combined = costs.before(target)
    spent = time.perf_counter() - started
    print(
        f"{args.family} {len(tree.nodes)} nodes, node {args.node}: {len(stages(tree, target))} stages"
    )
    print(
        f"P(U) by reach alone {reach_only}; with the stages {costs.before(target, coupled=False)}; "
        f"coupled {combined} ({spent:.2f} s, shortest_max_labels "
        f"{limits.current().shortest_max_labels})"
    )
    if args.labels:
        started = time.perf_counter()
        with limits.changed(shortest_max_labels=args.labels):
            larger = TickCosts(tree).before(target)
        spent = time.perf_counter() - started
        print(f"coupled {larger} ({spent:.2f} s, shortest_max_labels {args.labels})")
    started = time.perf_counter()
    found = approach(tree, target)
    spent = time.perf_counter() - started
    print(f"approach: {None if found is None else len(found)} leaves ({spent:.2f} s)")
    if args.astar > 0:
        started = time.perf_counter()
        bound, exact, expanded = _astar(tree, target, args.astar)
        spent = time.perf_counter() - started
        said = "exact" if exact else "a lower bound (stopped)"
        print(
            f"A* over the source alone: {bound} leaves, {said}; {expanded} states in {spent:.1f} s"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
