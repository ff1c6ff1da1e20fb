"""BT -> FSM of a dispatch tree (docs/semantics.md, "12. The dispatch form", "Back to a state
machine"): the state machine the tree's macro steps are.

A dispatch tree (``fsmbt.convert.dispatch``; any tree whose leaves are ``DispatchEntry``) runs
by macro steps (``fsmbt.semantics.dispatch_runtime.DispatchMachine``): events in, the entry
actions of the ``DispatchEntry`` leaves a tick runs out. Its state machine is read off those
macro steps, exactly:

1. explore every configuration the tree reaches from its start tick under every event its
   ``Switch`` nodes test (a configuration is the interpreter's memory with the blackboard and
   the root's last result, settled by ``DispatchMachine.settle``: a state and the one an
   ignored event silently leads it to are one configuration when no event tells them apart);
   a tick that changes nothing and outputs nothing is a silent self-loop;
2. merge configurations of one state index that no sequence of events tells apart (partition
   refinement of the configurations read as a Mealy machine: each event gives an output, the
   action of the ``DispatchEntry`` leaf the tick ran, and a next configuration; the first
   partition is by termination - whether the root returned SUCCESS - and state index, so
   distinct states of the source stay distinct even where they behave alike);
3. one FSM state per (block, action output on entering it), its action that output, final when
   the block is; an event that leads silently back into the same block is ignored (no
   transition), any other gives a transition. A state is named by the ``state`` port of the
   ``DispatchEntry`` that first enters it (``start`` for a start tick that runs none; ``~2``,
   ``~3`` ... when two states would share a name). When the start tick runs no leaf and one
   event only leaves it, never to come back, it is the FSM's start pseudo-state with that
   initial event (the form ``fsm_to_dispatch`` writes for such machines).

For a tree of the hierarchical form (docs/semantics.md §12a: a ``SubTree`` per composite
state), whose states are named by their configurations (``A/a1``),
``fsmbt.convert.dispatch_lift`` rebuilds the composite states when the hierarchical machine it
recovers flattens to exactly this machine; otherwise the flat machine is the result.

The result is the tree's behaviour itself, so the checker's macro-step pairing
(``fsmbt.verify.pairing``) proves it equivalent to the tree, and, for a tree fsmbt wrote, to the
source machine it was written from.

Bad input (located at the node): a tick that runs two ``DispatchEntry`` leaves with actions (a
state machine enters one state per step); a tree that reacts to an event after its root returned
SUCCESS (a final state ignores events); more configurations than
``fsmbt.limits.current().conversion_max_states``. A warning, located, names ``DispatchEntry``
leaves whose ``state`` ports disagree about the state one index holds, and leaves no tick runs.

Cost: O(C · (1 + e)) ticks for C reachable configurations (one per state of the machine for a
tree fsmbt wrote, at most one per transition plus one per state) and e events tested where a configuration's tick passes (the
others share one tick, ``DispatchMachine.active_inputs``), each O(log7 states + out-degree / 6)
node ticks, plus O(C · E) to record the moves of E events where that shared tick is not silent;
the refinement is O(moves) per round, one or two rounds for a tree fsmbt wrote.
"""

from __future__ import annotations

from collections import deque
from typing import Any

from fsmbt import limits
from fsmbt.convert.dispatch_lift import lift_hierarchy
from fsmbt.convert.perf import without_gc_pauses
from fsmbt.convert.result import ConversionResult
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import SourceLocation, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_runtime import OTHER_EVENT, DispatchMachine, DispatchState, Tick
from fsmbt.semantics.leaf_machine import StateLimitError
from fsmbt.semantics.status import NodeStatus

STYLE = "dispatch"
START = "start"

#: A move: (target configuration, the action output, the DispatchEntry leaves the tick ran).
_Move = tuple[int, str | None, tuple[int, ...]]


class _Explored:
    """The reachable configurations of a dispatch tree, numbered in breadth-first order
    (0: after the start tick), with their moves.

    Every event no ``{event}`` Switch of a configuration's tick reads does what
    ``OTHER_EVENT`` does (``DispatchMachine.active_inputs``), so that tick is taken once, as
    the configuration's **default move**, and only the events read are ticked one by one."""

    def __init__(self, machine: DispatchMachine, max_states: int) -> None:
        self.machine = machine
        self.states: list[DispatchState] = []
        self.index: dict[DispatchState, int] = {}
        self.final: list[bool] = []
        #: per configuration: event -> move, for the events its tick reads
        self.moves: list[dict[str, _Move]] = []
        #: per configuration: the move of every other event (``None``: a silent self-loop)
        self.default: list[_Move | None] = []
        #: per configuration: the events its tick reads, in alphabet order
        self.read: list[list[str]] = []
        order = {event: k for k, event in enumerate(machine.alphabet)}
        start, self.start_ran, _read = machine.tick(machine.before_start(), None)
        self.start_output = self._action(self.start_ran)
        queue: deque[int] = deque([self._add(machine.settle(start), max_states)])
        while queue:
            i = queue.popleft()
            state = self.states[i]
            other = machine.tick(state, OTHER_EVENT)
            self.default.append(self._move(i, other, "any other event", queue, max_states))
            read = sorted((e for e in other.read if e in order), key=order.__getitem__)
            moves: dict[str, _Move] = {}
            for event in read:
                move = self._move(i, machine.tick(state, event), event, queue, max_states)
                if move is not None:
                    moves[event] = move
            self.moves.append(moves)
            self.read.append(read)

    def _move(
        self, i: int, done: Tick, event: str, queue: deque[int], max_states: int
    ) -> _Move | None:
        """The move of a tick from configuration ``i`` (``None``: silent self-loop)."""
        output = self._action(done.entered)
        after = self.machine.settle(done.state)
        if after == self.states[i] and output is None:
            return None
        j = self.index.get(after)
        if j is None:
            j = self._add(after, max_states)
            queue.append(j)
        if self.final[i] and (output is not None or not self.final[j]):
            ran = done.entered
            raise UnsupportedError(
                f"the tree reacts to {event!r} after its root returned SUCCESS "
                "(a final state ignores every event)",
                **(self.located(ran[-1]) if ran else {"element": self.machine.name}),
            )
        return (j, output, done.entered)

    def arrivals(self) -> list[_Move]:
        """Every move (default moves included)."""
        found = [m for m in self.default if m is not None]
        for moves in self.moves:
            found.extend(moves.values())
        return found

    def _add(self, state: DispatchState, max_states: int) -> int:
        if len(self.states) >= max_states:
            raise StateLimitError(
                f"the dispatch tree has more than {max_states} reachable configurations "
                "(FSMBT_MAX_CONVERSION_STATES raises the limit)",
                element=self.machine.name,
            )
        i = len(self.states)
        self.states.append(state)
        self.index[state] = i
        self.final.append(state.last_result == NodeStatus.SUCCESS)
        return i

    def _action(self, ran: tuple[int, ...]) -> str | None:
        """The one action the leaves ``ran`` output (``None``: none)."""
        actions = [a for a in (self.machine.entries[n][1] for n in ran) if a is not None]
        if len(actions) > 1:
            raise UnsupportedError(
                f"one tick runs {len(ran)} DispatchEntry leaves with actions "
                f"({', '.join(repr(a) for a in actions)}); a state machine enters one state "
                "per step",
                **self.located(ran[-1]),
            )
        return actions[0] if actions else None

    def located(self, node_id: int) -> dict[str, Any]:
        """``location``/``element`` keyword arguments naming the leaf ``node_id``."""
        src = self.machine.tree.nodes[node_id].source
        return {"location": src.location, "element": f"<DispatchEntry> '{src.label}'"}


def _refine(explored: _Explored) -> list[int]:
    """Partition refinement of the configurations read as a Mealy machine (each event gives
    an output and a next configuration; an absent move is a silent self-loop), starting from
    the partition by termination and state index (the digits): the coarsest partition below
    that one in which configurations of one block give the same outputs and termination under
    every sequence of events. Blocks are numbered in order of their first configuration (the
    start's block is 0). A silent move into the own block counts as no move.

    Starting from the state index keeps a machine's distinct states apart even when they
    behave alike (the result is the source machine, not its minimum), and makes a tree fsmbt
    wrote stable after one or two rounds. Cost: O(moves) per round."""
    count = len(explored.states)
    digits_of = explored.machine.digits
    labels: dict[Any, int] = {}
    block = [
        labels.setdefault((explored.final[i], digits_of(explored.states[i])), len(labels))
        for i in range(count)
    ]
    blocks = len(labels)
    while True:
        labels = {}
        refined = [
            labels.setdefault(_signature(explored, block, i), len(labels)) for i in range(count)
        ]
        block = refined
        if len(labels) == blocks:
            return block
        blocks = len(labels)


def _signature(explored: _Explored, block: list[int], i: int) -> tuple[Any, ...]:
    """Configuration ``i``'s block and what every event does from it under ``block``, in a
    canonical form: ``(output, target block)`` of the default move (``(None, own block)``
    when it is silent or silently stays in the block) and of each event read whose move
    differs from that."""
    own = block[i]

    def seen(move: _Move | None) -> tuple[str | None, int]:
        if move is None:
            return (None, own)
        return (move[1], block[move[0]])

    default = seen(explored.default[i])
    moves = explored.moves[i]
    explicit = []
    for event in explored.read[i]:
        this = seen(moves.get(event))
        if this != default:
            explicit.append((event, this))
    return (own, default, tuple(explicit))


class _States:
    """The FSM's states: one per (block, action output on entering it), named by the
    ``state`` port of the leaf that first entered it; entered without a leaf, by the port of
    a leaf entering its block (else ``index_<digits>``), or ``start`` for the start tick;
    unique with ``~2``, ``~3`` ..."""

    def __init__(self, explored: _Explored, block: list[int]) -> None:
        self.explored = explored
        self.block = block
        self.keys: list[tuple[int, str | None]] = []
        self.index: dict[tuple[int, str | None], int] = {}
        self.names: list[str] = []
        self.ran: list[tuple[int, ...]] = []
        self._taken: dict[str, int] = {}
        entries = explored.machine.entries
        self._first: dict[int, int] = {}
        for i, b in enumerate(block):
            self._first.setdefault(b, i)
        self._block_names: dict[int, str] = {}
        arrivals = [(0, explored.start_ran), *((j, r) for j, _o, r in explored.arrivals())]
        for j, ran in arrivals:
            if ran and entries[ran[-1]][0]:
                self._block_names.setdefault(block[j], entries[ran[-1]][0])

    def get(
        self, block: int, output: str | None, ran: tuple[int, ...], *, start: bool = False
    ) -> int:
        key = (block, output)
        k = self.index.get(key)
        if k is not None:
            return k
        k = len(self.keys)
        self.keys.append(key)
        self.index[key] = k
        base = self.explored.machine.entries[ran[-1]][0] if ran else ""
        if not base:
            digits = self.explored.machine.digits(self.explored.states[self._first[block]])
            fallback = START if start else self._block_names.get(block, f"index_{digits}")
            base = fallback
        self._taken[base] = self._taken.get(base, 0) + 1
        self.names.append(base if self._taken[base] == 1 else f"{base}~{self._taken[base]}")
        self.ran.append(ran)
        return k


def _port_warnings(explored: _Explored) -> list[str]:
    """Leaves whose ``state`` ports name different states for one index, and leaves that no
    tick runs (both located)."""
    machine = explored.machine
    by_index: dict[str, dict[str, int]] = {}
    ran_any: set[int] = set(explored.start_ran)
    arrivals = [(explored.states[0], explored.start_ran)]
    arrivals.extend((explored.states[j], ran) for j, _out, ran in explored.arrivals())
    for state, ran in arrivals:
        ran_any.update(ran)
        if ran:
            port = machine.entries[ran[-1]][0]
            by_index.setdefault(machine.digits(state), {}).setdefault(port, ran[-1])
    warnings: list[str] = []
    for digits, named in by_index.items():
        if len(named) > 1:
            leaves = [
                f"'{name}' ({_at(explored.located(nid)['location'])})"
                for name, nid in named.items()
            ]
            warnings.append(
                f"DispatchEntry leaves naming different states enter the same state index "
                f"'{digits}': {', '.join(leaves)} (the index decides; their Scripts write the "
                "same digits)"
            )
    unused = [nid for nid in sorted(machine.entries) if nid not in ran_any]
    if unused:
        where = _at(explored.located(unused[0])["location"])
        warnings.append(
            f"{len(unused)} DispatchEntry leaf/leaves never run (unreachable), the first at {where}"
        )
    return warnings


def _at(location: SourceLocation | None) -> str:
    return str(location) if location is not None else "<tree>"


def _event_moves(explored: _Explored, block: list[int], i: int) -> list[tuple[str, _Move]]:
    """Configuration ``i``'s moves by event, in alphabet order: the events read, and every
    other event when the default move does more than stay silently in ``i``'s block."""
    moves, default = explored.moves[i], explored.default[i]
    if default is None or (default[1] is None and block[default[0]] == block[i]):
        return list(moves.items())
    read = set(explored.read[i])
    return [
        (event, moves[event] if event in read else default)
        for event in explored.machine.alphabet
        if event not in read or event in moves
    ]


@without_gc_pauses
def dispatch_to_fsm(
    doc: BTDocument, *, max_states: int | None = None, **_options: object
) -> ConversionResult:
    """The state machine of a dispatch tree's macro steps (see the module docstring).

    Raises:
        InputError: a leaf other than ``DispatchEntry`` (located); UnsupportedError: a tick
        entering two states, or a reaction after SUCCESS (located); StateLimitError: more
        configurations than the limit.
    """
    probe = DispatchMachine(doc, ())
    machine = DispatchMachine(doc, probe.events())
    explored = _Explored(machine, max_states or limits.current().conversion_max_states)
    block = _refine(explored)
    rep: dict[int, int] = {}
    for i, b in enumerate(block):
        rep.setdefault(b, i)
    states = _States(explored, block)
    start = states.get(0, explored.start_output, explored.start_ran, start=True)
    edges: list[tuple[int, str, int]] = []
    k = 0
    while k < len(states.keys):  # every (block, entry output) reached, breadth first
        b, _output = states.keys[k]
        i = rep[b]
        if not explored.final[i]:
            for event, (j, output, ran) in _event_moves(explored, block, i):
                if output is None and block[j] == b:
                    continue  # silent, and the same behaviour: the event is ignored
                edges.append((k, event, states.get(block[j], output, ran)))
        k += 1
    entered = {target for _k, _e, target in edges}
    out_of_start = [edge for edge in edges if edge[0] == start]
    pseudo_start = (
        explored.start_output is None
        and not explored.final[rep[0]]
        and start not in entered
        and len(out_of_start) == 1
    )
    fsm = FSM(name=machine.name)
    for k, (b, output) in enumerate(states.keys):
        if k == start and pseudo_start:
            continue
        ran = states.ran[k]
        fsm.add_state(states.names[k], action=output, final=explored.final[rep[b]])
        fsm.states[states.names[k]].location = (
            explored.located(ran[-1])["location"] if ran else None
        )
    if pseudo_start:
        ((_k, event, target),) = out_of_start
        fsm.initial, fsm.initial_event = states.names[target], event
    else:
        fsm.initial = states.names[start]
    for k, event, target in edges:
        if not (k == start and pseudo_start):
            fsm.add_transition(states.names[k], event, states.names[target])
    stats: dict[str, object] = {
        "style": STYLE,
        "states": len(fsm.states),
        "transitions": len(fsm.transitions),
        "configurations": len(explored.states),
        "final_states": sum(1 for s in fsm.states.values() if s.final),
    }
    warnings = _port_warnings(explored)
    lifted = lift_hierarchy(fsm) if len(doc.trees) > 1 and not warnings else None
    if lifted is not None:  # a hierarchical dispatch tree (docs/semantics.md §12a)
        stats["composites"] = sum(1 for _p, _m, s in lifted.walk() if s.is_composite)
        return ConversionResult(lifted, "rules", "bt->fsm", stats, warnings)
    return ConversionResult(fsm, "rules", "bt->fsm", stats, warnings)
