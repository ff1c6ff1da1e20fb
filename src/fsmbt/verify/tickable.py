"""Which nodes of a tree can ever be ticked, from the tree alone (docs/semantics.md §4d,
"Dead nodes").

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
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.bt_interpreter import BTLivelock, CompiledNode, CompiledTree
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify.abstract_node import AbstractRun, State

#: Most states one node's abstract run may hold before its answer is "everything".
RUN_LIMIT = 20_000
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


def never_ticked(tree: CompiledTree) -> frozenset[int]:
    """The ids of ``tree``'s nodes no run of the tree ever ticks (the module docstring).
    Iterative: children before parents (reverse pre-order), then parents before children."""
    returns: dict[int, frozenset[int]] = {}
    ticks: dict[int, frozenset[int]] = {}
    memo: dict[tuple[Any, ...], tuple[frozenset[int], frozenset[int]]] = {}
    for node in reversed(tree.nodes):
        if node.is_env_leaf and not node.children:
            returns[node.id] = _leaf_returns(node)
            continue
        kids = [returns[c] for c in node.children]
        key = _shape(node, kids)
        found = memo.get(key)
        if found is None:
            found = memo[key] = _run(node, kids)
        returns[node.id] = found[0]
        ticks[node.id] = frozenset(node.children[i] for i in found[1])
    dead: set[int] = set()
    for node in tree.nodes:  # pre-order: a parent before its children
        if node.parent is not None and (node.parent in dead or node.id not in ticks[node.parent]):
            dead.add(node.id)
    return frozenset(dead)
