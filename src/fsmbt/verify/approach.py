"""The approach to a node's first tick: the earlier siblings that must pass first, a sound
lower bound on the leaves they take, and a short way there (issue 27 item 1, seventh round;
docs/verification.md §3, "Stages: a sharper bound and a shorter approach"; the argument:
docs/semantics.md §4d, "Stages").

Why: a lifted counterexample is *shortest* when a lower bound on every counterexample meets its
length (``verify/lower_bound.py``). On a 15 000-node mutant the per-node bound charged an
earlier sibling of the failing node's ancestors what *some* state of it needs to pass (often
one leaf), while the sibling, a subtree of thousands of nodes with memory, needs tens of leaves
over several ticks from rest; and the lift drove each sibling to pass in one tick from rest,
which costs hundreds. Both ends move here, one sibling at a time.

Rules (node behaviour is fsmbt's interpreter's, ``BTInterpreter``, never the converter's):

1. *stages*: for an ancestor ``A`` of ``U`` of the ``sequence`` or ``reactive`` family
   (Sequence, Fallback, their Reactive, WithMemory and Async kinds) whose child ``i`` leads to
   ``U``, each earlier child ``j < i`` is a *stage* with its *pass statuses*: SUCCESS or
   SKIPPED under a sequence, FAILURE or SKIPPED under a fallback. ``A`` calls child ``i`` only
   when its index reaches ``i``; from rest the index is 0 and grows only when the child at it
   returns a pass status (it is set back to 0, never forward), so before ``U``'s first tick each
   stage has returned a pass status at least once (docs/semantics.md §4d, "Stages");
2. *standalone*: a stage's subtree behaves alone as in the tree (the interpreter keeps no state
   outside a node's subtree but the wake-up flag, which only re-ticks): its states are its own
   statuses, memories and frames, its inputs the ticks and halts its parent sends. Run alone
   with *any* interleaving of ticks and halts (a superset of what its parent sends), the least
   leaves before its first pass, ``d_j``, bounds the leaves under it before ``U``'s first tick;
   stages are disjoint subtrees, so the bounds add: ``P(U) >= sum of d_j`` (a 0-1 breadth-first
   search per stage; past ``STAGE_LIMIT`` states, the depth it exhausted, still a bound);
3. *coupled*: under a parent of the ``reactive`` family, every call that reaches a later stage
   makes the earlier ones pass again; ``verify/coupling.py`` bounds what the stages cost
   together (docs/semantics.md §4d, "Coupled stages");
4. *approach*: the whole tree is run by the interpreter; a leaf inside stage ``j`` answers the
   next outcome of ``j``'s current plan, a shortest way (no halts: the parent decides those)
   from ``j``'s state at that moment to its next pass, each tick it begins weighed by what the
   earlier coupled stages need to pass once more from where they are (their *refail* cost,
   measured on the run), searched again when the plan is spent or the run left it. The result
   is a real run to ``U``'s first tick, not a shortest one: it is shortest when its length
   meets the bound.

Cost: one standalone search per stage (at most ``STAGE_LIMIT`` states; ``BOUND_BUDGET`` for
all of one tree's), memoized by node; the approach replans once per stage per tick it passes
in, each search at most ``PLAN_LIMIT`` states and ``APPROACH_BUDGET`` for all of them, refail
costs memoized by the stage's state.
"""

from __future__ import annotations

import dataclasses
import heapq
import itertools
from collections import deque
from collections.abc import Iterable
from typing import Any

from fsmbt.model.bt import BehaviorTree
from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.bt_interpreter import (
    SKIPPED,
    BTInterpreter,
    BTLivelock,
    CompiledNode,
    CompiledTree,
    LeafRequest,
    Snapshot,
)
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.semantics.leaf_canonical import Canonicalizer, is_canonical_class
from fsmbt.semantics.nodes import runtime_tables

#: Most states one stage's standalone search settles (past it: the least cost not settled).
STAGE_LIMIT = 50_000
#: Most states all the standalone distances of one tree settle together (past it, a stage not
#: yet searched counts 0: no claim), so a bound over many failing nodes stays bounded.
BOUND_BUDGET = 500_000
#: Most states one plan's search settles (past it the approach gives up: ``drive`` then costs
#: each off-path child from rest, as before).
PLAN_LIMIT = 20_000
#: Most states all the plans of one approach settle together (past it the approach gives up).
APPROACH_BUDGET = 200_000
#: Most leaves the approach answers before it gives up (a run that never reaches ``U``).
APPROACH_LIMIT = 20_000
#: The weight of a tick in a refail search: far above any plan's leaves, so the search finds
#: the fewest ticks first (one, when the stage can pass again in one tick), then the fewest
#: leaves.
_ONE_TICK = 1_000_000
_STANDALONE_ID = "__fsmbt_stage__"


def pass_statuses(parent: CompiledNode) -> frozenset[int] | None:
    """What a child of ``parent`` returns for ``parent`` to move on to the next child (rule 1);
    ``None`` when ``parent`` is not of the ``sequence`` or ``reactive`` family."""
    tables = runtime_tables()
    handler = tables.handlers.get(parent.type)
    if handler == "sequence":
        fallback = tables.sequence_flags[parent.type][0]
    elif handler == "reactive":
        fallback = parent.type in tables.reactive_fallbacks
    else:
        return None
    return frozenset((FAILURE if fallback else SUCCESS, SKIPPED))


def coupled(parent: CompiledNode) -> bool:
    """Whether ``parent`` calls its children again from child 0 on every call (the
    ``reactive`` family, rule 3): its earlier children then pass again in every call that
    reaches a later one."""
    return runtime_tables().handlers.get(parent.type) == "reactive"


def stages(tree: CompiledTree, target: int) -> list[tuple[int, frozenset[int]]]:
    """Rule 1: ``(stage node id, pass statuses)`` for every earlier sibling of ``target``'s
    ancestors' path children, root first, in the order a tick meets them."""
    nodes = tree.nodes
    found: list[tuple[int, frozenset[int]]] = []
    child = nodes[target]
    while child.parent is not None:
        parent = nodes[child.parent]
        passing = pass_statuses(parent)
        if passing is not None:
            found[:0] = [(j, passing) for j in parent.children[: child.index]]
        child = parent
    return found


def last_descendant(tree: CompiledTree, nid: int) -> int:
    """The id of the last node of ``nid``'s subtree in pre-order (ids are pre-order, so the
    subtree is ``nid ..`` that id): down the last children."""
    nodes = tree.nodes
    while nodes[nid].children:
        nid = nodes[nid].children[-1]
    return nid


class Standalone:
    """A stage's subtree compiled alone (rule 2): its ids are the tree's shifted by
    ``offset``, so a slice of a whole-tree snapshot is a snapshot of it."""

    def __init__(self, tree: CompiledTree, nid: int) -> None:
        node = tree.nodes[nid]
        doc = tree.doc
        alone = dataclasses.replace(
            doc,
            trees={**doc.trees, _STANDALONE_ID: BehaviorTree(_STANDALONE_ID, node.source)},
            main_tree=_STANDALONE_ID,
        )
        self.interp = BTInterpreter(CompiledTree(alone), exactly_once=True)
        self.offset = nid
        self.last = nid + len(self.interp.nodes) - 1
        self.last_settled = 0  # states the last search settled
        #: whether the last search that found no pass settled every reachable state (a proof
        #: that none is reachable: neither a limit nor a refused construct stopped it)
        self.last_exhausted = False
        self._canonical: tuple[Canonicalizer, ...] | None = None
        if last_descendant(tree, nid) != self.last or any(
            a.type != b.type or len(a.children) != len(b.children)
            for a, b in zip(self.interp.nodes, tree.nodes[nid : self.last + 1], strict=True)
        ):
            raise FsmbtError(f"the subtree at {node.path or 'the root'} does not compile alone")

    def slice(self, snap: Snapshot) -> Snapshot:
        """The stage's part of a whole-tree snapshot (its statuses, memories and frames)."""
        lo, hi = self.offset, self.last
        return (
            tuple((i - lo, v) for i, v in snap[0] if lo <= i <= hi),
            tuple((i - lo, v) for i, v in snap[1] if lo <= i <= hi),
            tuple((f[0] - lo, *f[1:]) for f in snap[2] if lo <= f[0] <= hi),
            False,
        )

    def canonical(self) -> Canonicalizer | None:
        """The stage's ``leaf_canonical.Canonicalizer`` when its subtree is of the canonical
        class (docs/semantics.md §4a: statuses and frame locals reset before they are read are
        erased, so snapshots with the same future - under leaf outcomes, ticks and halts of the
        root alike - are one), else ``None``; built once."""
        if self._canonical is None:
            tree = self.interp.tree
            self._canonical = (Canonicalizer(tree),) if is_canonical_class(tree) else ()
        return self._canonical[0] if self._canonical else None

    def start(self, canonical: bool = False) -> Snapshot:
        """The stage at rest (canonical when asked and the class allows)."""
        snap = self.interp.initial()
        return self.erase(snap) if canonical else snap

    def erase(self, snap: Snapshot) -> Snapshot:
        """``snap`` canonical when the class allows (``canonical``), else itself."""
        canonical = self.canonical()
        return canonical.canonical(snap) if canonical is not None else snap

    def moves(
        self, snap: Snapshot, halts: bool, canonical: bool = False
    ) -> Iterable[tuple[str, Any, Snapshot, Any]]:
        """(``halt``, ``tick`` or ``leaf``; the outcome given or None; the next snapshot; the
        status the stage returned or None); with ``canonical``, each next snapshot canonical
        (``Standalone.canonical``): the same costs over fewer states, for the searches that
        need no faithful snapshot (``verify/coupling.py``; the approach, whose plan steps are
        matched against the run's snapshots made canonical the same way, ``erase``)."""
        erase = self.canonical() if canonical else None
        if erase is None:
            yield from self._moves(snap, halts)
            return
        for kind, outcome, after, status in self._moves(snap, halts):
            yield kind, outcome, erase.canonical(after), status

    def _moves(self, snap: Snapshot, halts: bool) -> Iterable[tuple[str, Any, Snapshot, Any]]:
        it = self.interp
        if not snap[2]:  # between ticks: tick it (and, for the bound, halt it)
            if halts:
                yield "halt", None, it.halt_tree(snap), None
            after, event = it.advance(it.begin_tick(snap), None)
            yield "tick", None, after, None if isinstance(event, LeafRequest) else event.status
            return
        request = it.leaf_request(snap)
        assert request is not None
        outcomes = (SUCCESS, FAILURE) if request.node.is_condition else (SUCCESS, FAILURE, RUNNING)
        for outcome in outcomes:
            after, event = it.advance(snap, outcome)
            yield "leaf", outcome, after, None if isinstance(event, LeafRequest) else event.status

    def search(
        self,
        start: Snapshot,
        passing: frozenset[int],
        halts: bool,
        tick_cost: int = 0,
        limit: int = STAGE_LIMIT,
        canonical: bool = False,
    ) -> tuple[int, list[tuple[Any, int]] | None]:
        """Dijkstra from ``start`` to the first tick returning a pass status, a leaf costing 1
        and each tick begun ``tick_cost``: (least cost, the outcomes - each with the stage's
        statuses, memories and frames before it - or ``None``). Past ``limit`` states, or
        when no pass is reachable: (the least cost not yet settled, ``None``) - with
        ``tick_cost`` 0, a lower bound on the leaves either way. ``canonical``: see
        ``moves`` (the plan's snapshots are then canonical too)."""
        counter = itertools.count()
        self.last_settled = 0
        self.last_exhausted = False
        heap: list[tuple[int, int, Any, Any]] = [(0, next(counter), start, None)]
        settled: set[Snapshot] = set()
        cost = 0
        try:
            while heap:
                cost, _n, snap, link = heapq.heappop(heap)
                if snap is None:
                    return cost, _unlink(link)  # a pass, settled in cost order
                if snap in settled:
                    continue
                if len(settled) >= limit:
                    return cost, None
                settled.add(snap)
                self.last_settled = len(settled)
                for kind, outcome, after, status in self.moves(snap, halts, canonical):
                    step = link if outcome is None else ((snap[:3], outcome), link)
                    extra = 1 if kind == "leaf" else tick_cost if kind == "tick" else 0
                    if status in passing:
                        heapq.heappush(heap, (cost + extra, next(counter), None, step))
                    elif after not in settled:
                        heapq.heappush(heap, (cost + extra, next(counter), after, step))
        except (FsmbtError, ValueError, BTLivelock):
            return cost, None  # a construct the standalone run refuses: what was settled
        self.last_exhausted = True
        return cost, None


def _unlink(link: Any) -> list[tuple[Any, int]]:
    out: list[tuple[Any, int]] = []
    while link is not None:
        out.append(link[0])
        link = link[1]
    out.reverse()
    return out


class StageBounds:
    """Rule 2 for every stage of a tree, memoized by node: ``d_j`` and the bound ``P(U)``."""

    def __init__(self, tree: CompiledTree) -> None:
        self.tree = tree
        self._distance: dict[int, int] = {}
        self._alone: dict[int, Standalone | None] = {}
        self.settled = 0  # states settled by the distances so far (``BOUND_BUDGET``)

    def standalone(self, nid: int) -> Standalone | None:
        if nid not in self._alone:
            try:
                self._alone[nid] = Standalone(self.tree, nid)
            except FsmbtError:
                self._alone[nid] = None
        return self._alone[nid]

    def distance(self, nid: int, passing: frozenset[int]) -> int:
        """``d_j``: least leaves under stage ``nid`` before it first passes (0 when it does not
        compile alone: no claim)."""
        if nid not in self._distance:
            alone = self.standalone(nid) if self.settled < BOUND_BUDGET else None
            if alone is None:
                self._distance[nid] = 0
            else:
                # over canonical snapshots (docs/semantics.md §4a: the same costs, fewer
                # states, so the same limit reaches deeper)
                found = alone.search(alone.start(canonical=True), passing, True, canonical=True)
                self._distance[nid] = found[0]
                self.settled += alone.last_settled
        return self._distance[nid]

    def per_ancestor(self, target: int) -> dict[int, int]:
        """ancestor id -> the sum of ``d_j`` over its stages towards ``target`` (ancestors
        without stages absent)."""
        out: dict[int, int] = {}
        for nid, passing in stages(self.tree, target):
            parent = self.tree.nodes[nid].parent
            assert parent is not None
            out[parent] = out.get(parent, 0) + self.distance(nid, passing)
        return out


def approach(
    tree: CompiledTree, target: int, bounds: StageBounds | None = None
) -> list[int] | None:
    """Rule 3: leaf outcomes from the root up to ``target``'s first tick (the last outcome given
    is the one after which ``target`` is ticked), or ``None`` when the run does not get there
    (a leaf outside every stage, a stage without a plan, the root returning SUCCESS or FAILURE
    - the leaf machine stops there, docs/semantics.md §4 -, ``APPROACH_LIMIT`` leaves or
    ``APPROACH_BUDGET`` states settled by its plans)."""
    bounds = bounds or StageBounds(tree)
    owner: list[tuple[Standalone, frozenset[int]]] = []
    # the coupled stages (rule 3): each tick a later stage begins makes them pass again
    again: list[int] = []
    for k, (nid, passing) in enumerate(stages(tree, target)):
        alone = bounds.standalone(nid)
        if alone is None:
            return None
        owner.append((alone, passing))
        parent = tree.nodes[nid].parent
        if parent is not None and coupled(tree.nodes[parent]):
            again.append(k)
    last = last_descendant(tree, target)
    interp = BTInterpreter(tree)
    plans: dict[int, deque[tuple[Any, int]]] = {}
    refails: dict[tuple[int, Snapshot], int] = {}
    settled = 0  # states the plans settled (``APPROACH_BUDGET``)

    def refail(k: int, snap: Snapshot) -> int:
        """The leaves stage ``k`` needs to pass once more, in one tick when it can, from its
        state in ``snap`` with its parent's reset of its status at the tick's end."""
        nonlocal settled
        alone, passing = owner[k]
        piece = alone.slice(snap)
        piece = alone.erase((tuple(e for e in piece[0] if e[0] != 0), piece[1], (), False))
        if (k, piece) not in refails:
            _cost, steps = alone.search(
                piece, passing, False, _ONE_TICK, PLAN_LIMIT, canonical=True
            )
            settled += alone.last_settled
            refails[k, piece] = len(steps) if steps is not None else 0
        return refails[k, piece]

    outcomes: list[int] = []
    try:
        snap, event = interp.advance(interp.begin_tick(interp.initial()), None)
        while len(outcomes) < APPROACH_LIMIT:
            if not isinstance(event, LeafRequest):
                if event.status != RUNNING:
                    return None  # the root returned: the leaf machine stops there
                snap, event = interp.advance(interp.begin_tick(snap), None)
                continue
            if target <= event.node.id <= last:
                return outcomes
            stage = next(
                (
                    k
                    for k, (alone, _p) in enumerate(owner)
                    if alone.offset <= event.node.id <= alone.last
                ),
                None,
            )
            if stage is None:
                return None
            alone, passing = owner[stage]
            # plans run over canonical snapshots (fewer states, the same costs; a plan step
            # is matched against the run's snapshot made canonical the same way)
            here = alone.erase(alone.slice(snap))
            plan = plans.get(stage)
            if not plan or plan[0][0] != here[:3]:  # spent, or the run left it (a halt)
                weight = sum(refail(k, snap) for k in again if k < stage)
                _cost, steps = alone.search(
                    here, passing, False, weight, PLAN_LIMIT, canonical=True
                )
                settled += alone.last_settled
                if not steps or settled > APPROACH_BUDGET:
                    return None
                plan = plans[stage] = deque(steps)
            outcome = plan.popleft()[1]
            if event.node.is_condition and outcome == RUNNING:
                return None
            outcomes.append(outcome)
            snap, event = interp.advance(snap, outcome)
    except (FsmbtError, ValueError, BTLivelock):
        return None
    return None
