"""Lift a per-node counterexample to the whole tree and confirm it by replay (issue 27;
docs/verification.md §3 and §7, "Lifted counterexamples"; docs/semantics.md §4d).

Why: the per-node check (``verify/pernode.py``) names a failing node ``N`` in about a second,
with a *local* counterexample - ticks of ``N`` and outcomes of its abstract children - but the
whole product that would give a counterexample in the user's terms does not finish on a large
result. Here the local counterexample is turned into leaf outcomes from the root, then replayed
on the two whole machines; it is reported only if the replay tells them apart.

Rules (every step judged by fsmbt's interpreter, never by the converter's rules):

1. *shortest realizations*: bottom-up, for each node ``x`` and status ``s``, a shortest leaf
   outcome sequence making ``x``, ticked fresh, return ``s`` (``x`` over abstract children run
   by the interpreter, each child outcome costing its own realization's length: a Dijkstra
   search; equal problems are searched once). The same search gives, for each child, a
   shortest way to get it ticked;
2. *drive*: the whole tree (the region after the same-type merge of docs/semantics.md §4d,
   lemma M, which keeps the leaf-execution machine) is run by the interpreter; a leaf outside
   ``N`` answers what its off-path ancestor child must return for the tick to reach ``N``; a
   leaf under ``N``'s child ``i`` answers the realization of the local counterexample's next
   outcome of child ``i``. A halt in the local counterexample is not lifted (the check's
   failing run offers none). The drive first tries the stages' approach to ``N``'s first tick
   (``verify/approach.py``: each earlier sibling on the way follows a shortest plan from its
   current state, far shorter on large trees with memory than each sibling's realization from
   rest), then, when that run's replay does not separate the machines, the drive from rest;
3. *replay*: the leaf outcomes run on both whole machines (``native.replay``); accepted only
   when a step differs that is not the source refusing its input. The sequence is cut at the
   first difference and shortened greedily (a step dropped while the replay still separates).

A lifted counterexample is a real one (the replay shows it) but not always a shortest one.
Cost: one abstract search per distinct node problem (a few hundred states each, capped at
``SEARCH_LIMIT``), one interpreter run of at most ``DRIVE_LIMIT`` leaves, and replays of the
counterexample (at most ``SHORTEN_REPLAYS`` or ``SHORTEN_SECONDS`` while shortening).
"""

from __future__ import annotations

import copy
import heapq
import itertools
import random
import time
from collections import deque
from collections.abc import Sequence
from typing import Any

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import (
    BTInterpreter,
    BTLivelock,
    CompiledNode,
    CompiledTree,
    LeafRequest,
)
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.semantics.execution import leaf_machine
from fsmbt.semantics.machine import Machine
from fsmbt.semantics.status import LeafOutcome
from fsmbt.verify.abstract_node import abstract_tree
from fsmbt.verify.approach import approach
from fsmbt.verify.lazy_fsm import LazyDataMachine, Unsupported
from fsmbt.verify.native import Replay, replay
from fsmbt.verify.pairing import LEAF_EXECUTION
from fsmbt.verify.pernode import PerNodeOutcome
from fsmbt.verify.random_walk import SEED, WALK_LEAVES, budget, walk_inputs
from fsmbt.verify.report import (
    COMPLETENESS,
    COMPOSITIONAL_LIFTED,
    NO_ADDITIONAL_BEHAVIOR,
    PER_NODE_LIFTED,
    TERMINATION_CONSISTENCY,
    PropertyResult,
    Report,
)
from fsmbt.verify.shortest import ShorterSearch, search_shorter

#: The leaf machine's input for each status.
SYMBOL = {
    SUCCESS: LeafOutcome.SUCCESS.value,
    FAILURE: LeafOutcome.FAILURE.value,
    RUNNING: LeafOutcome.RUNNING.value,
}
#: The status of each leaf machine input.
STATUS = {symbol: status for status, symbol in SYMBOL.items()}
#: Most states one abstract search settles.
SEARCH_LIMIT = 3_000
#: Most leaves one drive answers.
DRIVE_LIMIT = 20_000
#: Most replays, and wall seconds, the greedy shortening spends (a replay on a 15 000-node
#: tree costs about half a second: the shortening stops when either is spent).
SHORTEN_REPLAYS = 400
SHORTEN_SECONDS = 5.0
_SOURCE_REFUSES = "the source does not accept"

Costs = dict[int, int]  # status -> leaves of its shortest realization
Path = list[tuple[int, int]]  # (child index, status) in order


def whole_tree(source: BTDocument, region: BTNode, merged: BTNode) -> BTDocument:
    """``source``'s main tree with the node ``region`` replaced by ``merged`` (shared, not
    copied: its nodes keep their identity), every other node a shallow copy (iterative)."""
    root = source.main.root
    assert root is not None
    top = merged if root is region else copy.copy(root)
    stack = [(root, top)]
    while stack:
        old, new = stack.pop()
        if old is region:
            continue
        new.children = []
        for child in old.children:
            made = merged if child is region else copy.copy(child)
            new.children.append(made)
            stack.append((child, made))
    return BTDocument.single(top)


def _search(node: CompiledNode, costs: list[Costs]) -> tuple[dict[int, Path], dict[int, Path]]:
    """Dijkstra over ``node``'s abstract problem from a fresh tick: for each status its
    shortest path to be returned, for each child index its shortest path to be ticked."""
    interp = BTInterpreter(abstract_tree(node, [RUNNING in c for c in costs]), exactly_once=True)
    index = {n.id: int(n.label[1:-1]) for n in interp.tree.nodes if n.is_env_leaf}
    counter = itertools.count()
    heap: list[Any] = []
    exits: dict[int, Path] = {}
    reach: dict[int, Path] = {}

    def settle(snap: Any, event: Any, cost: int, link: Any) -> None:
        """Push the leaf request ``event`` leads to, or the node's exit (RUNNING: tick again)."""
        ticks = set()
        while not isinstance(event, LeafRequest):
            heapq.heappush(heap, (cost, next(counter), "exit", event.status, link))
            if event.status != RUNNING or snap in ticks:
                return
            ticks.add(snap)
            snap = (snap[0], snap[1], snap[2], False)
            snap, event = interp.advance(interp.begin_tick(snap), None)
        heapq.heappush(heap, (cost, next(counter), "leaf", snap, link))

    try:
        start, event = interp.advance(interp.begin_tick(interp.initial()), None)
        settle(start, event, 0, None)
        done: set[Any] = set()
        while heap and len(done) < SEARCH_LIMIT:
            cost, _n, kind, what, link = heapq.heappop(heap)
            if kind == "exit":
                exits.setdefault(what, _unlink(link))
                continue
            if what in done:
                continue
            done.add(what)
            request = interp.leaf_request(what)
            assert request is not None
            i = index[request.node.id]
            reach.setdefault(i, _unlink(link))
            for status, extra in costs[i].items():
                snap, event = interp.advance(what, status)
                settle(snap, event, cost + extra, (link, (i, status)))
    except (FsmbtError, ValueError):
        pass  # a construct the abstract run refuses: what was found stands
    return exits, reach


def _unlink(link: Any) -> Path:
    found: Path = []
    while link is not None:
        link, step = link
        found.append(step)
    return found[::-1]


class Realizer:
    """Shortest realizations of every node of a compiled tree (rule 1 of the module
    docstring), bottom-up once: O(nodes) plus one search per distinct abstract problem."""

    def __init__(self, tree: CompiledTree) -> None:
        self.tree = tree
        self.costs: dict[int, Costs] = {}
        self.paths: dict[int, dict[int, Path]] = {}
        self.reach: dict[int, dict[int, Path]] = {}
        memo: dict[Any, tuple[dict[int, Path], dict[int, Path]]] = {}
        for node in reversed(tree.nodes):
            if not node.children:
                if node.internal_status is not None:
                    self.costs[node.id] = {node.internal_status: 0}
                elif node.kind is NodeKind.ACTION:
                    self.costs[node.id] = {SUCCESS: 1, FAILURE: 1, RUNNING: 1}
                elif node.kind is NodeKind.CONDITION:
                    self.costs[node.id] = {SUCCESS: 1, FAILURE: 1}
                else:
                    self.costs[node.id] = {}
                continue
            kids = [self.costs[c] for c in node.children]
            attrs = tuple(sorted((k, v) for k, v in node.source.attrs.items() if k != "name"))
            key = (
                node.type,
                node.source.semantics,
                attrs,
                tuple(tuple(sorted(c.items())) for c in kids),
            )
            found = memo.get(key)
            if found is None:
                found = memo[key] = _search(node, kids)
            exits, reach = found
            self.paths[node.id] = exits
            self.reach[node.id] = reach
            self.costs[node.id] = {
                s: sum(kids[i][st] for i, st in path) for s, path in exits.items()
            }

    def expand(self, nid: int, status: int) -> list[tuple[int, int]] | None:
        """The leaf outcomes ``(leaf id, status)`` realizing ``nid`` returning ``status``
        (explicit stack); ``None`` when none was found."""
        found: list[tuple[int, int]] = []
        stack = [(nid, status)]
        while stack:
            x, s = stack.pop()
            node = self.tree.nodes[x]
            if not node.children:
                if s not in self.costs[x]:
                    return None
                if node.is_env_leaf:
                    found.append((x, s))
                continue
            path = self.paths[x].get(s)
            if path is None:
                return None
            stack.extend((node.children[i], st) for i, st in reversed(path))
        return found

    def cheapest(self, nid: int) -> int | None:
        costs = self.costs[nid]
        return min(costs, key=lambda s: (costs[s], s)) if costs else None


def drive(
    tree: CompiledTree,
    target: int,
    local: Sequence[tuple[int | None, Any]],
    extra: int,
    region: Sequence[int] = (),
    prefix: Sequence[int] = (),
) -> list[str] | None:
    """Leaf outcomes from the root that tick ``target`` and then give its children the local
    counterexample's outcomes, then ``extra`` more leaves (rule 2); ``None``: not liftable.
    With ``region`` (and no ``local``): once ``target`` is ticked, the leaves under it answer
    these statuses in order (a region's own counterexample: its leaf outcomes from its fresh
    tick, which the whole tree asks in the same order while the tick reaches it). With
    ``prefix`` (``approach.approach``: a run to ``target``'s first tick), the leaves answer it
    until ``target`` is ticked, instead of each off-path child's realization from rest."""
    if any(symbol == "halt" for _pos, symbol in local):
        return None
    answers = deque(region)
    approaching = deque(prefix)
    realizer = Realizer(tree)
    nodes = tree.nodes
    chain: list[int] = []
    x: int | None = target
    while x is not None:
        chain.append(x)
        x = nodes[x].parent
    events = deque((pos, s) for pos, s in local if pos is not None)
    interp = BTInterpreter(tree)
    queues: dict[int, deque[tuple[int, int]]] = {}
    goal: tuple[int, int] | None = None  # (child, status) answered by propagation
    inputs: list[str] = []
    left, reached = extra, False
    snap, event = interp.advance(interp.begin_tick(interp.initial()), None)
    for _step in range(DRIVE_LIMIT):
        if not isinstance(event, LeafRequest):
            if event.status != RUNNING:
                return inputs  # the root returned: the leaf machine stops here
            snap, event = interp.advance(interp.begin_tick(snap), None)
            continue
        active = [frame[0] for frame in snap[2]]
        reached = reached or target in active
        if reached and not events and not answers:  # the counterexample is given: ``extra``
            if left <= 0:
                return inputs
            left -= 1
        status = None
        if approaching and not reached:
            status = approaching.popleft()
        elif answers and target in active:
            status = answers.popleft()
            if event.node.is_condition and status == RUNNING:
                return None
        else:
            status = _from_queue(queues, active, event.node)
        if status is not None:
            pass
        elif goal is not None and goal[0] in active:
            status = _propagate(realizer, active, active.index(goal[0]), goal[1])
        else:
            goal = None
            child, wanted = _plan(active, target, chain, events, realizer)
            if child is None:
                return None
            if wanted is None:
                wanted = realizer.cheapest(child)
            if wanted is None:
                return None
            steps = realizer.expand(child, wanted)
            if steps:
                queues[child] = deque(steps)
                status = _from_queue(queues, active, event.node)
            if status is None:  # the child is not fresh: answer by its goal, leaf by leaf
                queues.pop(child, None)
                goal = (child, wanted)
                status = _propagate(realizer, active, active.index(child), wanted)
        inputs.append(SYMBOL[status])
        try:
            snap, event = interp.advance(snap, status)
        except (FsmbtError, ValueError, BTLivelock):
            return None
    return None


def _propagate(realizer: Realizer, active: list[int], at: int, status: int) -> int:
    """The requested leaf's answer when ``active[at]`` must return ``status`` from where it
    is: down the active path, each child gets the last status its parent's shortest
    realization gives it (or its cheapest)."""
    nodes = realizer.tree.nodes
    for k in range(at, len(active) - 1):
        x, y = active[k], active[k + 1]
        path = realizer.paths.get(x, {}).get(status, [])
        index = nodes[y].index
        found = [st for i, st in path if i == index]
        cheapest = realizer.cheapest(y)
        status = found[-1] if found else (cheapest if cheapest is not None else FAILURE)
    leaf = nodes[active[-1]]
    if leaf.is_condition and status == RUNNING:
        return FAILURE
    return status


def _from_queue(
    queues: dict[int, deque[tuple[int, int]]], active: list[int], leaf: CompiledNode
) -> int | None:
    """The next planned outcome of the deepest active node with one left, if it is meant for
    ``leaf`` (else the plan is dropped: the run went elsewhere)."""
    for nid in reversed(active):
        queue = queues.get(nid)
        if queue:
            planned_leaf, status = queue.popleft()
            if planned_leaf != leaf.id:
                queue.clear()
                return None
            if leaf.is_condition and status == RUNNING:
                return None
            return status
    return None


def _plan(
    active: list[int],
    target: int,
    chain: list[int],
    events: deque[tuple[int, Any]],
    realizer: Realizer,
) -> tuple[int | None, int | None]:
    """The child whose realization answers the next leaves, and the status it must return."""
    nodes = realizer.tree.nodes
    if target in active:
        at = active.index(target)
        if at + 1 >= len(active):
            return None, None
        child = active[at + 1]
        position = nodes[child].index
        while events and events[0][0] != position:
            pos, status = events[0]
            if realizer.expand(nodes[target].children[pos], status) != []:
                return None, None  # the run ticks another child than the local one
            events.popleft()  # a child without leaves answers on its own
        if not events:
            return child, None
        return child, events.popleft()[1]
    on_chain = set(chain)
    deepest = max((i for i, nid in enumerate(active) if nid in on_chain), default=None)
    if deepest is None or deepest + 1 >= len(active):
        return None, None
    ancestor, child = active[deepest], active[deepest + 1]
    below = chain[chain.index(ancestor) - 1]
    path = realizer.reach.get(ancestor, {}).get(nodes[below].index, [])
    wanted = next((s for i, s in path if i == nodes[child].index), None)
    return child, wanted


def separates(found: Replay) -> bool:
    """The replay tells the machines apart, and not by the source refusing its input."""
    return found.differs and _SOURCE_REFUSES not in found.differences[0]


def separating_prefix(
    source: Machine[Any], result: Machine[Any], inputs: list[str]
) -> list[str] | None:
    """The inputs cut at the first step where the replay separates the machines (``None``:
    no prefix does). Cost: one replay."""
    found = replay(source, result, inputs)
    if not separates(found):
        return None
    return inputs[: next(step.step for step in found.steps if step.note)]


def confirm(
    source: Machine[Any], result: Machine[Any], inputs: list[str]
) -> tuple[list[str], Replay] | None:
    """Rule 3: the inputs cut at the first separating step and shortened greedily, with
    their replay; ``None`` when no prefix separates the machines."""
    cut = separating_prefix(source, result, inputs)
    if cut is None:
        return None
    best = cut
    runs = 0
    i = len(best) - 1
    deadline = time.perf_counter() + SHORTEN_SECONDS
    while i >= 0 and runs < SHORTEN_REPLAYS and time.perf_counter() < deadline:
        trial = best[:i] + best[i + 1 :]
        runs += 1
        attempt = replay(source, result, trial)
        if separates(attempt):
            first = next(step.step for step in attempt.steps if step.note)
            best = trial[:first]
            i = min(i, len(best)) - 1
        else:
            i -= 1
    return best, replay(source, result, best)


LIFTED_SENTENCE = (
    "per node, lifted: the per-node check found a node whose local check fails; its local "
    "counterexample was lifted to leaf outcomes from the root and replayed on the two whole "
    "machines, which it tells apart (a real counterexample, not always a shortest one)"
)


REGION_LIFTED_SENTENCE = (
    "compositional, lifted: a region checked alone against its composite state fails; its "
    "counterexample (leaf outcomes from the region's fresh tick) was lifted to leaf outcomes "
    "from the root and replayed on the two whole machines, which it tells apart (a real "
    "counterexample, not always a shortest one)"
)


def lift_machines(source: BTDocument, result: FSM) -> tuple[Machine[Any], LazyDataMachine]:
    """The two whole machines a lifted counterexample is confirmed on (and a certificate of it
    replayed on): the interpreter's leaf machine of ``source`` and ``result``'s data machine
    expanded lazily (a large result is never flattened).

    Raises:
        Unsupported: the result's data is outside what the lazy machine expands.
    """
    return leaf_machine(source), LazyDataMachine(result)


def lifted_report(
    source: BTDocument, result: FSM, region: BTNode, failed: PerNodeOutcome
) -> Report | None:
    """NOT EQUIVALENT with the lifted counterexample of ``failed`` (a per-node check that
    failed in ``region``), or ``None`` when the lift does not separate the whole machines
    (the caller runs the whole product). The failing nodes the check collected are driven and
    replayed in the walk's order; the first whose replay separates the machines is kept and
    shortened."""
    tree = failed.tree
    if tree is None or failed.failed_id is None or failed.failed is None:
        return None
    merged = tree.doc.main.root
    assert merged is not None
    try:
        machines = lift_machines(source, result)
    except Unsupported:
        return None
    best: tuple[list[str], str] | None = None  # (separating inputs, the node)
    first = (failed.failed, failed.failed_id, failed.trace)
    for what, node_id, trace in itertools.chain([first], failed.more):
        found = _target(source, region, merged, tree.nodes[node_id].source)
        if found is None:
            continue
        for prefix in _approaches(*found):
            inputs = drive(found[0], found[1], trace, extra=4 * len(trace) + 64, prefix=prefix)
            try:
                cut = None if inputs is None else separating_prefix(*machines, inputs)
            except Unsupported:  # the result's run meets what the lazy runner refuses
                continue
            if cut is not None:  # the first that separates (each try: a drive and a replay)
                best = (cut, f"node {what}")
                break
        if best is not None:
            break
    if best is None:
        return None
    return _confirmed(source, result, best[0], best[1], PER_NODE_LIFTED, LIFTED_SENTENCE)


WALKED_SENTENCE = (
    "per node, random runs: a part of the compositional check failed (a node's local check "
    "or a region's) and no planned drive reached the failure; "
    "seeded random leaf outcomes from the root were replayed on the two whole machines until "
    "one run told them apart (verify/random_walk.py; a real counterexample, cut at the first "
    "difference and shortened, not always a shortest one)"
)


def walked_report(source: BTDocument, result: FSM, what: str) -> Report | None:
    """NOT EQUIVALENT with the first seeded random run that separates the two whole machines
    (``verify/random_walk.py``), confirmed and shortened as a lifted counterexample, or
    ``None``: no run does (nothing is claimed). ``what``: the failing node, for the details."""
    try:
        machines = lift_machines(source, result)
    except Unsupported:
        return None
    rng = random.Random(SEED)
    spent, allowed = 0, budget(sum(1 for _ in source.nodes()))
    while spent < allowed:
        try:
            inputs = walk_inputs(machines[0], rng, WALK_LEAVES)
            cut = separating_prefix(*machines, inputs)
        except (Unsupported, FsmbtError):
            return None
        if cut is not None:
            return _confirmed(source, result, cut, what, PER_NODE_LIFTED, WALKED_SENTENCE)
        spent += max(len(inputs), 1)
    return None


def lifted_region_report(
    source: BTDocument, result: FSM, region: BTNode, failed: Report
) -> Report | None:
    """NOT EQUIVALENT with the counterexample of a region checked alone (``failed``: the
    region's subtree run as a tree of its own against its composite state, docs/semantics.md
    §4c) lifted to the whole tree: the drive ticks the region fresh, then its leaves answer
    the region counterexample's outcomes in order (``drive``'s ``region``), confirmed by
    replay as a per-node lift; ``None`` when the replay does not separate the machines."""
    traces = [p.counterexample for p in failed.properties.values() if p.counterexample]
    if not traces:
        return None
    shortest = min(traces, key=len)
    answers = [STATUS[str(step.input)] for step in shortest[1:] if step.input in STATUS]
    if len(answers) != len(shortest) - 1:
        return None
    found = _target(source, region, region, region)
    if found is None:
        return None
    whole, target_id = found
    where = f"region {region.label}"
    for prefix in _approaches(whole, target_id):
        inputs = drive(whole, target_id, [], extra=64, region=answers, prefix=prefix)
        if inputs is None:
            continue
        report = _confirmed(
            source, result, inputs, where, COMPOSITIONAL_LIFTED, REGION_LIFTED_SENTENCE
        )
        if report is not None:
            return report
    return None


def _approaches(tree: CompiledTree, target: int) -> list[Sequence[int]]:
    """The prefixes ``drive`` tries, in order: the stages' approach to ``target``'s first tick
    (``verify/approach.py``, rule 3; usually far shorter on large trees with memory), then none
    (each off-path child's realization from rest)."""
    found = approach(tree, target)
    return [found, ()] if found else [()]


def _target(
    source: BTDocument, region: BTNode, merged: BTNode, wanted: BTNode
) -> tuple[CompiledTree, int] | None:
    """The whole tree (``region`` replaced by ``merged``) and the id of the node ``wanted``."""
    try:
        whole = CompiledTree(whole_tree(source, region, merged))
    except FsmbtError:
        return None
    ids = [n.id for n in whole.nodes if n.source is wanted]
    return (whole, ids[0]) if len(ids) == 1 else None


def _confirmed(
    source: BTDocument,
    result: FSM,
    inputs: list[str],
    what: str,
    method: str,
    sentence: str,
) -> Report | None:
    """Rule 3 on the driven ``inputs`` and the report of what the replay shows (``what``: the
    failing node or region, for the details)."""
    try:
        machines = lift_machines(source, result)
        found = confirm(*machines, inputs)
    except Unsupported:
        return None
    if found is None:
        return None
    best, shown = found
    try:  # is it the shortest? the whole machines' first levels say, within a budget
        search = search_shorter(*machines, len(best))
        if search.shorter is not None:
            best, shown = search.shorter, replay(*machines, search.shorter)
    except (Unsupported, FsmbtError):  # a state a machine cannot step: nothing is claimed
        search = ShorterSearch(len(best), None, False, 0, 0)
    report = Report(engine="native", source="source", result="result", mode=LEAF_EXECUTION)
    step = next(s for s in shown.steps if s.note)
    trace = shown.steps[: step.step + 1]
    where = f"after {len(best)} lifted leaf outcomes ({what})"
    if _SOURCE_REFUSES not in step.note and tuple(step.source_outputs) != tuple(
        step.result_outputs
    ):
        said = (
            f"{where} the source does {_show(step.source_outputs)}, "
            f"the result {_show(step.result_outputs)}"
        )
        if not _within(step.source_outputs, step.result_outputs):
            report.properties[COMPLETENESS] = PropertyResult(COMPLETENESS, False, said, trace)
        if not _within(step.result_outputs, step.source_outputs):
            report.properties[NO_ADDITIONAL_BEHAVIOR] = PropertyResult(
                NO_ADDITIONAL_BEHAVIOR, False, said, trace
            )
    if step.source_status != step.result_status:
        report.properties[TERMINATION_CONSISTENCY] = PropertyResult(
            TERMINATION_CONSISTENCY,
            False,
            f"{where} the source is {step.source_status}, the result {step.result_status}",
            trace,
        )
    if not report.properties:  # the result refuses an input the source takes
        report.properties[COMPLETENESS] = PropertyResult(
            COMPLETENESS, False, f"{where}: {step.note}", trace
        )
    report.method = method
    report.abstractions = [sentence, search.sentence()]
    report.stats = {
        "lifted_steps": len(best),
        "drive_steps": len(inputs),
        "shortest": search.exhausted,
        "shortest_search_pairs": search.pairs,
    }
    return report


def _within(small: Sequence[str], big: Sequence[str]) -> bool:
    it = iter(big)
    return all(any(item == other for other in it) for item in small)


def _show(outputs: Sequence[str]) -> str:
    return ", ".join(outputs) if outputs else "nothing"
