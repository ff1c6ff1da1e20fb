"""The finite state machine model, flat or hierarchical (docs/semantics.md, 'Models').

Semantics in one paragraph: the machine starts in ``initial`` (or, when ``initial_event`` is set,
in the start pseudo-state ``start_name`` and moves to ``initial`` on that event). Entering a state
runs its ``action`` (``None`` = runs nothing). An event with no transition from the current state
is ignored. Deterministic: at most one target per (source, event). A final state accepts no event.

Hierarchy: a state with one region is composite (a sub-FSM with its own initial and final
states); with several regions it is parallel (orthogonal regions, all active at once). A
transition whose ``event`` is ``None`` is a completion transition: from a composite state it fires
when the sub-FSM reaches a final state (``exit`` names which one; ``None`` = any); from an atomic
state it fires as soon as the state is entered. ``fsmbt.model.flatten`` gives the plain FSM every
check works on.

``State`` and ``Transition`` are slotted dataclasses (one allocation each, fields read without a
dictionary: a converter reads every one of them); they have their fields and no others.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from fsmbt.model.errors import SourceLocation


@dataclass(slots=True)
class State:
    """One state of an FSM, possibly composite (one region) or parallel (several).

    Attributes:
        name: Unique within its machine.
        action: The action label run on entry (every reader defaults it to ``name``;
            ``None``: no action).
        final: Whether the machine is done in this state.
        regions: Sub-machines: none (atomic), one (composite) or several (parallel).
        attrs: Format-specific attributes kept for round trips.
        location: Where the state was read (not compared).
    """

    name: str
    action: str | None = None
    final: bool = False
    regions: list[FSM] = field(default_factory=list)
    attrs: dict[str, str] = field(default_factory=dict)
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    @property
    def is_composite(self) -> bool:
        """Whether the state holds exactly one sub-machine."""
        return len(self.regions) == 1

    @property
    def is_parallel(self) -> bool:
        """Whether the state holds several concurrent regions."""
        return len(self.regions) > 1

    @property
    def is_atomic(self) -> bool:
        """Whether the state holds no sub-machine."""
        return not self.regions


@dataclass(slots=True)
class Transition:
    """``source --event--> target``; ``event=None`` is a completion (eventless) transition.

    Attributes:
        source: The source state's name (in the same machine).
        event: The triggering event, or ``None`` for a completion transition.
        target: The target state's name (in the same machine).
        exit: For a completion transition out of a composite state: the sub-machine's final
            state it waits for (``None``: any).
        attrs: Format-specific attributes kept for round trips.
        location: Where the transition was read (not compared).
    """

    source: str
    event: str | None
    target: str
    exit: str | None = None
    attrs: dict[str, str] = field(default_factory=dict)
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass
class FSM:
    """A (possibly hierarchical) deterministic state machine; states keep insertion order.

    Attributes:
        name: The machine's name.
        states: The states by name, in declaration order.
        transitions: The transitions, in declaration order.
        initial: The initial state's name (the target of the initial transition).
        start_name: The start pseudo-state's name, when the file gives one.
        initial_event: The event that leaves the start pseudo-state (``None``: none needed).
        attrs: Format-specific attributes kept for round trips.
    """

    name: str = "fsm"
    states: dict[str, State] = field(default_factory=dict)
    transitions: list[Transition] = field(default_factory=list)
    initial: str | None = None
    start_name: str | None = None
    initial_event: str | None = None
    attrs: dict[str, str] = field(default_factory=dict)

    # -- building -------------------------------------------------------------------------
    def add_state(self, state: State | str, **kwargs: object) -> State:
        """Add a state; the first one added becomes the initial state.

        Args:
            state: A ``State``, or a name (its action defaults to the name).
            **kwargs: ``State`` fields when ``state`` is a name.

        Returns:
            The state added (replacing any state of the same name).
        """
        if isinstance(state, str):
            kwargs.setdefault("action", state)
            state = State(state, **kwargs)  # type: ignore[arg-type]
        self.states[state.name] = state
        if self.initial is None:
            self.initial = state.name
        return state

    def add_transition(
        self, source: str, event: str | None, target: str, **kwargs: object
    ) -> Transition:
        """Add a transition.

        Args:
            source: The source state's name.
            event: The event, or ``None`` for a completion transition.
            target: The target state's name.
            **kwargs: Further ``Transition`` fields (``exit``, ``attrs``, ``location``).

        Returns:
            The transition added.
        """
        transition = Transition(source, event, target, **kwargs)  # type: ignore[arg-type]
        self.transitions.append(transition)
        return transition

    # -- queries ----------------------------------------------------------------------------
    @property
    def is_hierarchical(self) -> bool:
        """Whether some top-level state is composite or parallel."""
        return any(not s.is_atomic for s in self.states.values())

    def events(self) -> list[str]:
        """The events this machine's transitions name (not its sub-machines').

        Returns:
            The events in order of first appearance, the initial event first.
        """
        seen: dict[str, None] = {}
        if self.initial_event is not None:
            seen[self.initial_event] = None
        for t in self.transitions:
            if t.event is not None:
                seen.setdefault(t.event, None)
        return list(seen)

    def outgoing(self, source: str) -> list[Transition]:
        """The transitions out of a state.

        Args:
            source: A state's name.

        Returns:
            Its outgoing transitions, in declaration order.
        """
        return [t for t in self.transitions if t.source == source]

    def transition_map(self) -> dict[str, dict[str | None, Transition]]:
        """The transitions indexed by source and event.

        Returns:
            ``{source: {event: transition}}`` with an entry for every state; the first
            transition wins on a conflict (``validate`` reports conflicts).
        """
        table: dict[str, dict[str | None, Transition]] = {name: {} for name in self.states}
        for t in self.transitions:
            table.setdefault(t.source, {}).setdefault(t.event, t)
        return table

    def predecessors(self, target: str) -> list[str]:
        """The distinct sources of transitions into a state.

        Args:
            target: A state's name.

        Returns:
            The source names in order of first appearance; the start pseudo-state is included
            when ``target`` is the initial state.
        """
        preds: dict[str, None] = {}
        if target == self.initial and self.start_name is not None:
            preds[self.start_name] = None
        for t in self.transitions:
            if t.target == target:
                preds.setdefault(t.source, None)
        return list(preds)

    def successors(self, source: str) -> list[str]:
        """The distinct targets of transitions out of a state.

        Args:
            source: A state's name.

        Returns:
            The target names in order of first appearance.
        """
        succ: dict[str, None] = {}
        for t in self.transitions:
            if t.source == source:
                succ.setdefault(t.target, None)
        return list(succ)

    def machines(self) -> Iterator[FSM]:
        """This machine and every sub-machine (a composite or parallel state's region) at every
        level, pre-order: the order ``walk`` meets the regions in. Iterative.

        Returns:
            An iterator of machines, this one first.
        """
        stack: list[FSM] = [self]
        while stack:
            machine = stack.pop()
            yield machine
            for state in reversed(list(machine.states.values())):
                stack.extend(reversed(state.regions))

    def walk(self, prefix: str = "") -> Iterator[tuple[str, FSM, State]]:
        """Every state at every level, pre-order.

        Iterative, so deeply nested machines do not hit Python's recursion limit.

        Args:
            prefix: Prepended to every path.

        Returns:
            An iterator of ``(path, owning machine, state)``; a path joins the names of the
            enclosing states and the state with ``/`` (inside a parallel state, the region's
            index is added: ``P/0:x``).
        """
        stack: list[tuple[str, FSM, Iterator[State]]] = [(prefix, self, iter(self.states.values()))]
        while stack:
            base, machine, states = stack[-1]
            state = next(states, None)
            if state is None:
                stack.pop()
                continue
            path = f"{base}{state.name}"
            yield path, machine, state
            for index in reversed(range(len(state.regions))):
                sub = f"{path}/" if state.is_composite else f"{path}/{index}:"
                region = state.regions[index]
                stack.append((sub, region, iter(region.states.values())))
