"""Which nodes of a tree can ever be ticked, and which statuses a subtree can never return,
from the tree alone (docs/semantics.md §4d, "Dead nodes"; §4c, "Regions never ticked").

Why: the per-node check (``verify/pernode.py``) skips a node its machine never enters, but a
node can also be dead in the *tree*: a later child of a sequence whose earlier sibling can
never succeed (under ``ForceFailure``, a ``Parallel`` that fails first...), a later child of a
fallback whose earlier sibling can never fail. Its fragment in the machine is then unreachable
too, once its parent's local check held (the parent's fragment enters a child exactly when the
tree ticks it), so its local check proves nothing and a difference there is not a difference
of the two machines. Without this, a one-transition mutant inside such a fragment fails its
local check, the checks of its ancestors that halt it, and the lift finds no run to any of
them: the pair was left undecided (docs/verification.md §7, the `decorated` mutants).

The analysis, bottom-up then top-down, each node over abstract children (``AbstractRun``:
fsmbt's interpreter on the node, ``tick`` and ``halt`` offered between ticks, each child
returning any status it may return, independently at every call):

- ``returns(x)``: the statuses ``x`` may return. An environment leaf: SUCCESS and FAILURE,
  RUNNING too for an action; any other node: the results its abstract run returns with child
  ``i`` returning ``returns(c_i)``;
- ``ticked(x)``: the children its abstract run ever ticks; a node is *tickable* when it is the
  root or a child its tickable parent ever ticks.

Sound: the abstract run over-approximates every concrete context (any tick/halt order from the
parent, any sequence of the children's possible statuses), and each concrete child returns only
statuses in ``returns`` (induction from the leaves), so a node that is not tickable is never
ticked in any run of the tree. Cost: one abstract run per distinct (node shape, children's
status sets), each of at most ``RUN_LIMIT`` states; past it the node's children all count as
ticked and its statuses as all three (the safe side).

``never_returns`` answers the finer question the set abstraction cannot: the abstract run
treats each child's calls as independent, so a `ReactiveFallback(Parallel, ReactiveFallback)`
whose two children can each fail, but never in the same tick, "may fail" there. It runs the
subtree itself, alone, with any interleaving of ticks and halts (``approach.Standalone``: a
superset of every context its parent gives it) and looks for a tick returning one of the
statuses; a search that settles every reachable state without one is a proof. Past its limit,
a node of the sequence or reactive family whose go-on statuses contain the ones asked for
returns them only after each child in turn returned a go-on status (its index moves only on
those), so one child that never does is a proof too (searched the same way, recursively).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.bt_interpreter import BTLivelock, CompiledNode, CompiledTree
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify.abstract_node import AbstractRun, State
from fsmbt.verify.approach import Standalone, pass_statuses, stages

#: Most states one node's abstract run may hold before its answer is "everything".
RUN_LIMIT = 20_000
#: Most states one ``never_returns`` search settles, and all of one call's searches together.
SEARCH_LIMIT = 20_000
SEARCH_BUDGET = 400_000
ALL = frozenset({SUCCESS, FAILURE, RUNNING})


def _leaf_returns(node: CompiledNode) -> frozenset[int]:
    return frozenset({SUCCESS, FAILURE} | ({RUNNING} if node.kind is NodeKind.ACTION else set()))


def _run(node: CompiledNode, kids: list[frozenset[int]]) -> tuple[frozenset[int], frozenset[int]]:
    """(statuses returned, children ticked) of ``node``'s abstract run, or the safe answer
    (all three statuses, every child) past ``RUN_LIMIT`` or on a construct it refuses."""
    everything = (ALL, frozenset(range(len(kids))))
    try:
        machine = AbstractRun(node, [dict.fromkeys(k, 0) for k in kids])
        start = machine.start()
        seen: set[State] = {start}
        todo = [start]
        returned: set[int] = set()
        ticked: set[int] = set()
        while todo:
            for _input, _cost, nxt, (kind, what) in machine.edges(todo.pop()):
                if kind == "tick":
                    ticked.add(what)
                elif kind == "exit":
                    returned.add(what)
                if nxt not in seen:
                    if len(seen) >= RUN_LIMIT:
                        return everything
                    seen.add(nxt)
                    todo.append(nxt)
    except (FsmbtError, ValueError, BTLivelock):
        return everything
    return frozenset(returned), frozenset(ticked)


def _shape(node: CompiledNode, kids: list[frozenset[int]]) -> tuple[Any, ...]:
    source = node.source
    return (
        source.type,
        source.kind,
        tuple(sorted(source.attrs.items())),
        source.semantics,
        tuple(tuple(sorted(k)) for k in kids),
    )


def never_ticked(
    tree: CompiledTree, never: Mapping[int, frozenset[int]] | None = None
) -> frozenset[int]:
    """The ids of ``tree``'s nodes no run of the tree ever ticks (the module docstring).
    ``never``: statuses some nodes are proven never to return (``NeverReturns``, by their
    standalone search), taken out of what the set abstraction says they may return, so their
    parents' abstract runs see only what they can return. Iterative: children before parents
    (reverse pre-order), then parents before children."""
    never = never or {}
    returns: dict[int, frozenset[int]] = {}
    ticks: dict[int, frozenset[int]] = {}
    memo: dict[tuple[Any, ...], tuple[frozenset[int], frozenset[int]]] = {}
    for node in reversed(tree.nodes):
        if node.is_env_leaf and not node.children:
            returns[node.id] = _leaf_returns(node) - never.get(node.id, frozenset())
            continue
        kids = [returns[c] for c in node.children]
        key = _shape(node, kids)
        found = memo.get(key)
        if found is None:
            found = memo[key] = _run(node, kids)
        returns[node.id] = found[0] - never.get(node.id, frozenset())
        ticks[node.id] = frozenset(node.children[i] for i in found[1])
    dead: set[int] = set()
    for node in tree.nodes:  # pre-order: a parent before its children
        if node.parent is not None and (node.parent in dead or node.id not in ticks[node.parent]):
            dead.add(node.id)
    return frozenset(dead)


class NeverReturns:
    """``never_returns`` over one tree, its answers memoized by (node, statuses) and its
    searches sharing one budget of ``SEARCH_BUDGET`` settled states (past it: "not known")."""

    def __init__(self, tree: CompiledTree, budget: int = SEARCH_BUDGET) -> None:
        self.tree = tree
        self.budget = budget
        self.memo: dict[tuple[int, frozenset[int]], bool] = {}

    def __call__(self, nid: int, statuses: frozenset[int]) -> bool:
        """Whether the subtree at ``nid`` never returns any of ``statuses`` in any run (the
        module docstring); ``False`` when not proven. Iterative over the children asked."""
        key = (nid, statuses)
        if key in self.memo:
            return self.memo[key]
        # (node, statuses, child index next to try or -1 before the node's own search)
        stack: list[tuple[int, frozenset[int], int]] = [(nid, statuses, -1)]
        while stack:
            x, wanted, at = stack.pop()
            if (x, wanted) in self.memo:
                continue
            node = self.tree.nodes[x]
            if at < 0:
                found = self._search(x, wanted)
                if found is not None:
                    self.memo[x, wanted] = found
                    continue
                go_on = pass_statuses(node)
                if not node.children or go_on is None or not wanted <= go_on:
                    self.memo[x, wanted] = False
                    continue
                at = 0
            if at > 0 and self.memo.get(
                (node.children[at - 1], go_on := pass_statuses(node) or frozenset())
            ):
                self.memo[x, wanted] = True  # a child never goes on: neither does the node
                continue
            go_on = pass_statuses(node) or frozenset()
            if at >= len(node.children):
                self.memo[x, wanted] = False
                continue
            stack.append((x, wanted, at + 1))
            stack.append((node.children[at], go_on, -1))
        return self.memo[key]

    def _search(self, nid: int, wanted: frozenset[int]) -> bool | None:
        """The subtree alone: ``False`` when a tick returns one of ``wanted``, ``True`` when
        no reachable state does, ``None`` past the limit or the budget."""
        if self.budget <= 0:
            return None
        try:
            alone = Standalone(self.tree, nid)
        except FsmbtError:
            return None
        _cost, steps = alone.search(
            alone.start(canonical=True),
            wanted,
            True,
            0,
            min(SEARCH_LIMIT, self.budget),
            canonical=True,
        )
        self.budget -= alone.last_settled
        if steps is not None:
            return False
        return True if alone.last_exhausted else None


def stage_never_passes(
    tree: CompiledTree, nid: int, searches: NeverReturns
) -> tuple[int, frozenset[int]] | None:
    """A proof that ``nid`` is never ticked in any run of ``tree``: an earlier sibling of one
    of its ancestors' path children, under a sequence- or reactive-family parent (a *stage*,
    ``approach.stages``), that never returns the statuses its parent goes on with
    (``searches``), as (its id, those statuses); ``None`` when none is proven. The parent
    ticks the path child only after every earlier child returned one of them (its index
    moves only on those), so the node is never ticked. Stages nearest the node first (the
    smaller subtrees: the cheaper searches)."""
    for stage, passing in reversed(stages(tree, nid)):
        if searches(stage, passing):
            return stage, passing
    return None
