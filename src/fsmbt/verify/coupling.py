"""Stages coupled by reactive parents: a lower bound that counts the passes a later stage's
ticks force on the earlier ones (issue 27 item 1, ninth round; docs/semantics.md §4d,
"Coupled stages"; docs/verification.md §3).

Why: ``verify/approach.py`` bounds the leaves before a node ``U``'s first tick by the sum of
its *stages*' standalone distances ``d_j`` (each earlier sibling on the way must pass once).
Under a ``ReactiveFallback`` or ``ReactiveSequence`` that sum ignores what the stages cost
*together*: the parent calls its children again from child 0 on every call, so each call in
which a later stage makes progress makes every earlier stage pass once more. On the 15 560-node
mutant of the benchmark the sum is 76 while the shortest run found takes 106.

Rules (node behaviour is the interpreter's, ``BTInterpreter``; a stage is its subtree run
alone, ``approach.Standalone``, under *any* interleaving of calls and halts):

1. *segments*: walking from the root to ``U``, the stages whose parents are joined by ancestors
   of the ``sequence`` or ``reactive`` families only form a segment; another kind of ancestor
   (a decorator that retries or repeats, a ``Parallel``) may call the path below it several
   times in one call of its own, so it ends the segment and no coupling crosses it;
2. *calls*: within a segment, one call of a stage's parent calls each node on the way to ``U``
   at most once (a sequence or reactive node never goes back within a call). Before its first
   pass a stage ``j`` returns a non-pass status in all its calls but the last (``t_j`` calls in
   all), and its parent, then every ancestor up to the segment's top, returns with it: no later
   stage is called in the same call. So the ``t_j - 1`` non-pass calls of the stages after a
   stage ``i`` are distinct calls of ``i``'s parent;
3. *coupled*: when ``i``'s parent is of the ``reactive`` family it calls ``i`` first in each of
   those calls, and ``i`` passes in each (else the later stage is not called); with the final
   call towards ``U``, ``i`` passes at least ``1 + M_i`` times, ``M_i = sum over later stages j
   of the segment of (t_j - 1)``;
4. *costs*: with ``D_i(t)`` the least leaves before ``i``'s first pass in at most ``t`` calls
   (a search over (state, calls), ``tick_profile``), ``H_i(m)`` the least leaves for ``1 + m``
   passes (a search over (state, passes), ``pass_counts``) and ``r_i`` a bound on one pass from
   any state (``lower_bound.TickCosts``' ``any``), stage ``i`` consumes at least
   ``G_i(t_i, M_i) = max(D_i(t_i) + M_i * r_i, max over m <= M_i of H_i(m) + (M_i - m) * r_i)``
   leaves (every pass after the ``m``-th costs at least ``r_i``; ``D_i(t)`` is also at least
   ``L_i(w) - w * t`` for the least cost ``L_i(w)`` of a first pass when each call costs ``w``
   more, ``WEIGHTS``). Stages are disjoint subtrees, so the leaves before ``U``'s first tick
   number at least ``min over (t_j) of sum over i of G_i(t_i, M_i)``: a dynamic
   programme over the stages from the last, its state the running sum ``S`` of ``t_j - 1``
   (capped at ``SUM_CAP``: ``G`` grows with ``M``, so a smaller ``S`` only lowers the bound).
   A search stopped at its cap answers with its frontier's least cost (a bound still). The
   searches run over canonical snapshots (``Standalone.moves``, docs/semantics.md §4a: the
   same future under calls, halts and leaf outcomes, so the same costs over fewer states).

Cost: per stage, a profile search, one weighted search per ``WEIGHTS`` entry and a pass-count
search, at most ``PROFILE_LIMIT``, ``WEIGHT_LIMIT`` and ``shortest_max_labels``
(``fsmbt.limits``, ``FSMBT_MAX_SHORTEST_LABELS``) settled labels, ``BUDGET_PER_LABEL`` times
the last for a tree's (past it, a stage's costs fall back to ``d_j``); the programme is
``O(stages * SUM_CAP * TICK_CAP)``. On the 15 560-node mutant the coupling costs about 8 s at
the default limit and its bound meets the counterexample (106); at 20 000 labels, 5 s and 103
(docs/verification.md §3, "Coupled stages").
"""

from __future__ import annotations

import heapq
import itertools
from dataclasses import dataclass

from fsmbt import limits
from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.bt_interpreter import BTLivelock, CompiledTree, Snapshot
from fsmbt.verify.approach import StageBounds, Standalone, coupled, pass_statuses, stages

#: Most calls a stage's profile tells apart (past it: ``d_j``, with ``TICK_CAP`` calls counted).
TICK_CAP = 24
#: Most labels one profile search settles (past it: its frontier's least cost).
PROFILE_LIMIT = 5_000
#: Call weights of the profile's second bound: ``D(t) >= L(w) - w * t`` with ``L(w)`` the least
#: leaves plus ``w`` per call before the first pass (weak duality; cheap where the first search
#: is cut, since a heavy weight keeps the search on runs with few calls).
WEIGHTS = (2, 6, 16, 32)
#: Most labels one weighted search settles (past it: its frontier's least cost).
WEIGHT_LIMIT = 10_000
#: Passes after the first that ``pass_counts`` searches for (later ones: ``r_i`` each).
EXTRA_PASSES = 8
#: Labels all of one tree's coupling searches settle, per label one pass-count search may
#: settle (``fsmbt.limits``' ``shortest_max_labels``); past it a stage's costs are ``d_j`` alone.
BUDGET_PER_LABEL = 50
#: Largest running sum of non-pass calls the programme tells apart.
SUM_CAP = 64
_NEVER = 10**9


@dataclass(frozen=True)
class StageCosts:
    """One stage's rule-4 costs: ``profile[t - 1] = D(t)`` for ``t`` in ``1..TICK_CAP - 1``
    and ``d_j`` last, ``passes[m] = H(m)`` for ``m`` in ``0..EXTRA_PASSES``, ``refail = r``,
    and whether its parent is reactive (rule 3)."""

    profile: tuple[int, ...]
    passes: tuple[int, ...]
    refail: int
    coupled: bool

    def leaves(self, calls: int, extra: int) -> int:
        """``G(t, M)`` of rule 4; ``calls`` = ``TICK_CAP`` stands for any count from it on
        (its profile entry is ``d_j``, below ``D(t)`` for every ``t``)."""
        extra = extra if self.coupled else 0
        first = self.profile[min(calls, TICK_CAP) - 1]
        # each pass after the m-th costs at least ``refail``
        counted = max(
            self.passes[m] + (extra - m) * self.refail
            for m in range(min(extra, len(self.passes) - 1) + 1)
        )
        return max(first + extra * self.refail, counted)


def tick_profile(alone: Standalone, passing: frozenset[int], limit: int) -> tuple[list[int], int]:
    """``D(t)`` for ``t = 1..TICK_CAP`` from the stage's rest, halts allowed: a Dijkstra over
    (state, calls so far), a label dropped when its state was settled with no more calls (so
    at most ``TICK_CAP`` labels per state). A pass met with ``c`` calls settles ``D(t)`` for
    every ``t >= c`` not yet settled (passes pop in cost order). Returns (the profile, labels
    settled); a ``t`` no pass reaches is ``_NEVER``; past ``limit`` the unsettled ones are the
    frontier's least cost."""
    counter = itertools.count()
    heap: list[tuple[int, int, Snapshot | None, int]] = [
        (0, next(counter), alone.start(canonical=True), 0)
    ]
    fewest: dict[Snapshot, int] = {}
    profile = [_NEVER] * (TICK_CAP + 1)  # index t; 0 unused
    best = TICK_CAP + 1  # fewest calls of a pass popped so far
    settled = cost = 0
    try:
        while heap and best > 1:
            cost, _n, snap, calls = heapq.heappop(heap)
            if snap is None:
                for t in range(calls, best):
                    profile[t] = cost
                best = min(best, calls)
                continue
            if fewest.get(snap, TICK_CAP + 1) <= calls:
                continue
            if settled >= limit:
                break
            fewest[snap] = calls
            settled += 1
            for kind, _outcome, after, status in alone.moves(snap, True, canonical=True):
                more = calls + (kind == "tick")
                if more > TICK_CAP:
                    continue
                spent = cost + (kind == "leaf")
                if status in passing:
                    heapq.heappush(heap, (spent, next(counter), None, more))
                elif fewest.get(after, TICK_CAP + 1) > more:
                    heapq.heappush(heap, (spent, next(counter), after, more))
        else:
            return profile[1:], settled
    except (FsmbtError, ValueError, BTLivelock):
        pass  # a construct the standalone run refuses: what was settled
    for t in range(1, best):
        profile[t] = min(profile[t], cost)
    return profile[1:], settled


def pass_counts(alone: Standalone, passing: frozenset[int], limit: int) -> tuple[list[int], int]:
    """``H(m)`` for ``m = 0..EXTRA_PASSES``: least leaves from the stage's rest to its
    ``(1 + m)``-th pass, halts allowed: a Dijkstra over (state, passes so far). Returns (the
    counts, labels settled); past ``limit`` the unsettled ones are the frontier's least
    cost, a count no run reaches ``_NEVER``."""
    counter = itertools.count()
    heap: list[tuple[int, int, Snapshot | None, int]] = [
        (0, next(counter), alone.start(canonical=True), 0)
    ]
    done: set[tuple[Snapshot, int]] = set()
    counts = [_NEVER] * (EXTRA_PASSES + 1)
    cost = 0
    try:
        while heap and counts[-1] == _NEVER:
            cost, _n, snap, passed = heapq.heappop(heap)
            if snap is None:  # a pass, settled in cost order
                counts[passed] = min(counts[passed], cost)
                continue
            if (snap, passed) in done:
                continue
            if len(done) >= limit:
                break
            done.add((snap, passed))
            for kind, _outcome, after, status in alone.moves(snap, True, canonical=True):
                spent = cost + (kind == "leaf")
                now = passed
                if status in passing:
                    heapq.heappush(heap, (spent, next(counter), None, passed))
                    if passed == EXTRA_PASSES:
                        continue
                    now = passed + 1
                if (after, now) not in done:
                    heapq.heappush(heap, (spent, next(counter), after, now))
        else:
            return counts, len(done)
    except (FsmbtError, ValueError, BTLivelock):
        pass  # a construct the standalone run refuses: what was settled
    return [min(c, cost) for c in counts], len(done)


class CoupledBound:
    """Rules 1-4 for the nodes of one tree, each stage's costs memoized by node."""

    def __init__(self, tree: CompiledTree, bounds: StageBounds) -> None:
        self.tree = tree
        self.bounds = bounds
        self._costs: dict[int, StageCosts] = {}
        self.settled = 0  # labels the searches settled (``BUDGET_PER_LABEL``)
        self.cut = False  # a pass-count search stopped at its limit, or the budget was spent

    def stage_costs(self, nid: int, passing: frozenset[int], refail: int) -> StageCosts:
        """A stage's rule-4 costs (``d_j`` everywhere when it does not compile alone or the
        budget is spent)."""
        if nid not in self._costs:
            parent = self.tree.nodes[nid].parent
            assert parent is not None
            is_coupled = coupled(self.tree.nodes[parent])
            alone = self.bounds.standalone(nid)
            floor = self.bounds.distance(nid, passing)
            labels = limits.current().shortest_max_labels
            if alone is None or self.settled >= BUDGET_PER_LABEL * labels:
                self.cut = self.cut or alone is not None
                costs = StageCosts((floor,) * TICK_CAP, (floor,), 0, is_coupled)
            else:
                profile, used = tick_profile(alone, passing, PROFILE_LIMIT)
                start = alone.start(canonical=True)
                for weight in WEIGHTS:
                    least = alone.search(
                        start, passing, True, weight, WEIGHT_LIMIT, canonical=True
                    )[0]
                    used += alone.last_settled
                    profile = [max(p, least - weight * t) for t, p in enumerate(profile, 1)]
                counts, more = pass_counts(alone, passing, labels)
                self.cut = self.cut or more >= labels
                self.settled += used + more
                # the last entry stands for every count of calls from ``TICK_CAP`` on: ``d_j``
                profile[-1] = floor
                costs = StageCosts(
                    tuple(max(p, floor) for p in profile),
                    tuple(max(c, floor) for c in counts),
                    refail,
                    is_coupled,
                )
            self._costs[nid] = costs
        return self._costs[nid]

    def before(self, target: int, refail: dict[int, int]) -> int:
        """Rule 4's bound on the leaves under all of ``target``'s stages before its first
        tick; ``refail[j]`` is ``r_j`` (absent: 0)."""
        nodes = self.tree.nodes
        found = stages(self.tree, target)
        # the segment of each stage (rule 1): a boundary at every ancestor outside the
        # sequence and reactive families
        segment: dict[int, int] = {}
        index = 0
        above = nodes[target].parent
        while above is not None:
            if pass_statuses(nodes[above]) is None:
                index += 1
            segment[above] = index
            above = nodes[above].parent
        best: dict[int, int] = {0: 0}  # running sum S -> least cost of the later stages
        last_segment = None
        for nid, passing in reversed(found):
            parent = nodes[nid].parent
            assert parent is not None
            if last_segment is not None and segment[parent] != last_segment:
                best = {0: min(best.values())}  # rule 1: nothing couples across
            last_segment = segment[parent]
            costs = self.stage_costs(nid, passing, refail.get(nid, 0))
            following: dict[int, int] = {}
            for total, spent in best.items():
                for calls in range(1, TICK_CAP + 1):
                    value = spent + costs.leaves(calls, total)
                    key = min(total + calls - 1, SUM_CAP)
                    if value < following.get(key, _NEVER):
                        following[key] = value
            best = following
        return min(best.values())
