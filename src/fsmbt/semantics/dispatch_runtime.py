"""Macro steps of the dispatch form of an FSM (docs/semantics.md, "12. The dispatch form").

The dispatch form (``fsmbt.convert.dispatch``) keeps the FSM's current state as an index on the
blackboard, written in base 6 as the digit entries ``fsm_d0`` (least significant) ..
``fsm_d{L-1}`` with the letters ``a``..``f`` (BehaviorTree.CPP's ``Switch`` compares numbers
numerically, so digits are letters). Its control nodes are BehaviorTree.CPP built-ins
(``Switch2``..``Switch6``, ``Script``, ``ReactiveSequence``, ``KeepRunningUntilFailure``,
``AlwaysSuccess``, ``AlwaysFailure``), modelled exactly by ``fsmbt.semantics.outcome_blackboard``;
its only leaf is ``DispatchEntry`` (Action; ports ``state``, ``action``): it runs ``action``
(empty: none) and returns SUCCESS.

One macro step: the environment writes the event to the entry ``event`` and ticks the root once;
``event`` is then unset again (the tree never writes it). The start is one tick with ``event``
unset. The tree has terminated when the last tick returned SUCCESS (the current state is final).

Cost: a tick is O(log6(states) + events of the current state / 6) node ticks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import LeafRequest, Snapshot
from fsmbt.semantics.machine import FINAL, RUNNING, FSMMachine, Outputs
from fsmbt.semantics.outcome_blackboard import (
    BLACKBOARD_SLOT,
    OutcomeInterpreter,
    OutcomeTree,
    with_entry,
)
from fsmbt.semantics.status import NodeStatus

ENTRY = "DispatchEntry"
EVENT_KEY = "event"
DIGIT_PREFIX = "fsm_d"
DIGITS = "abcdef"
BASE = len(DIGITS)


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
        self.interp = OutcomeInterpreter(self.tree)
        self.name = name or doc.main.id
        self.alphabet = tuple(alphabet)
        self.entries: dict[int, tuple[str, str | None]] = {}
        self.event_cases: set[str] = set()
        for node in self.tree.nodes:
            src = node.source
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
            elif node.type == "bb.Switch" and node.params[0] == EVENT_KEY:
                self.event_cases.update(node.params[1])

    def events(self) -> list[str]:
        """Every event a Switch of the tree tests, sorted (the checker offers them all)."""
        return sorted(self.event_cases)

    # -- Machine protocol --------------------------------------------------------------------
    def start(self) -> tuple[DispatchState, Outputs]:
        return self._tick(DispatchState(self.interp.initial(), None), None)

    def inputs(self, state: DispatchState) -> Sequence[str]:
        return self.alphabet

    def step(self, state: DispatchState, symbol: str) -> tuple[DispatchState, Outputs]:
        return self._tick(state, symbol)

    def status(self, state: DispatchState) -> str:
        return FINAL if state.last_result == NodeStatus.SUCCESS else RUNNING

    def describe(self, state: DispatchState) -> str:
        entries = dict(dict(state.snapshot[1]).get(BLACKBOARD_SLOT, ()))
        digits = [v for k, v in sorted(entries.items()) if k.startswith(DIGIT_PREFIX)]
        return "".join(digits) or "start"

    # -- one tick ------------------------------------------------------------------------------
    def _tick(self, state: DispatchState, event: str | None) -> tuple[DispatchState, Outputs]:
        snap = state.snapshot
        if event is not None:
            snap = with_entry(snap, EVENT_KEY, event)
        actions: list[str] = []
        snap = self.interp.begin_tick(snap)
        snap, request = self.interp.advance(snap)
        while isinstance(request, LeafRequest):
            _state, action = self.entries[request.node.id]
            if action is not None:
                actions.append(action)
            snap, request = self.interp.advance(snap, NodeStatus.SUCCESS.value)
        snap = without_entry(snap, EVENT_KEY)
        return DispatchState(snap, NodeStatus(request.status)), tuple(actions)


def machines_for_dispatch(source: FSM, result: BTDocument) -> tuple[FSMMachine, DispatchMachine]:
    """The checker's pair for (FSM, dispatch BT): both over the union of their events."""
    base = FSMMachine(source)
    probe = DispatchMachine(result, ())
    alphabet = list(dict.fromkeys([*base.alphabet, *probe.events()]))
    return FSMMachine(source, alphabet=alphabet), DispatchMachine(result, alphabet)
