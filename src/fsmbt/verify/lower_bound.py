"""A lower bound on the length of *any* counterexample of a pair whose per-node check failed
(docs/semantics.md §4d, "A lower bound on any counterexample, from the per-node proof";
docs/verification.md §3, "A lower bound from the per-node proof"; issue 27 item 1).

Why: a lifted counterexample of ``L`` inputs is shortest when nothing shorter separates the two
whole machines. The breadth-first search of ``verify/shortest.py`` settles that only while the
first ``L - 1`` levels stay small; on a 15 000-node mutant each input sequence reaches a new
pair and 386 levels are out of reach. A lower bound ``B`` on every counterexample's length
closes the gap when ``B == L``.

The argument (the full text is docs/semantics.md §4d):

1. when the complete walk (``pernode.complete_walk``: every live node checked, no stray jump,
   no early stop; a node failing with and without ``halt`` settled haltable) fails at the set
   ``F`` of nodes (the caller has checked the skeleton around the one region, §4c), the
   composition of §4d, read step by step, says the two machines agree on every input sequence
   until some node ``U`` of ``F`` has its local pair (tree side with σ_U as settled, fragment
   side) output differently; every other node's pair is related at every step before that
   (its local check held with the σ its children were settled with);
2. before ``U``'s first tick its local pair is at rest on both sides, so a difference needs
   (a) the leaves consumed before ``U`` is first ticked - at least ``P(U)``, the sum over
   ``U``'s ancestors ``A`` of ``reach(A, i)``: the cheapest way, from ``A``'s rest, to have
   ``A`` tick its child ``i`` towards ``U`` for the first time, or, when larger, the sum of
   ``A``'s stages' standalone distances (``verify/approach.py``: each earlier child of a
   sequence or fallback ancestor must pass once before, run alone exactly), or the stages'
   coupled bound (``verify/coupling.py``: under a reactive parent, each call a later stage
   makes forces the earlier ones to pass again) plus the other ancestors' ``reach`` - and (b) the
   leaves under ``U`` until its pair differs - at least ``k(U)``, the cheapest path of ``U``'s
   local product from rest to a step whose outputs differ (``U``'s children are at rest at
   its first tick). In both searches a child ``j`` returning ``s`` costs ``first_j(s)`` the
   first time and ``any_j(s)`` later (the search state records which children were touched);
3. ``any_x(s)``: a lower bound on the leaves *one* tick of ``x`` consumes to return ``s``, from
   *any* state ``x`` can reach (fresh, resumed, halted, done): the least cost over every
   reachable state of ``x`` over abstract children, each child event costing its own ``any``;
   ``first_x(s)``: the same for ``x``'s first tick from rest (children's first events costing
   their ``first``). An environment leaf costs 1, a leaf with a fixed status 0. The leaves
   under different children are different leaves, so the costs add.

So every counterexample has at least ``B = min over U in F of P(U) + k(U)`` inputs. Node
behaviour is the interpreter's (``BTInterpreter`` on the node over abstract leaves, ``tick`` and
``halt`` between ticks: the same abstraction as the per-node check), never the converter's.
Each search is a Dijkstra over costs >= 0; when one passes its cap, its frontier's least cost
(still a lower bound) is used, or 0 where no frontier bounds it.

Cost: one abstract exploration per distinct (node shape, children's costs) of at most
``ABSTRACT_LIMIT`` states, a walk up each failing node's ancestors, one local product per
distinct failing problem of at most ``pernode.LOCAL_LIMIT`` pairs.
"""

from __future__ import annotations

import dataclasses
import heapq
import itertools
from collections.abc import Hashable
from dataclasses import dataclass
from typing import Any

from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.bt_interpreter import (
    BTLivelock,
    CompiledNode,
    CompiledTree,
)
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify.abstract_node import AbstractRun, Edge, State
from fsmbt.verify.approach import StageBounds, stages
from fsmbt.verify.coupling import CoupledBound
from fsmbt.verify.pernode import (
    LOCAL_LIMIT,
    STATUS_OF,
    CompleteWalk,
    FailedUnit,
    local_machines,
)

#: Most states one node's abstract exploration holds (past it: that node's costs are 0).
ABSTRACT_LIMIT = 5_000
ALL = (SUCCESS, FAILURE, RUNNING)

Costs = dict[int, int]  # status -> least leaves one tick returning it consumes


@dataclass(frozen=True)
class NodeCosts:
    """Lower bounds on the leaves a node consumes: ``first[s]`` for its first tick from rest
    returning ``s`` (absent: the first tick never returns ``s``), ``any[s]`` for one tick from
    any state it can reach returning ``s`` (absent: never). ``first[s] >= any[s]``."""

    first: dict[int, int]
    any: dict[int, int]

    def key(self) -> tuple[Any, ...]:
        return (tuple(sorted(self.first.items())), tuple(sorted(self.any.items())))


@dataclass
class _Shape:
    """What one abstract exploration gives: the node's costs and ``reach`` (child -> least
    cost from rest to its first tick)."""

    costs: NodeCosts
    reach: dict[int, int]


#: Most (state, children touched) pairs one refined search settles before it stops and
#: answers with its frontier's least cost (still a lower bound).
PAIR_LIMIT = 50_000


def _explore(node: CompiledNode, kids: list[NodeCosts]) -> _Shape:
    """Rule 3 (``tick``: ``any`` and ``first``) and rule 2a (``reach``) of the module
    docstring for one node over abstract children."""
    free = {s: 0 for s in ALL}
    zero = _Shape(NodeCosts(free, free), {i: 0 for i in range(len(kids))})
    try:
        machine = AbstractRun(node, [k.any for k in kids])
        start: State = machine.start()
        graph: dict[State, list[Edge]] = {}
        todo = [start]
        while todo:
            state = todo.pop()
            if state in graph:
                continue
            if len(graph) >= ABSTRACT_LIMIT:
                return zero
            graph[state] = machine.edges(state)
            todo.extend(nxt for _i, _c, nxt, _e in graph[state] if nxt not in graph)
    except (FsmbtError, ValueError, BTLivelock):
        return zero  # a construct the abstract run refuses: nothing is bounded
    # any: from every state between ticks at once, through child outcomes, to an exit
    anyc: dict[int, int] = {}
    heap: list[tuple[int, int, State]] = []
    counter = itertools.count()
    for state, out in graph.items():
        if state[1] is None:
            _input, _cost, nxt, event = out[0]
            if event[0] == "exit":
                anyc[event[1]] = 0
            else:
                heapq.heappush(heap, (0, next(counter), nxt))
    done: set[State] = set()
    while heap:
        cost, _n, state = heapq.heappop(heap)
        if state in done:
            continue
        done.add(state)
        for _input, extra, nxt, event in graph[state]:
            if event[0] == "exit":
                anyc[event[1]] = min(anyc.get(event[1], cost + extra), cost + extra)
            elif nxt not in done:
                heapq.heappush(heap, (cost + extra, next(counter), nxt))
    first, reach = _refined(graph, start, kids)
    first = {s: max(c, anyc.get(s, c)) for s, c in first.items()}
    return _Shape(NodeCosts(first, anyc), reach)


def _refined(
    graph: dict[State, list[Edge]], start: State, kids: list[NodeCosts]
) -> tuple[dict[int, int], dict[int, int]]:
    """From rest, each child's first event costing its ``first``, later ones its ``any``
    (the search state: the abstract state and the children touched so far): ``first`` (the
    node's first tick to each exit) and ``reach`` (each child's first tick, over any ticks
    and halts). Past ``PAIR_LIMIT`` pairs, every value not yet settled is the frontier's least
    cost."""
    first: dict[int, int] = {}
    reach: dict[int, int] = {}
    counter = itertools.count()
    # (cost, n, state, touched, ticks): ticks = 0 before the first tick, 1 during it, 2 after
    heap: list[tuple[int, int, State, int, int]] = [(0, next(counter), start, 0, 0)]
    done: set[tuple[State, int, int]] = set()
    cost = 0
    while heap:
        cost, _n, state, touched, ticks = heapq.heappop(heap)
        if (state, touched, ticks) in done:
            continue
        if len(done) >= PAIR_LIMIT:
            break
        done.add((state, touched, ticks))
        position = state[1]
        if position is not None:
            reach.setdefault(position, cost)
        for symbol, _extra, nxt, event in graph[state]:
            extra, now = 0, touched
            if position is not None:
                costs = kids[position].any if touched >> position & 1 else kids[position].first
                status = symbol
                if status not in costs:
                    continue  # this child never returns that from where it is
                extra, now = costs[status], touched | 1 << position
            after = ticks
            if symbol == "tick":
                after = 1 if ticks == 0 else ticks
            if event[0] == "exit" and after == 1:
                first[event[1]] = min(first.get(event[1], cost + extra), cost + extra)
                after = 2
            heapq.heappush(heap, (cost + extra, next(counter), nxt, now, after))
    else:
        return first, reach
    for status in ALL:  # stopped: a path not yet explored costs at least the frontier
        first[status] = min(first.get(status, cost), cost)
    for i in range(len(kids)):
        reach.setdefault(i, cost)
    return first, reach


class TickCosts:
    """``NodeCosts`` and ``reach`` for every node of a compiled tree, bottom-up (no
    recursion), one exploration per distinct (type, ports, children's costs)."""

    def __init__(self, tree: CompiledTree) -> None:
        self.tree = tree
        self.stages = StageBounds(tree)
        self.coupling = CoupledBound(tree, self.stages)
        self.costs: dict[int, NodeCosts] = {}
        self.reach: dict[int, dict[int, int]] = {}
        memo: dict[Hashable, _Shape] = {}
        for node in reversed(tree.nodes):
            if not node.children:
                leaf = _leaf_costs(node)
                self.costs[node.id] = NodeCosts(leaf, leaf)
                continue
            kids = [self.costs[c] for c in node.children]
            attrs = tuple(sorted((k, v) for k, v in node.source.attrs.items() if k != "name"))
            key = (node.type, node.source.semantics, attrs, tuple(k.key() for k in kids))
            shape = memo.get(key)
            if shape is None:
                shape = memo[key] = _explore(node, kids)
            self.costs[node.id] = shape.costs
            self.reach[node.id] = shape.reach

    def before(self, nid: int, coupled: bool = True) -> int | None:
        """``P``: least leaves consumed before ``nid`` is first ticked (``None``: never). Per
        ancestor, the larger of its ``reach`` and its stages' standalone distances
        (``verify/approach.py``): both bound the leaves under its other children before the
        path child's first tick, and ancestors' other children are disjoint subtrees. Or,
        when larger, the coupled stages' bound (``verify/coupling.py``) plus the ``reach`` of the
        ancestors without stages (disjoint from every stage); ``coupled`` False leaves that
        bound out (for the benchmarks and tests that compare the two)."""
        total = 0
        unstaged = 0  # the ancestors without stages: their ``reach`` alone
        nodes = self.tree.nodes
        staged = self.stages.per_ancestor(nid)
        child = nid
        parent = nodes[nid].parent
        while parent is not None:
            step = self.reach[parent].get(nodes[child].index)
            if step is None:
                return None  # the interpreter never ticks that child: neither is the node
            total += max(step, staged.get(parent, 0))
            if parent not in staged:
                unstaged += step
            child, parent = parent, nodes[parent].parent
        if not staged or not coupled:
            return total
        # the stages coupled through reactive parents (``verify/coupling.py``): a bound on
        # the leaves under all of them together, beside the other ancestors' reach
        refail = {
            j: min((self.costs[j].any[s] for s in passing if s in self.costs[j].any), default=0)
            for j, passing in stages(self.tree, nid)
        }
        return max(total, unstaged + self.coupling.before(nid, refail))


def _leaf_costs(node: CompiledNode) -> dict[int, int]:
    if node.internal_status is not None:
        return {node.internal_status: 0}
    if node.kind is NodeKind.ACTION:
        return {SUCCESS: 1, FAILURE: 1, RUNNING: 1}
    if node.kind is NodeKind.CONDITION:
        return {SUCCESS: 1, FAILURE: 1}
    raise FsmbtError(f"leaf {node.label}: neither an environment leaf nor a fixed status")


def local_distance(unit: FailedUnit, kids: list[NodeCosts]) -> int:
    """``k(U)``: the least child-outcome cost of a path of ``U``'s local product (σ_U and
    ``halt`` as settled) from rest to a step whose outputs differ, each child's first outcome
    costing its ``first``, later ones its ``any`` (the children are at rest when ``U`` is
    first ticked); past ``LOCAL_LIMIT`` pairs, the frontier's least cost."""
    tree, frag = local_machines(unit.problem, unit.sigma, unit.can_halt)
    start = (tree.start()[0], frag.start()[0], 0)
    counter = itertools.count()
    heap: list[tuple[int, int, Any]] = [(0, next(counter), start)]
    done: set[Any] = set()
    while heap:
        cost, _n, pair = heapq.heappop(heap)
        if pair is None:
            return cost  # a differing step
        if pair in done:
            continue
        if len(done) >= LOCAL_LIMIT:
            return cost
        done.add(pair)
        t, f, touched = pair
        position = t[1]
        for symbol in tree.inputs(t):
            extra, now = 0, touched
            if position is not None:
                costs = kids[position].any if touched >> position & 1 else kids[position].first
                status = STATUS_OF[symbol]
                if status not in costs:
                    continue  # the child never returns that from where it is
                extra, now = costs[status], touched | 1 << position
            t2, out_t = tree.step(t, symbol)
            f2, out_f = frag.step(f, symbol)
            nxt = None if out_t != out_f or t2[1] != f2[0] else (t2, f2, now)
            if nxt is None or nxt not in done:
                heapq.heappush(heap, (cost + extra, next(counter), nxt))
    raise FsmbtError(f"the local product of {unit.problem.node.label} has no differing step")


@dataclass(frozen=True)
class LowerBound:
    """``bound``: no counterexample has fewer inputs; ``node``: the failing node that gives it
    (its path), with ``before`` (P) and ``inside`` (k); ``failing``: the size of ``F``;
    ``cut``: some coupled-stage search stopped at ``shortest_max_labels`` (a larger limit may
    raise the bound; ``verify/coupling.py``)."""

    bound: int
    node: str
    before: int
    inside: int
    failing: int
    cut: bool = False


def lower_bound(whole: CompiledTree, found: CompleteWalk) -> LowerBound | None:
    """``B`` of the module docstring over the whole tree ``whole`` (the source with the
    region replaced by the walk's merged region, nodes shared: ``lift.whole_tree``) and the
    complete walk ``found``; ``None`` when no node fails (nothing to bound) or a failing node
    is not in ``whole``."""
    costs = TickCosts(whole)
    by_source = {id(n.source): n.id for n in whole.nodes}
    local: dict[Hashable, int] = {}
    best: LowerBound | None = None
    for unit in found.failed:
        nid = by_source.get(id(unit.problem.node.source))
        if nid is None:
            return None
        before = costs.before(nid)
        if before is None:
            continue  # never ticked: never separates
        kids = [costs.costs[c] for c in whole.nodes[nid].children]
        key = (
            unit.problem.key,
            tuple(sorted(unit.sigma.items())),
            unit.can_halt,
            tuple(k.key() for k in kids),
        )
        inside = local.get(key)
        if inside is None:
            inside = local[key] = local_distance(unit, kids)
        if best is None or before + inside < best.bound:
            path = unit.problem.node.path or "the root"
            best = LowerBound(before + inside, path, before, inside, len(found.failed))
    if best is not None and costs.coupling.cut:
        best = dataclasses.replace(best, cut=True)
    return best
