"""Macro steps of the dispatch form of an FSM (docs/semantics.md, "12. The dispatch form").

The dispatch form (``fsmbt.convert.dispatch``) keeps the FSM's current state as an index on the
blackboard, written in base 7 as the digit entries ``fsm_d0`` (least significant) ..
``fsm_d{L-1}`` with the letters ``a``..``g`` (BehaviorTree.CPP's ``Switch`` compares numbers
numerically, so digits are letters; a ``Switch6``'s default child is the seventh digit). Its
control nodes are BehaviorTree.CPP built-ins
(``Switch2``..``Switch6``, ``Script``, ``Sequence``, ``KeepRunningUntilFailure``,
``AlwaysSuccess``, ``AlwaysFailure``), modelled exactly by ``fsmbt.semantics.outcome_blackboard``;
its only leaf is ``DispatchEntry`` (Action; ports ``state``, ``action``): it runs ``action``
(empty: none) and returns SUCCESS, after which BehaviorTree.CPP runs its ``_onSuccess``
post-condition: ``KEY:='literal'`` assignments (the target's index digits), applied here to the
blackboard before the parent sees the SUCCESS. No other node may carry a post-condition, and no
other script form is accepted there (``InputError``/``UnsupportedError`` naming the node).

One macro step: the environment writes the event to the entry ``event`` and ticks the root once;
``event`` is then unset again (the tree never writes it). The start is one tick with ``event``
unset. The tree has terminated when the last tick returned SUCCESS (the current state is final).

Cost: a tick is O(log7(states) + events of the current state / 6) node ticks.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import (
    CompiledNode,
    Frame,
    HaltHook,
    LeafRequest,
    Snapshot,
    TickAction,
)
from fsmbt.semantics.machine import FINAL, RUNNING, FSMMachine, Outputs
from fsmbt.semantics.outcome_blackboard import (
    BLACKBOARD_SLOT,
    SWITCH,
    OutcomeInterpreter,
    OutcomeTree,
    script_assignments,
    with_entry,
)
from fsmbt.semantics.status import NodeStatus

ENTRY = "DispatchEntry"
EVENT_KEY = "event"
DIGIT_PREFIX = "fsm_d"
DIGITS = "abcdefg"
BASE = len(DIGITS)
#: The digit-entry key grammar of both dispatch forms (docs/semantics.md §12, §12a): a level's
#: prefix - ``fsm_d`` for the top machine, ``fsm_d_<level>_`` for a composite state's
#: sub-machine (``<level>`` its path, letters, digits and ``_``) - then the digit number ``J``
#: (0 = least significant, at most 4 decimal digits). ``J`` is what follows the last ``_``, so
#: a key names one (prefix, J) pair.
_DIGIT_KEY = re.compile(re.escape(DIGIT_PREFIX) + r"((?:_[A-Za-z0-9_]+_)?)([0-9]{1,4})")


def level_prefix(level: str) -> str:
    """The digit-entry prefix of the composite level ``level`` (``[A-Za-z0-9_]+``):
    ``fsm_d_<level>_``; its digits are ``fsm_d_<level>_0``, ``fsm_d_<level>_1``, ..."""
    return f"{DIGIT_PREFIX}_{level}_"


def digit_key(key: str) -> tuple[str, int] | None:
    """``(level prefix, J)`` of a digit entry ``fsm_dJ`` (prefix ``fsm_d``) or
    ``fsm_d_<level>_J`` (prefix ``fsm_d_<level>_``), else ``None``."""
    match = _DIGIT_KEY.fullmatch(key)
    if match is None:
        return None
    return DIGIT_PREFIX + match.group(1), int(match.group(2))


#: The most cases a BehaviorTree.CPP ``Switch`` has (``Switch6``); its default is one more.
MAX_CASES = 6
#: An event value no ``Switch`` case can equal (XML cannot hold NUL): the "any other event" of
#: ``DispatchMachine.active_inputs``.
OTHER_EVENT = "\x00"
#: The post-condition a ``DispatchEntry`` may carry (BehaviorTree.CPP runs it after SUCCESS).
ON_SUCCESS = "_onSuccess"
#: BehaviorTree.CPP 4's post-condition attributes (refused anywhere else in a dispatch tree).
POST_CONDITIONS = ("_onSuccess", "_onFailure", "_onHalted", "_post")


def is_dispatch_bt(doc: BTDocument) -> bool:
    """True when the document's leaves are the dispatch form's ``DispatchEntry`` leaves."""
    return any(node.type == ENTRY for _tree, node in doc.nodes())


def without_entry(snap: Snapshot, key: str) -> Snapshot:
    """``snap`` with blackboard entry ``key`` unset."""
    mem = dict(snap[1])
    entries = dict(mem.get(BLACKBOARD_SLOT, ()))
    if key not in entries:
        return snap
    del entries[key]
    mem[BLACKBOARD_SLOT] = tuple(sorted(entries.items()))
    return (snap[0], tuple(sorted(mem.items())), snap[2], snap[3])


class _EventReadingInterpreter(OutcomeInterpreter):
    """``OutcomeInterpreter`` that notes the cases of every ``Switch`` on ``{event}`` it
    ticks (in ``read``; the caller clears it)."""

    def __init__(self, tree: OutcomeTree) -> None:
        super().__init__(tree)
        self.read: set[str] = set()
        self._tick = {**self._tick, SWITCH: self._t_reading_switch}

    def _t_reading_switch(
        self, w: Any, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        if frame[1] == 0 and node.params[0] == EVENT_KEY:
            self.read.update(node.params[1])
        return self._t_bb_switch(w, node, frame, result, hook)


class Tick(NamedTuple):
    """One tick: the state after it, the ``DispatchEntry`` leaves it ran (node ids in
    ``DispatchMachine.tree``, in order), and the cases of the ``{event}`` switches it read."""

    state: DispatchState
    entered: tuple[int, ...]
    read: frozenset[str]


@dataclass(frozen=True)
class DispatchState:
    """Between two macro steps: interpreter memory (with the blackboard), last root result."""

    snapshot: Snapshot
    last_result: NodeStatus | None


class DispatchMachine:
    """``Machine`` of a dispatch tree's macro steps: inputs are events, outputs actions."""

    def __init__(
        self, doc: BTDocument, alphabet: Sequence[str], *, name: str | None = None
    ) -> None:
        self.tree = OutcomeTree(doc)
        self.interp = _EventReadingInterpreter(self.tree)
        self.name = name or doc.main.id
        self.alphabet = tuple(alphabet)
        self.entries: dict[int, tuple[str, str | None]] = {}
        self.event_cases: set[str] = set()
        self._settled: dict[DispatchState, DispatchState] = {}
        self._names: dict[str, str] = {}  # index digits -> state port (describe)
        self._ticks: dict[tuple[DispatchState, str], Tick] = {}  # settle's, used once
        self._alphabet_set = frozenset(self.alphabet)
        self._order = {event: k for k, event in enumerate(self.alphabet)}
        #: node id -> the blackboard writes of its ``_onSuccess`` (DispatchEntry leaves)
        self.on_success: dict[int, tuple[tuple[str, str], ...]] = {}
        for node in self.tree.nodes:
            src = node.source
            posts = [a for a in POST_CONDITIONS if a in src.attrs]
            if posts and (posts != [ON_SUCCESS] or not node.is_env_leaf):
                raise UnsupportedError(
                    f"post-condition '{posts[0]}': in a dispatch tree only a {ENTRY} leaf may "
                    f"carry one, {ON_SUCCESS} with KEY:='literal' assignments",
                    location=src.location,
                    element=f"<{node.type}> '{node.label}'",
                )
            if posts:
                pairs = script_assignments(src.attrs[ON_SUCCESS])
                if pairs is None:
                    raise UnsupportedError(
                        f"{ON_SUCCESS} {src.attrs[ON_SUCCESS]!r}: only KEY:='literal' "
                        "assignments joined by ';' are modelled",
                        location=src.location,
                        element=f"<{node.type}> '{node.label}'",
                    )
                self.on_success[node.id] = pairs
            if node.is_env_leaf:
                if node.type != ENTRY or node.kind is not NodeKind.ACTION:
                    raise InputError(
                        f"a dispatch tree only has {ENTRY} action leaves",
                        location=src.location,
                        element=f"<{node.type}> '{node.label}'",
                    )
                self.entries[node.id] = (
                    src.attrs.get("state", ""),
                    src.attrs.get("action") or None,
                )
            elif node.type == SWITCH and node.params[0] == EVENT_KEY:
                self.event_cases.update(node.params[1])

    def events(self) -> list[str]:
        """Every event a Switch of the tree tests, sorted (the checker offers them all)."""
        return sorted(self.event_cases)

    # -- Machine protocol --------------------------------------------------------------------
    def start(self) -> tuple[DispatchState, Outputs]:
        done = self.tick(self.before_start(), None)
        return self.settle(done.state), self._outputs(done.entered)

    def before_start(self) -> DispatchState:
        """The state before the start tick (nothing written, no tick yet)."""
        return DispatchState(self.interp.initial(), None)

    def inputs(self, state: DispatchState) -> Sequence[str]:
        return self.alphabet

    def active_inputs(self, state: DispatchState) -> Sequence[str]:
        """The events that may do anything in ``state``; every other one is a silent
        self-loop (the checker skips those).

        Why it is sound: an event's value is read only by the ``Switch`` nodes on ``{event}``
        (``Script`` and ``_onSuccess`` write literals, ``DispatchEntry`` reads no entry, and
        ``event`` is unset
        after the tick). One tick with ``OTHER_EVENT`` takes the default at every such switch
        it reaches; any event that is no case of those switches takes the same defaults, so
        the same path, the same state and the same outputs. When that tick is silent (state
        unchanged, no leaf run) only the cases read are active; otherwise every event is.
        Cost: one tick plus O(r log r) for the r cases read.
        """
        other = self._tick_once(state, OTHER_EVENT)
        if other.state == state and not self._outputs(other.entered):
            read = [e for e in other.read if e in self._order]
            return sorted(read, key=self._order.__getitem__)
        return self.alphabet

    def step(self, state: DispatchState, symbol: str) -> tuple[DispatchState, Outputs]:
        done = self._tick_once(state, symbol)
        return self.settle(done.state), self._outputs(done.entered)

    def settle(self, state: DispatchState) -> DispatchState:
        """``state``, or the state an ignored event leads it to when the two cannot be told
        apart (docs/semantics.md section 12, "Settled states"): the macro-step machine's
        states are then one per FSM state, not one per transition into it.

        After a transition the tree remembers the transition's running path; the next event
        the state ignores halts it, silently. ``idle`` = the state after one tick with
        ``OTHER_EVENT`` replaces ``state`` when: that tick outputs nothing and keeps the
        status; a second such tick from ``idle`` changes nothing and outputs nothing; and
        every event a ``Switch`` on ``{event}`` read in either tick gives the same state and
        the same leaves from both. Then {(state, idle)} plus equality is a bisimulation: the
        events read lead to the same states with the same outputs, every other event takes
        both silently to ``idle`` (``active_inputs``), and the statuses agree. So the
        replacement is exact for any tree (nothing is assumed about its shape). Cost: two
        ticks plus two per event read, once per state (memoised); the ticks taken from the
        state returned serve its ``active_inputs`` and ``step`` once.
        """
        hit = self._settled.get(state)
        if hit is not None:
            return hit
        settled = state
        first = self.tick(state, OTHER_EVENT)
        mine: dict[str, Tick] = {OTHER_EVENT: first}  # ticks from ``state``
        idle = first.state
        if (
            idle != state
            and not self._outputs(first.entered)
            and idle.last_result == state.last_result
        ):
            again = self.tick(idle, OTHER_EVENT)
            theirs: dict[str, Tick] = {OTHER_EVENT: again}  # ticks from ``idle``
            if again.state == idle and not self._outputs(again.entered):
                agree = True
                for e in sorted((first.read | again.read) & self._alphabet_set):
                    mine[e], theirs[e] = self.tick(state, e), self.tick(idle, e)
                    if mine[e][:2] != theirs[e][:2]:
                        agree = False
                        break
                if agree:
                    settled, mine = idle, theirs
        # the checker asks next for the settled state's active inputs and steps: keep the
        # ticks already taken from it (each used once, then dropped: memory stays that of the
        # states not yet explored)
        for e, done in mine.items():
            self._ticks[(settled, e)] = done
        self._settled[state] = settled
        return settled

    def _tick_once(self, state: DispatchState, event: str) -> Tick:
        """``tick(state, event)``, taken from ``settle``'s ticks when it took it already."""
        done = self._ticks.pop((state, event), None)
        return done if done is not None else self.tick(state, event)

    def status(self, state: DispatchState) -> str:
        return FINAL if state.last_result == NodeStatus.SUCCESS else RUNNING

    def describe(self, state: DispatchState) -> str:
        """The state's name for traces: the ``state`` port of the ``DispatchEntry`` whose tick
        wrote its index (the first seen), else the index digits (``start`` before any)."""
        digits = self.digits(state)
        return self._names.get(digits, digits)

    def digits(self, state: DispatchState) -> str:
        """The state index as its digits, most significant first (``start``: none written)."""
        entries = dict(dict(state.snapshot[1]).get(BLACKBOARD_SLOT, ()))
        digits = [v for k, v in sorted(entries.items()) if k.startswith(DIGIT_PREFIX)]
        return "".join(reversed(digits)) or "start"

    # -- one tick ------------------------------------------------------------------------------
    def _outputs(self, entered: tuple[int, ...]) -> Outputs:
        actions = (self.entries[nid][1] for nid in entered)
        return tuple(action for action in actions if action is not None)

    def tick(self, state: DispatchState, event: str | None) -> Tick:
        """One tick with ``event`` pending (``None``: the start tick), as a ``Tick``.

        ``start()``/``step()`` output the entered leaves' non-empty ``action`` ports; BT -> FSM
        (``fsmbt.convert.dispatch_fsm``) also reads their ``state`` ports and locations.
        """
        self.interp.read.clear()
        snap = state.snapshot
        if event is not None:
            snap = with_entry(snap, EVENT_KEY, event)
        entered: list[int] = []
        snap = self.interp.begin_tick(snap)
        snap, request = self.interp.advance(snap)
        while isinstance(request, LeafRequest):
            entered.append(request.node.id)
            for key, value in self.on_success.get(request.node.id, ()):
                snap = with_entry(snap, key, value)
            snap, request = self.interp.advance(snap, NodeStatus.SUCCESS.value)
        snap = without_entry(snap, EVENT_KEY)
        after = DispatchState(snap, NodeStatus(request.status))
        if entered and self.entries[entered[-1]][0]:
            self._names.setdefault(self.digits(after), self.entries[entered[-1]][0])
        return Tick(after, tuple(entered), frozenset(self.interp.read))


def machines_for_dispatch(source: FSM, result: BTDocument) -> tuple[FSMMachine, DispatchMachine]:
    """The checker's pair for (FSM, dispatch BT): both over the union of their events."""
    base = FSMMachine(source)
    probe = DispatchMachine(result, ())
    alphabet = list(dict.fromkeys([*base.alphabet, *probe.events()]))
    return FSMMachine(source, alphabet=alphabet), DispatchMachine(result, alphabet)
