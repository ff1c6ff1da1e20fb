"""A composite state holding a ``<parallel>`` run as one block by the lazy runner
(``verify/lazy_fsm.py``): the state's sub-machine, flattened alone by ``FSMLeafMachine``.

Why: a Parallel heading a small region is written as a ``<parallel>`` state whose regions take
turns on data (``convert/bt_parallel.py``). The lazy runner follows one configuration path and
does not read orthogonal regions, so a tree holding one could not have a per-node failure lifted
(``verify/lift.py``) and went to the whole product, which stops on large trees. The block's
sub-machine is small (that is why it was written so): here it is flattened alone, with the W3C
reading the whole machine gets (``FSMLeafMachine``, docs/semantics.md §6a), and stepped inside
the lazy run.

Rules (each checked on the machine; anything else raises ``Unsupported`` and the caller does not
lift, as before):

- the block is a composite state ``S`` whose sub-machine holds a parallel state, in a machine
  with data; its transitions are completions only (so no event leaves it from outside);
- *private data*: every variable the sub-machine reads or writes is mentioned nowhere outside it
  but in ``S``'s own ``onexit``; each one the sub-machine writes is reset there to a literal. So
  while ``S`` is active nothing outside reads or changes them, and after it is left their
  values are ``S``'s ``onexit`` literals, whatever the block did: the lazy run keeps its
  values outside the block, stale while inside, exact again once ``onexit`` ran;
- the block's sub-machine is flattened with its private variables at their values when ``S``
  is entered (one flattening per distinct entry valuation, cached); a final sub-state ``F``
  reached is told by a marker action (the outputs of entering it are dropped: in the whole
  machine a final sub-state is no leaf), then the lazy run goes on as W3C does, from ``S``'s
  configuration with ``F`` active and ``done.state.S`` queued.

Cost: one flattening per block and entry valuation (the block's reachable configurations and
values, at most ``limits`` ``conversion_max_states``), then one flat step per input.
"""

from __future__ import annotations

import copy
import re
from typing import Any

from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import (
    ASSIGN,
    DATAMODEL,
    ONEXIT,
    join_lines,
    mentioned_names,
    parse_lines,
)
from fsmbt.semantics.machine import FINAL, FSMLeafMachine

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: The action a final sub-state gets in the block's flattening (never a leaf's label: ``⟪`` is
#: not an XML name character).
_FINAL_MARK = "⟪final {}⟫"


class BlockUnsupported(Exception):
    """The block is outside the rules of the module docstring (the reason is the message)."""


def holds_parallel(state: State) -> bool:
    """Whether ``state`` is composite and its sub-machine holds a parallel state."""
    return len(state.regions) == 1 and any(s.is_parallel for s in state.regions[0].states.values())


def _written(machine: FSM) -> set[str]:
    """The variables ``machine``'s assignments and ``onexit`` texts (nested too) assign."""
    found: set[str] = set()
    stack = [machine]
    while stack:
        current = stack.pop()
        for t in current.transitions:
            found.update(var for var, _e in parse_lines(t.attrs.get(ASSIGN, "")))
        for state in current.states.values():
            found.update(var for var, _e in parse_lines(state.attrs.get(ONEXIT, "")))
            stack.extend(state.regions)
    return found


class ParallelBlock:
    """One block (the module docstring): ``start`` and ``step`` run its flattened sub-machine
    and say which final sub-state it reached, if any."""

    def __init__(self, fsm: FSM, state: State, declared: set[str]) -> None:
        self.state = state
        self.sub = state.regions[0]
        inside = mentioned_names(self.sub, declared)
        shared = inside & mentioned_names(fsm, declared, skip=state)
        if shared:
            raise BlockUnsupported(
                f"state {state.name}: variable {sorted(shared)[0]} is read or written outside it"
            )
        resets = parse_lines(state.attrs.get(ONEXIT, ""))
        for var, expr in resets:
            if var in inside and not _is_literal(expr) or set(_IDENT.findall(expr)) & inside:
                raise BlockUnsupported(f"state {state.name}: its exit reads or computes {var}")
        reset = {var for var, _expr in resets}
        for var in _written(self.sub) & inside:
            if var not in reset:
                raise BlockUnsupported(f"state {state.name}: {var} is not reset on exit")
        for name, sub_state in self.sub.states.items():
            if sub_state.final and (sub_state.attrs.get(ONEXIT) or sub_state.regions):
                raise BlockUnsupported(f"state {state.name}: its final {name} does something")
        self.private = sorted(inside)
        self.machines: dict[tuple[tuple[str, Any], ...], FSMLeafMachine] = {}

    def key(self, values: dict[str, Any]) -> tuple[tuple[str, Any], ...]:
        """The entry valuation of the block's private variables."""
        return tuple((var, values[var]) for var in self.private if var in values)

    def _machine(self, key: tuple[tuple[str, Any], ...]) -> FSMLeafMachine:
        found = self.machines.get(key)
        if found is None:
            states = {}
            for name, state in self.sub.states.items():
                if state.final and not state.regions:
                    state = copy.copy(state)
                    state.action = _FINAL_MARK.format(name)
                states[name] = state
            alone = FSM(
                name=f"{self.state.name}_block",
                states=states,
                transitions=list(self.sub.transitions),
                initial=self.sub.initial,
                attrs={DATAMODEL: join_lines([(var, repr(value)) for var, value in key])},
            )
            try:
                found = self.machines[key] = FSMLeafMachine(alone)
            except (FsmbtError, RecursionError) as exc:
                raise BlockUnsupported(f"state {self.state.name}: {exc}") from None
        return found

    def start(self, values: dict[str, Any]) -> tuple[Any, tuple[str, ...], str | None]:
        """Enter the block with ``values``: (its state, outputs, the final reached or None)."""
        key = self.key(values)
        inner, outputs = self._machine(key).start()
        return self._after(key, inner, outputs)

    def step(self, at: Any, symbol: str) -> tuple[Any, tuple[str, ...], str | None]:
        """One input inside the block (``at``: what ``start``/``step`` returned)."""
        key, inner = at
        new, outputs = self.machines[key].step(inner, symbol)
        return self._after(key, new, outputs)

    def _after(
        self, key: tuple[tuple[str, Any], ...], inner: Any, outputs: Any
    ) -> tuple[Any, tuple[str, ...], str | None]:
        machine = self.machines[key]
        if machine.status(inner) != FINAL:
            return (key, inner), tuple(outputs), None
        for name in self.sub.states:
            if _FINAL_MARK.format(name) in outputs:
                return (key, inner), (), name
        raise BlockUnsupported(f"state {self.state.name}: a final without its marker")


def _is_literal(text: str | None) -> bool:
    """Whether ``text`` is a number or a quoted string (a reset the run can apply blind)."""
    if text is None:
        return False
    text = text.strip()
    return bool(re.fullmatch(r"-?\d+|'[^'\\]*'|\"[^\"\\]*\"|True|False|None", text))
