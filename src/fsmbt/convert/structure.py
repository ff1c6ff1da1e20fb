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
``LebtStructure.start_id`` (= the number of states) stands for the start pseudo-state. The analysis works on integer
indices, flat lists and byte flags - one name -> index look-up per transition endpoint, then no
string-keyed dictionary at all - so that at 100 000 states it does not spend its time on random
probes into dictionaries of 100 000 string keys (docs/conversion.md, 'Cost of FSM -> BT'). The
per-state lists are visited in declaration order, i.e. in the order the FSM's objects lie in
memory. Name-keyed views (``roots``, ``children``, ``guard_pairs``, ``exits``,
``predecessors``) are built on first use, for callers that want names (the hierarchical builder
``fsmbt.convert.hfsm_to_bt``, tests).

Complexity: O(S + T) time and memory for S states and T transitions, no recursion.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import NoReturn

from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, Transition
from fsmbt.semantics.lebt.spec import DEFAULT_START, NO_EVENT

#: Shared empty per-state list (no successor linked below / no kept transition / no exit): many
#: states have none, and one empty list each would cost memory and collector time for nothing.
#: Never appended to.
_NONE: tuple[()] = ()

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
        reachable_ids: The reachable states' indices, ascending (declaration order).
        root_ids: The entry state, then the loop states, in declaration order.
        loop_ids: The loop states (in-degree >= 2), in declaration order.
        child_ids: Per state, the successors of in-degree 1 linked below it, in the order of
            its outgoing transitions (empty for unreachable states).
        kept_targets: Per state, the targets of the transitions that can fire out of it (the
            first per event), parallel to ``exit_events``.
        exit_events: Per state, the events with a transition out of it (first one per event).
        initial_event: The event of the start pseudo-state's transition (``NO_EVENT``: none).
        unreachable: The states dropped, by name.
    """

    start: str
    names: list[str]
    entry_id: int
    reachable_ids: list[int]
    root_ids: list[int]
    loop_ids: list[int]
    child_ids: list[Sequence[int]]
    kept_targets: list[Sequence[int]]
    exit_events: list[Sequence[str]]
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
        names = self.names
        return {names[i]: [names[c] for c in self.child_ids[i]] for i in self.reachable_ids}

    def guard_ids(self) -> list[list[tuple[int, str]]]:
        """Per state, the (source index or ``start_id``, event) pairs entering it: the start
        pair first for the entry state, then by source in declaration order and by the
        source's transitions. O(S + T)."""
        pairs: list[list[tuple[int, str]]] = [[] for _ in self.names]
        pairs[self.entry_id].append((self.start_id, self.initial_event))
        for source in self.reachable_ids:
            for target, event in zip(self.kept_targets[source], self.exit_events[source]):
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
        return {self.names[i]: list(self.exit_events[i]) for i in self.reachable_ids}

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


def _out_edges(
    fsm: FSM, index: dict[str, int]
) -> tuple[list[list[int] | None], list[list[str] | None]]:
    """Per state, the targets and the events of its transitions (two parallel lists, in
    declaration order; ``None`` for none), final states' transitions dropped. Raises the
    located errors for an unknown state, an eventless and an empty-event transition."""
    finals = [state.final for state in fsm.states.values()]
    out_targets: list[list[int] | None] = [None] * len(finals)
    out_events: list[list[str] | None] = [None] * len(finals)
    for t in fsm.transitions:
        source = index.get(t.source)
        target = index.get(t.target)
        event = t.event
        if source is None or target is None or not event:
            _refuse(fsm, t, source is None)
        assert source is not None and target is not None and event is not None
        if finals[source]:
            continue  # never fires
        targets = out_targets[source]
        if targets is None:
            out_targets[source] = [target]
            out_events[source] = [event]
        else:
            targets.append(target)
            out_events[source].append(event)  # type: ignore[union-attr]
    return out_targets, out_events


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


def _reached(entry: int, out_targets: list[list[int] | None]) -> bytearray:
    """Flag 1 per state reachable from ``entry``.

    First a sequential pass for the usual case, a machine declared roughly in the order it
    runs: take the order "entry first, then declaration order"; if every other state has a
    transition from a state before it in that order, every state is reachable (by induction
    along the order) - checked without visiting the states in graph order, which at 100 000
    states of a random machine is a cache miss per state. Otherwise, breadth-first search.
    """
    count = len(out_targets)
    seen = bytearray(count)
    seen[entry] = 1
    for source, targets in enumerate(out_targets):
        if targets is None:
            continue
        if source == entry:
            for target in targets:
                seen[target] = 1
        else:
            for target in targets:
                if target > source:
                    seen[target] = 1
    if seen.count(0) == 0:
        return seen
    seen = bytearray(count)
    seen[entry] = 1
    queue = [entry]
    for state in queue:  # the list grows while it is read: a queue without pops
        for target in out_targets[state] or _NONE:
            if not seen[target]:
                seen[target] = 1
                queue.append(target)
    return seen


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
    out_targets, out_events = _out_edges(fsm, index)
    entry = index[fsm.initial]
    seen = _reached(entry, out_targets)
    reachable = [i for i in range(count) if seen[i]]
    unreachable = [names[i] for i in range(count) if not seen[i]]

    # kept edges (the first per (source, event)) and the distinct-predecessor marks
    kept_targets: list[Sequence[int]] = [_NONE] * count
    exit_events: list[Sequence[str]] = [_NONE] * count
    pred_mark = [_NO_PRED] * count  # _NO_PRED, the only predecessor's index, or _MANY_PREDS
    pred_mark[entry] = count  # the start pseudo-state
    for source in reachable:
        targets = out_targets[source]
        if targets is None:
            continue
        events = out_events[source]
        assert events is not None
        if len(events) > 1 and len(set(events)) < len(events):
            firsts: dict[str, int] = {}
            for target, event in zip(targets, events):
                firsts.setdefault(event, target)
            events, targets = list(firsts), list(firsts.values())
        exit_events[source] = events
        kept_targets[source] = targets
        for target in targets:
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
    child_ids: list[Sequence[int]] = [_NONE] * count
    for source in reachable:
        below: list[int] | None = None
        for target in out_targets[source] or _NONE:  # every transition, in order
            if placed[target] or pred_mark[target] != source:
                continue
            placed[target] = 1
            if below is None:
                below = [target]
                child_ids[source] = below
            else:
                below.append(target)
    return LebtStructure(
        start,
        names,
        entry,
        reachable,
        root_ids,
        loop_ids,
        child_ids,
        kept_targets,
        exit_events,
        fsm.initial_event if fsm.initial_event is not None else NO_EVENT,
        unreachable,
    )
