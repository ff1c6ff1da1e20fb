"""A state machine with data run lazily as a leaf-execution machine, for replaying one
counterexample (``verify/lift.py``; docs/verification.md §3).

Why: ``FSMLeafMachine`` flattens a machine with data by the W3C reading of *every* reachable
configuration and valuation (``fsm_data.expand``): on a large per-node result that is the
product the per-node check avoids. A replay needs only the configurations one input sequence
visits, so here the machine is run step by step instead.

Scope (anything else raises ``Unsupported``; the caller then does not lift): the shape the
compositional check accepts (``verify/compositional.py``) - a top-level machine without data
whose states are leaf states (an action), final states, or *region states*: one flat
sub-machine each, left only by completion transitions naming its final (``exit``), with
``onexit`` assignments at most. Rules, as ``FSMLeafMachine`` reads the flattened machine
(docs/semantics.md, "The leaf-execution machine" and "Data in state machines"): the data model
is initialised once; a leaf state takes the first transition (document order) on the outcome
whose guard holds, its assignments run in order, then eventless transitions are taken (the
first enabled, document order) until a state with an action or a final; an outcome without an
enabled transition stays, and the leaf's action is output again; entering a state outputs its
action; a region's final takes the region's completion on it (``onexit`` first). Cost: per
input, the eventless steps taken (at most ``STEP_LIMIT``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from fsmbt.model.fsm import FSM, State, Transition
from fsmbt.model.fsm_data import ASSIGN, COND, DATAMODEL, ONEXIT, parse_lines
from fsmbt.semantics.machine import FINAL, LEAF_OUTCOMES, RUNNING
from fsmbt.verify.subset_expr import OutsideSubset, compile_subset

#: Most eventless steps one input may take (an eventless cycle is refused).
STEP_LIMIT = 100_000

State_ = tuple[str, str | None, tuple[tuple[str, Any], ...]]  # (top, sub or None, values)


class Unsupported(Exception):
    """The machine is outside this runner's scope (the reason is the message)."""


_CACHE: dict[str, Callable[[dict[str, Any]], Any]] = {}


def _expr(text: str) -> Callable[[dict[str, Any]], Any]:
    found = _CACHE.get(text)
    if found is None:
        try:
            _canonical, found = compile_subset(text, subtract=True)
        except OutsideSubset:
            raise Unsupported(f"expression {text!r}") from None
        _CACHE[text] = found
    return found


class LazyDataMachine:
    """``Machine`` over leaf outcomes for a result of the compositional shape (module
    docstring), stepped on demand."""

    follows_environment = True

    def __init__(self, fsm: FSM) -> None:
        self.fsm = fsm
        self.name = fsm.name
        if fsm.initial is None:
            raise Unsupported("no initial state")
        self.out: dict[tuple[str, str | None], list[Transition]] = {}
        self.subs: dict[str, FSM] = {}
        for name, state in fsm.states.items():
            if state.regions:
                if len(state.regions) != 1 or state.regions[0].is_hierarchical:
                    raise Unsupported(f"state {name} is not one flat region")
                sub = state.regions[0]
                if sub.initial is None:
                    raise Unsupported(f"region {name} has no initial state")
                self.subs[name] = sub
                for t in sub.transitions:
                    self.out.setdefault((name, t.source), []).append(t)
            elif set(state.attrs) - {ONEXIT} or state.attrs:
                raise Unsupported(f"state {name} carries data")
        for t in fsm.transitions:
            if t.attrs and t.source not in self.subs:
                raise Unsupported("data outside a region")
            self.out.setdefault((t.source, None), []).append(t)
        values: dict[str, Any] = {}
        for var, text in parse_lines(fsm.attrs.get(DATAMODEL, "")):
            values[var] = _expr(text)({})
        self.initial_values = tuple(sorted(values.items()))

    # -- Machine protocol --------------------------------------------------------------------
    def start(self) -> tuple[State_, tuple[str, ...]]:
        assert self.fsm.initial is not None
        values = dict(self.initial_values)
        outputs: list[str] = []
        top, sub = self._enter_top(self.fsm.initial, values, outputs)
        return (top, sub, tuple(sorted(values.items()))), tuple(outputs)

    def inputs(self, state: State_) -> Sequence[str]:
        return () if self.status(state) == FINAL else LEAF_OUTCOMES

    def status(self, state: State_) -> str:
        top, sub, _values = state
        return FINAL if sub is None and self.fsm.states[top].final else RUNNING

    def describe(self, state: State_) -> str:
        top, sub, _values = state
        return top if sub is None else f"{top}/{sub}"

    def step(self, state: State_, symbol: str) -> tuple[State_, tuple[str, ...]]:
        top, sub, frozen = state
        if self.status(state) == FINAL:
            return state, ()
        values = dict(frozen)
        outputs: list[str] = []
        taken = self._first(self.out.get((top, sub), []), symbol, values)
        if taken is None:  # no transition: the same leaf is ticked again
            here = self.subs[top].states[sub] if sub is not None else self.fsm.states[top]
            outputs.extend([here.action] if here.action is not None else [])
            return state, tuple(outputs)
        if sub is None:
            top, sub = self._enter_top(taken.target, values, outputs)
        else:
            self._assign(taken, values)
            top, sub = self._enter_sub(top, taken.target, values, outputs)
        return (top, sub, tuple(sorted(values.items()))), tuple(outputs)

    # -- helpers -----------------------------------------------------------------------------
    @staticmethod
    def _first(arms: list[Transition], event: str | None, values: dict[str, Any]) -> Any:
        for t in arms:
            if t.event != event or t.exit is not None:
                continue
            cond = t.attrs.get(COND)
            if cond is None or _expr(cond)(dict(values)):
                return t
        return None

    @staticmethod
    def _assign(t: Transition | State, values: dict[str, Any], key: str = ASSIGN) -> None:
        for var, text in parse_lines(t.attrs.get(key, "")):
            values[var] = _expr(text)(dict(values))

    def _enter_top(
        self, name: str, values: dict[str, Any], outputs: list[str]
    ) -> tuple[str, str | None]:
        for _step in range(STEP_LIMIT):
            state = self.fsm.states[name]
            if name not in self.subs:
                if state.action is not None:
                    outputs.append(state.action)
                elif state.final:
                    outputs.append(name)
                return name, None
            sub = self.subs[name].initial
            assert sub is not None
            return self._enter_sub(name, sub, values, outputs)
        raise Unsupported("a cycle of completions")

    def _enter_sub(
        self, top: str, name: str, values: dict[str, Any], outputs: list[str]
    ) -> tuple[str, str | None]:
        for _step in range(STEP_LIMIT):
            machine = self.subs[top]
            state = machine.states[name]
            if state.final:
                done = [t for t in self.out.get((top, None), []) if t.exit in (name, None)]
                if not done:
                    return top, name  # a region that never completes: it stays
                self._assign(self.fsm.states[top], values, ONEXIT)
                return self._enter_top(done[0].target, values, outputs)
            taken = self._first(self.out.get((top, name), []), None, values)
            if taken is None:
                if state.action is not None:
                    outputs.append(state.action)
                return top, name
            self._assign(taken, values)
            name = taken.target
        raise Unsupported("an eventless cycle without a leaf")
