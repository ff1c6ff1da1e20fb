"""LEBT structure recognition (docs/conversion.md, 'FSM -> BT: the loop-execution BT'): entry, loop and ordinary states; chain and branch links.

Definitions, on the part of the FSM that can run (see ``analyse``):
- the entry state is the target of the initial transition (the FSM's initial state);
- a loop state has in-degree >= 2, counted as distinct predecessor states, the start
  pseudo-state's edge into the entry state and a self-loop included;
- every other state has exactly one predecessor ``p``; it is linked below ``p``: ``p``'s body is a
  chain (one such successor) or a branch (several).
The root subtrees are the entry state first, then the loop states in the FSM's declaration order
(an entry state that is also a loop state gets one subtree). Ordinary states hang below their
predecessor in the order of ``p``'s outgoing transitions.

Preparation: transitions out of final states are dropped (a final state accepts no event, so they
never fire), then states the initial state cannot reach are dropped with a warning (they never
run, so no behaviour depends on them) before degrees are counted. Of several transitions leaving
one state on the same event only the first counts (as ``FSMMachine`` runs it).

Representation: a state is its position in ``fsm.states`` (declaration order);
``LebtStructure.start_id`` (= the number of states) stands for the start pseudo-state. Edges are
flat parallel sequences - source indices, target indices (``array('l')``: machine integers, no
object per entry) and events - grouped by source in declaration order, each source's edges in
transition order (the order files usually give them in; otherwise one stable sort by source).
There is no list per state and no string-keyed dictionary after the one name -> index look-up
per transition endpoint. This is about memory, not operation counts: at 100 000 states a
random machine's transitions point at random states, and every step that follows a transition
touches memory far from the last one; on flat arrays of machine integers (hundreds of KB) that
is a cache hit, on a list per state and an integer object per entry (megabytes spread over the
heap) it was a cache miss (docs/conversion.md, 'Cost of FSM -> BT'). Name-keyed views
(``roots``, ``children``, ``guard_pairs``, ``exits``, ``predecessors``) and per-state lists
(``child_ids``) are built on first use, for callers that want them (the hierarchical builder
``fsmbt.convert.hfsm_to_bt``, tests).

Complexity: O(S + T) time and memory for S states and T transitions (O(T log T) for the sort
when the transitions are not grouped by source in declaration order), no recursion.
"""

from __future__ import annotations

from array import array
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from itertools import compress
from typing import NoReturn

from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, Transition
from fsmbt.semantics.lebt.spec import DEFAULT_START, NO_EVENT

#: Deepest XML element a written ``<BehaviorTree>`` may hold, ``<root>`` = level 1 (so its
#: tree's root node is on level 3): BehaviorTree.CPP 4.8.2's tinyxml2 refuses 500, 4.9+ refuses
#: 256 (docs/semantics.md §5, "Depth-bounded LEBT").
MAX_XML_LEVELS = 200
#: Selector levels an LEBT may nest (``bound_depth``): ``k`` levels give a tree of ``2k + 1``
#: node levels, i.e. XML down to level ``2k + 3``.
MAX_SELECTOR_LEVELS = (MAX_XML_LEVELS - 3) // 2

# pred_mark values besides a state index: no predecessor yet, several distinct predecessors
_NO_PRED = -1
_MANY_PREDS = -2


@dataclass
class LebtStructure:
    """What the LEBT builder needs, computed once; states are indices into ``names``.

    Attributes:
        start: The start pseudo-state's name.
        names: Every state of the FSM in declaration order (reachable or not); index = position.
        entry_id: The entry state's index.
        reachable_ids: The reachable states' indices, ascending (declaration order); a
            ``range`` when every state is reachable (no integer object per state).
        root_ids: The entry state, then the loop states, in declaration order (after
            ``bound_depth``: then the states promoted to roots to bound the depth).
        loop_ids: The loop states (in-degree >= 2), in declaration order.
        kept_sources: The source of every transition that can fire (out of a reachable,
            non-final state, the first per (source, event)), grouped by source in declaration
            order, each source's in transition order.
        kept_targets: Their targets, parallel to ``kept_sources``.
        kept_events: Their events, parallel to ``kept_sources``.
        child_sources: Per link "state of in-degree 1 below its only predecessor", the
            predecessor, grouped by predecessor in declaration order.
        child_targets: The linked state, parallel (per predecessor in the order of its
            outgoing transitions).
        child_counts: Per state, how many states are linked below it.
        placed: Per state, 1 when it is a root or linked below its predecessor (a reachable
            state entered only by transitions that never fire is neither).
        initial_event: The event of the start pseudo-state's transition (``NO_EVENT``: none).
        unreachable: The states dropped, by name.
    """

    start: str
    names: list[str]
    entry_id: int
    reachable_ids: Sequence[int]
    root_ids: list[int]
    loop_ids: list[int]
    kept_sources: Sequence[int]
    kept_targets: Sequence[int]
    kept_events: Sequence[str]
    child_sources: Sequence[int]
    child_targets: Sequence[int]
    child_counts: Sequence[int]
    placed: bytearray
    initial_event: str
    unreachable: list[str] = field(default_factory=list)

    @property
    def start_id(self) -> int:
        """The index standing for the start pseudo-state in ``guard_ids`` (one past the last
        state, so ``[*names, start][start_id]`` is its name)."""
        return len(self.names)

    @property
    def entry(self) -> str:
        """The entry state's name."""
        return self.names[self.entry_id]

    # -- per-state lists, built on first use (O(S + T) each) ---------------------------------
    @cached_property
    def child_ids(self) -> list[list[int]]:
        """Per state, the states linked below it, in the order of its outgoing transitions."""
        below: list[list[int]] = [[] for _ in self.names]
        for source, child in zip(self.child_sources, self.child_targets):
            below[source].append(child)
        return below

    @cached_property
    def exit_events(self) -> list[list[str]]:
        """Per state, the events of its transitions that can fire, in transition order."""
        events: list[list[str]] = [[] for _ in self.names]
        for source, event in zip(self.kept_sources, self.kept_events):
            events[source].append(event)
        return events

    # -- name-keyed views, built on first use (O(S + T) each) --------------------------------
    @cached_property
    def roots(self) -> list[str]:
        """The root states by name: the entry state, then loop states in declaration order."""
        return [self.names[i] for i in self.root_ids]

    @cached_property
    def loop_states(self) -> list[str]:
        """The loop states by name, in declaration order."""
        return [self.names[i] for i in self.loop_ids]

    @cached_property
    def children(self) -> dict[str, list[str]]:
        """Reachable state -> successors of in-degree 1 linked below it."""
        names, below = self.names, self.child_ids
        return {names[i]: [names[c] for c in below[i]] for i in self.reachable_ids}

    def guard_ids(self) -> list[list[tuple[int, str]]]:
        """Per state, the (source index or ``start_id``, event) pairs entering it: the start
        pair first for the entry state, then by source in declaration order and by the
        source's transitions. O(S + T)."""
        pairs: list[list[tuple[int, str]]] = [[] for _ in self.names]
        pairs[self.entry_id].append((self.start_id, self.initial_event))
        for source, target, event in zip(self.kept_sources, self.kept_targets, self.kept_events):
            pairs[target].append((source, event))
        return pairs

    @cached_property
    def guard_pairs(self) -> dict[str, list[tuple[str, str]]]:
        """Reachable state -> the (source, event) pairs entering it (``guard_ids`` by name)."""
        sources = [*self.names, self.start]
        by_index = self.guard_ids()
        return {
            self.names[i]: [(sources[s], event) for s, event in by_index[i]]
            for i in self.reachable_ids
        }

    @cached_property
    def exits(self) -> dict[str, list[str]]:
        """Reachable state -> the events with a transition out of it."""
        events = self.exit_events
        return {self.names[i]: events[i] for i in self.reachable_ids}

    @cached_property
    def predecessors(self) -> dict[str, list[str]]:
        """Reachable state -> its distinct predecessors (the start pseudo-state included)."""
        return {
            target: list(dict.fromkeys(source for source, _event in pairs))
            for target, pairs in self.guard_pairs.items()
        }

    def kind(self, state: str) -> str:
        """``entry``, ``loop``, ``entry+loop``, ``chain`` (one child), ``branch`` or ``leaf``."""
        tags = []
        if state == self.entry:
            tags.append("entry")
        if state in self.loop_states:
            tags.append("loop")
        if tags:
            return "+".join(tags)
        count = len(self.children.get(state, ()))
        return "leaf" if count == 0 else "chain" if count == 1 else "branch"


def _edges(fsm: FSM, index: dict[str, int]) -> tuple[array[int], array[int], list[str]]:
    """Every transition out of a non-final state as three parallel flat sequences - source
    indices, target indices, events - grouped by source in declaration order, each source's
    in transition order (a stable sort when the FSM does not list them so). Raises the located
    errors for an unknown state, an eventless and an empty-event transition."""
    finals = bytearray(state.final for state in fsm.states.values())
    sources: array[int] = array("l")
    targets: array[int] = array("l")
    events: list[str] = []
    add_source, add_target, add_event = sources.append, targets.append, events.append
    grouped = True
    last = 0
    for t in fsm.transitions:
        source = index.get(t.source)
        target = index.get(t.target)
        event = t.event
        if source is None or target is None or not event:
            _refuse(fsm, t, source is None)
        assert source is not None and target is not None and event is not None
        if finals[source]:
            continue  # never fires
        if source < last:
            grouped = False
        last = source
        add_source(source)
        add_target(target)
        add_event(event)
    if not grouped:
        order = sorted(range(len(sources)), key=sources.__getitem__)  # stable
        sources = array("l", [sources[k] for k in order])
        targets = array("l", [targets[k] for k in order])
        events = [events[k] for k in order]
    return sources, targets, events


def _refuse(fsm: FSM, t: Transition, source_unknown: bool) -> NoReturn:
    """The located error for a transition ``analyse`` cannot take."""
    if t.source not in fsm.states or t.target not in fsm.states:
        missing = t.source if source_unknown else t.target
        raise InputError(
            f"transition refers to unknown state '{missing}'",
            element=fsm.name,
            location=t.location,
        )
    if t.event is None:
        raise InputError(
            "eventless transition in a flat FSM; flatten it first",
            element=t.source,
            location=t.location,
        )
    raise UnsupportedError(
        "an empty event name cannot be told from 'no event'",
        element=t.source,
        location=t.location,
    )


def _reached(entry: int, count: int, sources: array[int], targets: array[int]) -> bytearray:
    """Flag 1 per state reachable from ``entry`` over the edges (grouped by source).

    First a sequential pass for the usual case, a machine declared roughly in the order it
    runs: take the order "entry first, then declaration order"; if every other state has a
    transition from a state before it in that order, every state is reachable (by induction
    along the order) - checked without visiting the states in graph order, which at 100 000
    states of a random machine is a cache miss per state. Otherwise, breadth-first search.
    """
    seen = bytearray(count)
    seen[entry] = 1
    for source, target in zip(sources, targets):
        if target > source or source == entry:
            seen[target] = 1
    if seen.count(0) == 0:
        return seen
    first = [0] * (count + 1)  # first[s]: where source s's edges start (grouped by source)
    for source in sources:
        first[source + 1] += 1
    for state in range(count):
        first[state + 1] += first[state]
    seen = bytearray(count)
    seen[entry] = 1
    queue = [entry]
    for state in queue:  # the list grows while it is read: a queue without pops
        for target in targets[first[state] : first[state + 1]]:
            if not seen[target]:
                seen[target] = 1
                queue.append(target)
    return seen


def _kept_flags(sources: array[int], events: list[str], seen: bytearray) -> bytearray | None:
    """Per edge, 1 when it can fire: its source is reachable and it is its source's first
    edge on its event. ``None`` when every edge can (the usual case: no copy is made)."""
    flags: bytearray | None = None
    previous = -1
    first_event = ""
    group: set[str] | None = None  # the events seen so far from a source with >= 2 edges
    for k, (source, event) in enumerate(zip(sources, events)):
        if source != previous:
            previous, first_event, group = source, event, None
            if seen[source]:
                continue
        elif seen[source]:
            if group is None:
                group = {first_event}
            if event not in group:
                group.add(event)
                continue
        if flags is None:
            flags = bytearray(b"\x01") * len(sources)
        flags[k] = 0
    return flags


def analyse(fsm: FSM) -> LebtStructure:
    """Recognise the LEBT structure of a flat FSM (see the module docstring).

    Args:
        fsm: A flat machine (``model.flatten`` first for a hierarchical one).

    Returns:
        The structure, states as indices into ``fsm.states``'s declaration order.

    Raises:
        InputError: a hierarchical machine, no initial state, a transition to an unknown state
            or without an event (located).
        UnsupportedError: a state named like the start pseudo-state, an empty event name.
    """
    if fsm.is_hierarchical:
        raise InputError("LEBT structure needs a flat FSM; flatten it first", element=fsm.name)
    if fsm.initial is None or fsm.initial not in fsm.states:
        raise InputError("the state machine has no initial state", element=fsm.name)
    start = fsm.start_name or DEFAULT_START
    if start in fsm.states:
        raise UnsupportedError(
            f"a state is named like the start pseudo-state '{start}'", element=start
        )
    names = list(fsm.states)
    count = len(names)
    index = {name: position for position, name in enumerate(names)}
    sources, targets, events = _edges(fsm, index)
    entry = index[fsm.initial]
    del index
    seen = _reached(entry, count, sources, targets)
    reachable: Sequence[int]
    if seen.count(0) == 0:
        reachable = range(count)
        unreachable: list[str] = []
    else:
        reachable = [i for i in range(count) if seen[i]]
        unreachable = [names[i] for i in range(count) if not seen[i]]

    # the edges that can fire, and the distinct-predecessor marks they give
    flags = _kept_flags(sources, events, seen)
    if flags is None:
        kept_sources, kept_targets, kept_events = sources, targets, events
    else:
        kept_sources = array("l", compress(sources, flags))
        kept_targets = array("l", compress(targets, flags))
        kept_events = list(compress(events, flags))
    pred_mark = array("l", [_NO_PRED]) * count  # _NO_PRED, the only predecessor, _MANY_PREDS
    pred_mark[entry] = count  # the start pseudo-state
    for source, target in zip(kept_sources, kept_targets):
        mark = pred_mark[target]
        if mark == _NO_PRED:
            pred_mark[target] = source
        elif mark != source:
            pred_mark[target] = _MANY_PREDS

    loop_ids = [i for i in reachable if pred_mark[i] == _MANY_PREDS]
    root_ids = [entry] + [i for i in loop_ids if i != entry]
    placed = bytearray(count)  # a root, or linked below its only predecessor (at most once)
    for root in root_ids:
        placed[root] = 1
    child_sources: array[int] = array("l")
    child_targets: array[int] = array("l")
    child_counts = array("l", [0]) * count
    for source, target in zip(sources, targets):  # every transition, in order
        if placed[target] or pred_mark[target] != source:
            continue  # (only a reachable source is a predecessor: no check of ``seen``)
        placed[target] = 1
        child_sources.append(source)
        child_targets.append(target)
        child_counts[source] += 1
    return LebtStructure(
        start,
        names,
        entry,
        reachable,
        root_ids,
        loop_ids,
        kept_sources,
        kept_targets,
        kept_events,
        child_sources,
        child_targets,
        child_counts,
        placed,
        fsm.initial_event if fsm.initial_event is not None else NO_EVENT,
        unreachable,
    )


def bound_depth(structure: LebtStructure, max_levels: int = MAX_SELECTOR_LEVELS) -> LebtStructure:
    """The structure with no selector nested deeper than ``max_levels`` (root selectors = 1):
    docs/semantics.md §5, "Depth-bounded LEBT".

    Rule: walk the links from the roots; a state whose selector would sit on level
    ``max_levels + 1`` is not linked below its predecessor but *promoted* to a root (appended
    to the root Sequence in the order the walk meets them) and its own links are counted from
    level 1 again. A promoted state is entered as a loop state is: its predecessor's leaf
    returns SUCCESS with the event pending, every enclosing Sequence completes (the later
    sibling guards do not hold the pair), and the root's Sequence reaches the promoted
    selector in the same tick or, when it lies before, in the second tick of the macro step.
    So a chain of ``n`` states becomes ``ceil(n / max_levels)`` root selectors each holding a
    chain of at most ``max_levels`` states: depth ``2 * max_levels + 1`` for any ``n``.

    Returns ``structure`` itself (no copy) when nothing is that deep, so small machines keep
    the paper's exact shape. O(S) time, no recursion.
    """
    if max_levels < 1:
        raise ValueError("max_levels must be >= 1")
    counts = structure.child_counts
    first = array("l", [0]) * (len(counts) + 1)  # where each state's links start
    total = 0
    for state, count in enumerate(counts):
        first[state] = total
        total += count
    child_targets = structure.child_targets
    level = array("l", [0]) * len(counts)
    queue = list(structure.root_ids)
    for root in queue:
        level[root] = 1
    promoted: list[int] = []
    for state in queue:  # the list grows while it is read: a queue without pops
        count = counts[state]
        if not count:
            continue
        below = level[state] + 1
        for child in child_targets[first[state] : first[state] + count]:
            if below > max_levels:
                promoted.append(child)
                level[child] = 1
            else:
                level[child] = below
            queue.append(child)
    if not promoted:
        return structure
    cut = bytearray(len(counts))
    for state in promoted:
        cut[state] = 1
    child_sources: array[int] = array("l")
    kept_targets: array[int] = array("l")
    child_counts = array("l", [0]) * len(counts)
    for source, target in zip(structure.child_sources, child_targets):
        if not cut[target]:
            child_sources.append(source)
            kept_targets.append(target)
            child_counts[source] += 1
    return replace(
        structure,
        root_ids=[*structure.root_ids, *promoted],
        child_sources=child_sources,
        child_targets=kept_targets,
        child_counts=child_counts,
    )
