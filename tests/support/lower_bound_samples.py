"""Samples for the lower bound's tests and benchmark (``verify/lower_bound.py``): the
interpreter's own fewest leaves before each node's first tick, and the seeded per-node mutants
the bound applies to. Shared by ``tests/verify/test_ver_lower_bound.py`` and
``benchmarks/bench_lower_bound.py``."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from fsmbt import limits
from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledTree, LeafRequest
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify.compositional import NotDecomposable, decompose, per_node_lower_bound
from fsmbt.verify.lower_bound import LowerBound
from support.pernode_mutants import BOUND, seeded_mutants

#: Leaves the interpreter's breadth-first search answers, and the states it may hold.
DEPTH, STATES = 9, 30_000


def first_ticks(
    doc: BTDocument, depth: int = DEPTH, states: int = STATES
) -> tuple[CompiledTree, dict[int, int], dict[int, int]]:
    """Breadth-first over the interpreter's leaf outcomes (``depth`` leaves at most): the fewest
    leaves answered before each node is seen ticking (on the path to a requested leaf), and
    before the root's first tick returns each status (``exactly_once``: a RUNNING with a
    wake-up ends the tick, as a parent sees its child's tick)."""
    interp = BTInterpreter(doc, exactly_once=True)
    seen: dict[int, int] = {}
    root_first: dict[int, int] = {}
    start, event = interp.advance(interp.begin_tick(interp.initial()), None)
    level: list[tuple[Any, Any, bool]] = [(start, event, True)]
    visited = {start}
    for level_depth in range(depth + 1):
        following: list[tuple[Any, Any, bool]] = []
        for snap, event, first in level:
            while not isinstance(event, LeafRequest):
                if first:
                    root_first.setdefault(event.status, level_depth)
                if event.status != RUNNING:
                    break
                first = False
                snap = (snap[0], snap[1], snap[2], False)
                snap, event = interp.advance(interp.begin_tick(snap), None)
            if not isinstance(event, LeafRequest):
                continue
            for frame in snap[2]:
                seen.setdefault(frame[0], level_depth)
            node = event.node
            outcomes = (
                (SUCCESS, FAILURE)
                if node.kind is NodeKind.CONDITION
                else (SUCCESS, FAILURE, RUNNING)
            )
            for status in outcomes:
                nxt, ev = interp.advance(snap, status)
                if nxt not in visited and len(visited) < states:
                    visited.add(nxt)
                    following.append((nxt, ev, first))
        level = following
    return interp.tree, seen, root_first


def bounded_pairs(
    trees: int, seed: int, rng_seed: int, per_tree: int
) -> Iterator[tuple[BTDocument, FSM, LowerBound]]:
    """The seeded mutants whose per-node check fails and the bound's conditions hold."""
    for doc, _model, mutants in seeded_mutants(
        trees, seed=seed, rng_seed=rng_seed, per_tree=per_tree
    ):
        for mutant in mutants:
            try:
                with limits.changed(conversion_max_states=BOUND):
                    found = decompose(doc, mutant, max_states=BOUND)
            except (NotDecomposable, FsmbtError):
                continue
            if found.per_node_failure is None:
                continue
            bound = per_node_lower_bound(doc, mutant, *found.per_node_failure)
            if bound is not None:
                yield doc, mutant, bound
