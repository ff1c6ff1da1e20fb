"""The behaviour of the two LEBT leaves, and the parsed leaves of a compiled tree.

Rules (docs/semantics.md §5, "The LEBT protocol"), against a blackboard with ``state`` and
``event`` (``""`` = no event pending):

- guard (``LebtGuard``, a condition): FAILURE when (``state``, ``event``) is one of its pairs —
  the transition fires and the Fallback runs the body — else SUCCESS.
- state leaf (``LebtState``, a stateful action) for state ``s``:
  ``onStart``: run ``s``'s action, set ``state = s``, clear ``event``; RUNNING (SUCCESS if ``s``
  is final). ``onRunning``: if an event is pending and ``s`` has a transition on it, SUCCESS
  without clearing it; if one is pending without a transition, clear it and stay RUNNING;
  with none pending, RUNNING.

Every runtime (the interpreter's, the fast strict-grammar one, BehaviorTree.CPP's, py_trees')
calls these same three functions; they differ only in the control flow around them, which is
what the differential tests compare.

Costs: a guard's tick is O(p) for its p pairs, a state leaf's O(x) for its x exits (both
tuples tested with ``in``); ``LebtLeaves.of`` is O(N + P) for N nodes and P guard pairs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.lebt.spec import (
    DEFAULT_START,
    GUARD_TYPE,
    NO_EVENT,
    STATE_TYPE,
    GuardSpec,
    StateSpec,
)
from fsmbt.semantics.status import LeafOutcome

_SUCCESS = LeafOutcome.SUCCESS
_FAILURE = LeafOutcome.FAILURE
_RUNNING = LeafOutcome.RUNNING


class LebtBlackboard(Protocol):
    """What the leaves read and write; ``PlainBlackboard`` here, the engine's blackboard in the
    engine adapters."""

    state: str
    event: str


@dataclass
class PlainBlackboard:
    """A blackboard held in Python: the interpreted, fast and py_trees runtimes use it."""

    state: str
    event: str = NO_EVENT


def guard_outcome(spec: GuardSpec, bb: LebtBlackboard) -> LeafOutcome:
    """A guard's tick: FAILURE when its transition fires (the paper's "event negated").

    Args:
        spec: the guard's parsed ports.
        bb: the blackboard (read only).

    Returns:
        ``LeafOutcome.FAILURE`` when (``bb.state``, ``bb.event``) is one of the guard's pairs,
        else ``LeafOutcome.SUCCESS``.
    """
    return _FAILURE if spec.matches(bb.state, bb.event) else _SUCCESS


def state_on_start(spec: StateSpec, bb: LebtBlackboard, actions: list[str]) -> LeafOutcome:
    """A state leaf's first tick: enter the state (its action runs once, here).

    Args:
        spec: the state leaf's parsed ports.
        bb: the blackboard; ``state`` is set, ``event`` cleared.
        actions: the macro step's outputs; the state's action is appended.

    Returns:
        ``SUCCESS`` for a final state, else ``RUNNING``.
    """
    if spec.action is not None:
        actions.append(spec.action)
    bb.state = spec.state
    bb.event = NO_EVENT
    return _SUCCESS if spec.final else _RUNNING


def state_on_running(spec: StateSpec, bb: LebtBlackboard) -> LeafOutcome:
    """A state leaf's later ticks: leave on an event with a transition, drop one without.

    Args:
        spec: the state leaf's parsed ports.
        bb: the blackboard; ``event`` is cleared when the state has no transition on it.

    Returns:
        ``SUCCESS`` when the pending event is one of the state's exits, else ``RUNNING``.
    """
    if bb.event != NO_EVENT:
        if bb.event in spec.exits:
            return _SUCCESS
        bb.event = NO_EVENT
    return _RUNNING


@dataclass(frozen=True)
class LebtLeaves:
    """The parsed LEBT leaves of a compiled tree, by compiled node id, and the start name."""

    guards: dict[int, GuardSpec]
    states: dict[int, StateSpec]
    start: str
    init_on_start: bool  # an entry guard holds the pair (start, "")

    @classmethod
    def of(cls, tree: CompiledTree, start: str | None = None) -> LebtLeaves:
        """Parse every environment leaf of ``tree``.

        Args:
            tree: the compiled tree.
            start: the start pseudo-state; ``None`` infers it (the one guard source that is no
                state, else ``DEFAULT_START``).

        Returns:
            The leaves by compiled id.

        Raises:
            InputError: a leaf that is no LEBT leaf, of the wrong kind, or with malformed pairs
                (located at the leaf).
        """
        guards: dict[int, GuardSpec] = {}
        states: dict[int, StateSpec] = {}
        for node in tree.nodes:
            if not node.is_env_leaf:
                continue
            location, element = node.source.location, f"<{node.type}> '{node.label}'"
            if node.type == GUARD_TYPE:
                if node.kind is not NodeKind.CONDITION:
                    raise InputError(
                        "an LEBT guard must be a Condition", location=location, element=element
                    )
                try:
                    guards[node.id] = GuardSpec.from_attrs(node.source.attrs)
                except ValueError as exc:
                    raise InputError(str(exc), location=location, element=element) from None
            elif node.type == STATE_TYPE:
                if node.kind is not NodeKind.ACTION:
                    raise InputError(
                        "an LEBT state leaf must be an Action", location=location, element=element
                    )
                states[node.id] = StateSpec.from_attrs(node.source.attrs)
            else:
                raise InputError(
                    f"a loop-execution BT only has {GUARD_TYPE} and {STATE_TYPE} leaves",
                    location=location,
                    element=element,
                )
        if start is None:
            start = cls._infer_start(guards, states)
        init = any((start, NO_EVENT) in g.pairs for g in guards.values())
        return cls(guards, states, start, init)

    @staticmethod
    def _infer_start(guards: dict[int, GuardSpec], states: dict[int, StateSpec]) -> str:
        """The start pseudo-state: the one guard source that is no state, else the default."""
        names = {s.state for s in states.values()}
        sources = {src for g in guards.values() for src, _ in g.pairs if src not in names}
        return sources.pop() if len(sources) == 1 else DEFAULT_START
