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
run, so no behaviour depends on them) before degrees are counted.

Complexity: O(S + T) time and memory, no recursion.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, Transition
from fsmbt.semantics.lebt.spec import DEFAULT_START, NO_EVENT


@dataclass
class LebtStructure:
    """What the LEBT builder needs, computed once."""

    start: str
    entry: str
    roots: list[str]  # the entry state, then loop states in declaration order
    loop_states: list[str]
    children: dict[str, list[str]]  # state -> successors of in-degree 1 linked below it
    guard_pairs: dict[str, list[tuple[str, str]]]  # state -> (source, event) pairs entering it
    exits: dict[str, list[str]]  # state -> events with a transition out of it
    predecessors: dict[str, list[str]]
    unreachable: list[str] = field(default_factory=list)

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


def _reachable(fsm: FSM, table: dict[str, list[Transition]]) -> list[str]:
    assert fsm.initial is not None
    seen = {fsm.initial}
    queue = deque([fsm.initial])
    while queue:
        for t in table.get(queue.popleft(), ()):
            if t.target not in seen:
                seen.add(t.target)
                queue.append(t.target)
    return [name for name in fsm.states if name in seen]


def analyse(fsm: FSM) -> LebtStructure:
    """Recognise the LEBT structure of a flat FSM (see the module docstring)."""
    if fsm.is_hierarchical:
        raise InputError("LEBT structure needs a flat FSM; flatten it first", element=fsm.name)
    if fsm.initial is None or fsm.initial not in fsm.states:
        raise InputError("the state machine has no initial state", element=fsm.name)
    start = fsm.start_name or DEFAULT_START
    if start in fsm.states:
        raise UnsupportedError(
            f"a state is named like the start pseudo-state '{start}'", element=start
        )
    table: dict[str, list[Transition]] = {}
    for t in fsm.transitions:
        if t.source not in fsm.states or t.target not in fsm.states:
            missing = t.source if t.source not in fsm.states else t.target
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
        if t.event == NO_EVENT:
            raise UnsupportedError(
                "an empty event name cannot be told from 'no event'",
                element=t.source,
                location=t.location,
            )
        if fsm.states[t.source].final:
            continue  # never fires
        table.setdefault(t.source, []).append(t)
    reachable = _reachable(fsm, table)
    live = set(reachable)
    unreachable = [name for name in fsm.states if name not in live]

    entry = fsm.initial
    predecessors: dict[str, list[str]] = {name: [] for name in reachable}
    guard_pairs: dict[str, list[tuple[str, str]]] = {name: [] for name in reachable}
    exits: dict[str, list[str]] = {name: [] for name in reachable}
    predecessors[entry].append(start)
    guard_pairs[entry].append(
        (start, fsm.initial_event if fsm.initial_event is not None else NO_EVENT)
    )
    seen_pred: set[tuple[str, str]] = {(start, entry)}
    for source in reachable:
        events_out: dict[str, None] = {}
        for t in table.get(source, ()):
            if t.event in events_out:
                continue  # nondeterministic duplicate: the first transition wins (as FSMMachine)
            events_out[t.event] = None  # type: ignore[index]
            guard_pairs[t.target].append((source, t.event))  # type: ignore[arg-type]
            if (source, t.target) not in seen_pred:
                seen_pred.add((source, t.target))
                predecessors[t.target].append(source)
        exits[source] = list(events_out)  # type: ignore[arg-type]

    loop_states = [name for name in reachable if len(predecessors[name]) >= 2]
    roots = [entry] + [name for name in loop_states if name != entry]
    root_set = set(roots)
    children: dict[str, list[str]] = {name: [] for name in reachable}
    linked: set[str] = set()  # a non-root state has one predecessor: it is linked at most once
    for source in reachable:
        below = children[source]
        for t in table.get(source, ()):
            target = t.target
            if target in root_set or target in linked:
                continue
            preds = predecessors[target]
            if len(preds) == 1 and preds[0] == source:
                linked.add(target)
                below.append(target)
    return LebtStructure(
        start, entry, roots, loop_states, children, guard_pairs, exits, predecessors, unreachable
    )
