"""Executable leaves of the classical state-variable baselines (BSD, CHDS) and their macro steps.

The baselines (``fsmbt.convert.baselines``) encode an FSM's current state in a blackboard
variable instead of in the tree's running node (the LEBT's way). Their leaves, written with
these types and ports, act on a blackboard with ``state`` (the FSM state), ``event`` (the
pending event, ``""`` = none) and ``entered`` (the current state's entry action has run):

- ``SvIsState`` (Condition; ports ``state``, ``initial``): SUCCESS iff ``bb.state == state``.
- ``SvEntryAction`` (Action; ``state``, ``action``): when ``entered`` is false, run ``action``
  (empty = none) and set ``entered``; SUCCESS. (BSD's "state action".)
- ``SvTransition`` (Action; ``state``, ``transitions`` = ``event/target`` items joined by ``;``,
  ``final``): a final state: SUCCESS. Else, when ``bb.state == state`` and the pending event has
  a transition: ``state = target``, ``entered = false``, event cleared, SUCCESS; otherwise
  RUNNING (the state stays active). (BSD's transition leaf.)
- ``SvGuard`` (Condition; ``state``, ``event``, ``initial``): SUCCESS iff
  ``(bb.state, bb.event) == (state, event)``. (CHDS's switching guard.)
- ``SvAssign`` (Action; ``target``): ``state = target``, ``entered = false``, event cleared;
  SUCCESS. (CHDS's reset map.)
- ``SvMode`` (Action; ``state``, ``action``, ``final``): when ``entered`` is false, run
  ``action`` and set ``entered``; RUNNING (the mode's controller keeps running), SUCCESS in a
  final state. (CHDS's mode controller.)

Start: ``state`` is the ``state`` port of the one leaf marked ``initial="true"`` (the initial
state, or the start pseudo-state when the FSM has an initial event); ``entered`` is false; the
root is ticked until quiescent (below), which runs the initial state's action.

One macro step (the analogue of the LEBT macro step, docs/semantics.md §5, for a state
variable): set ``event``; tick the root;
while that tick fired a transition (a leaf wrote ``state``, self-loops included, so the new
state's subtree must run; its entry action sets ``entered`` on that next tick), tick again, at most ``MAX_TICKS_PER_STEP`` times in all (more is a livelock, reported
as an ``InputError``); then drop the event if it is still pending (no transition took it: the
FSM ignores it). The tree has terminated when the last tick returned SUCCESS and ``state`` is
not the start pseudo-state (``status`` = ``"final"``).

Complexity: a tick is O(nodes ticked); a macro step at most ``MAX_TICKS_PER_STEP`` ticks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledTree, LeafRequest, Snapshot
from fsmbt.semantics.lebt.spec import NO_EVENT, decode_pairs, encode_pairs
from fsmbt.semantics.machine import FINAL, RUNNING, FSMMachine, Outputs
from fsmbt.semantics.status import LeafOutcome, NodeStatus

IS_STATE, ENTRY_ACTION, TRANSITION = "SvIsState", "SvEntryAction", "SvTransition"
GUARD, ASSIGN, MODE = "SvGuard", "SvAssign", "SvMode"
CONDITION_TYPES = frozenset({IS_STATE, GUARD})
ACTION_TYPES = frozenset({ENTRY_ACTION, TRANSITION, ASSIGN, MODE})
SV_TYPES = CONDITION_TYPES | ACTION_TYPES
MAX_TICKS_PER_STEP = 8


def encode_transitions(pairs: Sequence[tuple[str, str]]) -> str:
    """``event/target`` items joined by ``;`` (names escaped as in ``fsmbt.semantics.lebt.spec``)."""
    return encode_pairs(pairs)


def decode_transitions(text: str) -> dict[str, str]:
    """The inverse of ``encode_transitions`` as ``{event: target}`` (the first item wins)."""
    table: dict[str, str] = {}
    for event, target in decode_pairs(text):
        table.setdefault(event, target)
    return table


@dataclass(frozen=True)
class SvLeaf:
    """One parsed leaf: its type and the ports its behaviour reads."""

    type: str
    state: str = ""
    action: str | None = None
    final: bool = False
    event: str = ""
    target: str = ""
    transitions: tuple[tuple[str, str], ...] = ()
    initial: bool = False


@dataclass
class SvBlackboard:
    state: str
    event: str = NO_EVENT
    entered: bool = False
    switched: bool = False  # a transition fired during the current tick


def is_state_variable_bt(doc: BTDocument) -> bool:
    """True when the document's leaves are the baselines' state-variable leaves."""
    return any(node.type in SV_TYPES for _tree, node in doc.nodes())


def _parse_leaf(node) -> SvLeaf:  # type: ignore[no-untyped-def]
    attrs = node.source.attrs
    where = {"location": node.source.location, "element": f"<{node.type}> '{node.label}'"}
    expected = NodeKind.CONDITION if node.type in CONDITION_TYPES else NodeKind.ACTION
    if node.type not in SV_TYPES:
        raise InputError(
            f"a state-variable BT only has Sv* leaves ({', '.join(sorted(SV_TYPES))})", **where
        )
    if node.kind is not expected:
        raise InputError(
            f"{node.type} must be a{'n' if expected is NodeKind.ACTION else ''} {expected.value}",
            **where,
        )
    try:
        transitions = tuple(decode_transitions(attrs.get("transitions", "")).items())
    except ValueError as exc:
        raise InputError(str(exc), **where) from None
    return SvLeaf(
        type=node.type,
        state=attrs.get("state", ""),
        action=attrs.get("action") or None,
        final=attrs.get("final", "false").lower() == "true",
        event=attrs.get("event", ""),
        target=attrs.get("target", ""),
        transitions=transitions,
        initial=attrs.get("initial", "false").lower() == "true",
    )


def leaf_outcome(leaf: SvLeaf, bb: SvBlackboard, actions: list[str]) -> LeafOutcome:
    """What one leaf returns (and does to the blackboard); see the module docstring."""
    kind = leaf.type
    if kind == IS_STATE:
        return LeafOutcome.SUCCESS if bb.state == leaf.state else LeafOutcome.FAILURE
    if kind == GUARD:
        matches = bb.event != NO_EVENT and (bb.state, bb.event) == (leaf.state, leaf.event)
        return LeafOutcome.SUCCESS if matches else LeafOutcome.FAILURE
    if kind in (ENTRY_ACTION, MODE):
        if not bb.entered:
            if leaf.action is not None:
                actions.append(leaf.action)
            bb.entered = True
        if kind == ENTRY_ACTION or leaf.final:
            return LeafOutcome.SUCCESS
        return LeafOutcome.RUNNING
    if kind == ASSIGN:
        _switch(bb, leaf.target)
        return LeafOutcome.SUCCESS
    # TRANSITION
    if leaf.final:
        return LeafOutcome.SUCCESS
    if bb.event != NO_EVENT and bb.state == leaf.state:
        target = dict(leaf.transitions).get(bb.event)
        if target is not None:
            _switch(bb, target)
            return LeafOutcome.SUCCESS
    return LeafOutcome.RUNNING


def _switch(bb: SvBlackboard, target: str) -> None:
    bb.state = target
    bb.entered = False
    bb.switched = True
    bb.event = NO_EVENT


@dataclass(frozen=True)
class SvState:
    """Between two macro steps: interpreter memory, the blackboard, the last root result."""

    snapshot: Snapshot
    bb_state: str
    entered: bool
    last_result: NodeStatus | None


class StateVariableMachine:
    """``Machine`` of a state-variable BT's macro steps: inputs are events, outputs actions."""

    def __init__(
        self, doc: BTDocument, alphabet: Sequence[str], *, name: str | None = None
    ) -> None:
        self.interp = BTInterpreter(doc)
        self.tree: CompiledTree = self.interp.tree
        self.name = name or self.tree.doc.main.id
        self.alphabet = tuple(alphabet)
        self._alphabet_set = frozenset(self.alphabet)
        self.leaves: dict[int, SvLeaf] = {}
        for node in self.tree.nodes:
            if node.is_env_leaf:
                self.leaves[node.id] = _parse_leaf(node)
            elif node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
                raise InputError(
                    "a state-variable BT only has Sv* leaves",
                    location=node.source.location,
                    element=f"<{node.type}> '{node.label}'",
                )
        initial = [leaf for leaf in self.leaves.values() if leaf.initial]
        if len({leaf.state for leaf in initial}) != 1:
            raise InputError(
                "a state-variable BT needs exactly one initial state (a leaf with "
                f'initial="true"), found {len(initial)}',
                element=self.name,
            )
        self.initial_state = initial[0].state
        # the start pseudo-state: initial, but without a mode/entry-action leaf of its own
        entered_by = {
            leaf.state for leaf in self.leaves.values() if leaf.type in (ENTRY_ACTION, MODE)
        }
        self.pseudo_start = self.initial_state not in entered_by
        self._events_from: dict[str, set[str]] = {}
        for leaf in self.leaves.values():
            if leaf.type == GUARD and leaf.event:
                self._events_from.setdefault(leaf.state, set()).add(leaf.event)
            elif leaf.type == TRANSITION:
                self._events_from.setdefault(leaf.state, set()).update(
                    e for e, _t in leaf.transitions
                )

    def events(self) -> list[str]:
        """Every event the leaves name, sorted (so the checker can offer them all)."""
        return sorted({e for events in self._events_from.values() for e in events})

    # -- Machine protocol --------------------------------------------------------------------
    def start(self) -> tuple[SvState, Outputs]:
        state = SvState(self.interp.initial(), self.initial_state, False, None)
        return self._settle(state, NO_EVENT)

    def inputs(self, state: SvState) -> Sequence[str]:
        return self.alphabet

    def active_inputs(self, state: SvState) -> Sequence[str]:
        """Events some leaf tests against the current ``state``; every other event reads as
        "no event" (a guard or transition leaf compares the event only together with
        ``bb.state``, which cannot change while an event is pending), so one of them is
        stepped: if it is a silent self-loop, none of them matters."""
        relevant = self._events_from.get(state.bb_state, set())
        active = [e for e in self.alphabet if e in relevant]
        other = next((e for e in self.alphabet if e not in relevant), None)
        if other is None:
            return active
        nxt, outputs = self.step(state, other)
        if nxt == state and not outputs:
            return active
        return self.alphabet

    def step(self, state: SvState, symbol: str) -> tuple[SvState, Outputs]:
        return self._settle(state, symbol)

    def status(self, state: SvState) -> str:
        done = state.last_result == NodeStatus.SUCCESS
        if self.pseudo_start and state.bb_state == self.initial_state:
            done = False
        return FINAL if done else RUNNING

    def describe(self, state: SvState) -> str:
        return state.bb_state

    # -- the macro step ------------------------------------------------------------------------
    def _settle(self, state: SvState, event: str) -> tuple[SvState, Outputs]:
        bb = SvBlackboard(state.bb_state, event, state.entered)
        snap = state.snapshot
        actions: list[str] = []
        result = state.last_result
        for _ in range(MAX_TICKS_PER_STEP):
            bb.switched = False
            snap, result = self._tick(snap, bb, actions)
            if not bb.switched:
                break
        else:
            raise InputError(
                f"the tree does not settle within {MAX_TICKS_PER_STEP} ticks (livelock)",
                element=self.name,
            )
        return SvState(snap, bb.state, bb.entered, result), tuple(actions)

    def _tick(
        self, snap: Snapshot, bb: SvBlackboard, actions: list[str]
    ) -> tuple[Snapshot, NodeStatus]:
        snap = self.interp.begin_tick(snap)
        snap, request = self.interp.advance(snap)
        while isinstance(request, LeafRequest):
            outcome = leaf_outcome(self.leaves[request.node.id], bb, actions)
            snap, request = self.interp.advance(snap, outcome.status)
        return snap, NodeStatus(request.status)


def machines_for_state_variable(
    source: FSM, result: BTDocument
) -> tuple[FSMMachine, StateVariableMachine]:
    """The checker's pair for (FSM, state-variable BT): both over the union of their events."""
    base = FSMMachine(source)
    probe = StateVariableMachine(result, ())
    alphabet = list(dict.fromkeys([*base.alphabet, *probe.events()]))
    return FSMMachine(source, alphabet=alphabet), StateVariableMachine(result, alphabet)
