"""Flattening a hierarchical FSM into the plain FSM every check works on (docs/semantics.md, 'Models').

Rules (also in docs/semantics.md):
- A configuration is the active atomic state at each level: ``C/x`` for state ``x`` inside
  composite ``C``; ``P/[x|y]`` for parallel ``P`` whose regions are in ``x`` and ``y``.
- An event goes to the innermost active states first (every region of a parallel state); only
  when no inner state has a transition on it does the enclosing state's transition fire.
- Entering a composite state enters its initial sub-state; entering a parallel state enters every
  region's initial sub-state.
- Completion transitions (``event=None``) fire at once: from an atomic state on entry, from a
  composite state when its sub-FSM is in a final state (``exit`` = that state, or ``None``), from
  a parallel state when every region is in a final state - a region whose active state is
  composite counts when that state's sub-FSM is in a final state, a nested parallel one when all
  its regions are (SCXML's rule for ``done.state.<parallel>``). A state left that way is
  transient.
- The flat state's action is the actions of its active atomic states joined with ``+`` in
  document order; a transient state is never observed, so its action is not either.
- Only the reachable configurations are kept; a plain FSM without eventless transitions is
  returned as an equal copy.

Complexity: O(C · E · D) for C reachable configurations, E events and nesting depth D; C is
bounded by ``max_configurations`` (parallel regions multiply).
"""

from __future__ import annotations

import copy
from collections import deque
from dataclasses import dataclass

from fsmbt.model import fsm_data
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM, State, Transition

#: Separator between a composite state's name and its active sub-state in flat names.
PATH_SEPARATOR = "/"
MAX_COMPLETION_CHAIN = 10_000


@dataclass(frozen=True)
class _Config:
    """Active configuration of one machine level: a state, and the configs of its regions."""

    state: str
    inner: tuple[_Config, ...] = ()

    def name(self) -> str:
        if not self.inner:
            return self.state
        if len(self.inner) == 1:
            return f"{self.state}{PATH_SEPARATOR}{self.inner[0].name()}"
        return f"{self.state}{PATH_SEPARATOR}[" + "|".join(c.name() for c in self.inner) + "]"


class _Flattener:
    def __init__(self, fsm: FSM, max_configurations: int) -> None:
        self.fsm = fsm
        self.max_configurations = max_configurations
        self._tables: dict[int, dict[str, dict[str | None, list[Transition]]]] = {}

    # -- structure helpers --------------------------------------------------------------------
    def table(self, machine: FSM) -> dict[str, dict[str | None, list[Transition]]]:
        key = id(machine)
        if key not in self._tables:
            table: dict[str, dict[str | None, list[Transition]]] = {}
            for t in machine.transitions:
                table.setdefault(t.source, {}).setdefault(t.event, []).append(t)
            self._tables[key] = table
        return self._tables[key]

    def state(self, machine: FSM, name: str) -> State:
        try:
            return machine.states[name]
        except KeyError:
            raise InputError(
                f"transition to unknown state '{name}'", element=machine.name
            ) from None

    # -- semantics ----------------------------------------------------------------------------
    def enter(self, machine: FSM, name: str) -> _Config:
        state = self.state(machine, name)
        if state.is_atomic:
            config = _Config(name)
        else:
            inner = []
            for region in state.regions:
                if region.initial is None:
                    raise InputError(
                        "composite state has a sub-machine without initial state",
                        element=name,
                        location=state.location,
                    )
                inner.append(self.enter(region, region.initial))
            config = _Config(name, tuple(inner))
        return self.settle(machine, config)

    def is_done(self, machine: FSM, config: _Config) -> bool:
        """Is this configuration in a final state of ``machine``?"""
        return self.state(machine, config.state).final and not config.inner

    def in_final(self, machine: FSM, config: _Config) -> bool:
        """SCXML's "in a final state" for a parallel state's region: an atomic final state, a
        composite state whose active sub-state is final, a parallel state whose every region is
        in a final state (so a parallel of compound states completes as in SCXML)."""
        state = self.state(machine, config.state)
        if not config.inner:
            return state.final
        if state.is_composite:
            return self.is_done(state.regions[0], config.inner[0])
        return all(self.in_final(region, sub) for region, sub in zip(state.regions, config.inner))

    def settle(self, machine: FSM, config: _Config) -> _Config:
        """Fire completion transitions until none applies."""
        for _ in range(MAX_COMPLETION_CHAIN):
            transition = self.completion(machine, config)
            if transition is None:
                return config
            config = self.enter_no_settle(machine, transition.target)
        raise InputError("eventless transitions form a cycle", element=config.state)

    def enter_no_settle(self, machine: FSM, name: str) -> _Config:
        state = self.state(machine, name)
        if state.is_atomic:
            return _Config(name)
        inner = tuple(self.enter(region, region.initial or "") for region in state.regions)
        return _Config(name, inner)

    def completion(self, machine: FSM, config: _Config) -> Transition | None:
        state = self.state(machine, config.state)
        candidates = self.table(machine).get(config.state, {}).get(None, [])
        if not candidates:
            return None
        if state.is_atomic:
            return candidates[0]
        if state.is_composite:
            done = self.is_done(state.regions[0], config.inner[0])
        else:
            done = all(
                self.in_final(region, sub) for region, sub in zip(state.regions, config.inner)
            )
        if not done:
            return None
        exit_name = config.inner[0].state if state.is_composite else None
        for t in candidates:
            if t.exit is None or t.exit == exit_name:
                return t
        return None

    def step(self, machine: FSM, config: _Config, event: str) -> _Config | None:
        """The configuration after ``event``, or ``None`` when nothing at this level or below
        handles it."""
        state = self.state(machine, config.state)
        if config.inner:
            changed = False
            new_inner = []
            for region, sub in zip(state.regions, config.inner):
                moved = self.step(region, sub, event)
                if moved is not None:
                    changed = True
                    new_inner.append(moved)
                else:
                    new_inner.append(sub)
            if changed:
                return self.settle(machine, _Config(config.state, tuple(new_inner)))
        if state.final:
            return None
        candidates = self.table(machine).get(config.state, {}).get(event, [])
        if not candidates:
            return None
        return self.enter(machine, candidates[0].target)

    def action(self, machine: FSM, config: _Config) -> str | None:
        state = self.state(machine, config.state)
        if not config.inner:
            return state.action
        parts = [self.action(region, sub) for region, sub in zip(state.regions, config.inner)]
        kept = [p for p in parts if p is not None]
        return "+".join(kept) if kept else None

    # -- exploration --------------------------------------------------------------------------
    def run(self) -> FSM:
        fsm = self.fsm
        if fsm.initial is None:
            raise InputError("the state machine has no initial state", element=fsm.name)
        events = _all_events(fsm)
        start = self.enter(fsm, fsm.initial)
        flat = FSM(
            name=fsm.name,
            start_name=fsm.start_name,
            initial_event=fsm.initial_event,
            attrs=dict(fsm.attrs),
        )
        seen: dict[_Config, str] = {}
        queue: deque[_Config] = deque()

        def visit(config: _Config) -> str:
            name = seen.get(config)
            if name is None:
                if len(seen) >= self.max_configurations:
                    raise InputError(
                        f"flattening exceeds {self.max_configurations} configurations "
                        "(parallel regions multiply)",
                        element=fsm.name,
                    )
                name = config.name()
                seen[config] = name
                top = self.state(fsm, config.state)
                flat.add_state(
                    State(
                        name,
                        action=self.action(fsm, config),
                        final=top.final and not config.inner,
                        location=top.location,
                    )
                )
                queue.append(config)
            return name

        flat.initial = visit(start)
        while queue:
            config = queue.popleft()
            source = seen[config]
            for event in events:
                moved = self.step(fsm, config, event)
                if moved is not None:
                    flat.add_transition(source, event, visit(moved))
        return flat


def _all_events(fsm: FSM) -> list[str]:
    seen: dict[str, None] = {}
    for _, machine, _state in [("", fsm, None), *fsm.walk()]:
        if _state is not None:
            for region in _state.regions:
                for e in region.events():
                    seen.setdefault(e, None)
        else:
            for e in machine.events():
                seen.setdefault(e, None)
    return list(seen)


def needs_flattening(fsm: FSM) -> bool:
    """Whether ``fsm`` differs from its flattening.

    Args:
        fsm: A machine.

    Returns:
        True when it has a composite or parallel state, a completion transition, or data
        (``fsmbt.model.fsm_data``).
    """
    return (
        fsm_data.has_data(fsm)
        or fsm.is_hierarchical
        or any(t.event is None for t in fsm.transitions)
    )


def flatten(fsm: FSM, *, max_configurations: int = 1_000_000) -> FSM:
    """The plain FSM with the same macro-step behaviour as ``fsm`` (see module docstring).

    Args:
        fsm: A flat or hierarchical machine; it is not modified.
        max_configurations: Bound on the reachable configurations kept.

    Returns:
        A new flat FSM whose states are the reachable configurations (a copy of ``fsm`` when
        it needs no flattening).

    Raises:
        InputError: A transition to an unknown state, a composite state without initial
            state, a cycle of completion transitions, no initial state, or more than
            ``max_configurations`` configurations.
    """
    if not needs_flattening(fsm):
        return copy.deepcopy(fsm)
    if fsm_data.has_data(fsm):  # its meaning is the W3C reading (docs/semantics.md, data)
        return fsm_data.expand(fsm)
    return _Flattener(fsm, max_configurations).run()
