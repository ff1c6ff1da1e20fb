"""A hierarchical state machine (with or without data) run lazily as a leaf-execution machine,
for replaying one counterexample (``verify/lift.py``; docs/verification.md §3).

Why: ``FSMLeafMachine`` flattens the whole machine first - every reachable configuration, and
for a machine with data every valuation too (``fsm_data.expand``): on a large result that is
the product the compositional check avoids. A replay needs only the configurations one input
sequence visits, so here the machine is run step by step instead, taking exactly the steps
``FSMLeafMachine`` takes on the flattened machine (tested side by side on random walks of
converted trees, written whole and per node, and their one-transition mutants:
``tests/verify/test_ver_lazy_fsm.py``).

Scope (anything else raises ``Unsupported`` naming the shape; the caller then does not lift):
atomic states and composite states (one sub-machine each, nested to any depth) - every shape
``bt_to_hfsm`` writes. A configuration is the path of active states from the top machine down
to an atomic state, or down to a composite state holding a parallel state (a *block*,
``verify/lazy_block.py``: a Parallel written as ``<parallel>``; its sub-machine, whose data
no one else reads, is flattened alone and stepped inside the run; the block's own state is
part of the configuration). A parallel state anywhere else is refused.

``FSMLeafMachine`` reads a machine by one of two readings (docs/semantics.md §6 and §6a), and
this runner follows the one it uses:

- *without data* (``fsm_data.has_data`` false): ``model/flatten.py``'s rules. Guards and
  assignments are not read. An outcome is offered to the active states innermost first; a
  state marked final handles none, any other takes its first transition on it (document
  order), and the states below it are left. Then completions fire until none applies, the
  innermost first: the atomic state's first eventless transition (final or not), or, when the
  atomic state is final, its parent's first completion whose ``exit`` is that state or
  ``None``. Entering a composite state enters its initial sub-state.
- *with data*: the W3C algorithm the SCXML reader runs on the machine written as SCXML
  (``formats/scxml``: a completion of ``P`` is ``done.state.P`` whose guard is ``In(exit)``,
  or the transition's own guard when it has one; a final sub-state keeps its transitions). An
  outcome selects the first transition on it whose guard holds, innermost state first; taking
  it exits the states it leaves (their ``onexit`` assignments, deepest first), runs its
  assignments and enters its target (and initial sub-states); entering a final sub-state of
  ``P`` queues ``done.state.P``. Then, until the macro step ends: the atomic state's first
  eventless transition whose guard holds, or when there is none the next queued event
  (selected as above). Entering a top-level final state ends the run. The data model is
  initialised once, in declaration order.

In both readings entering a configuration outputs its atomic state's action (without data
``""`` is an action, with data it is none), an outcome that moves nothing outputs that action
again, and a top-level final state is the end (status ``final``, no more input). Cost: per
input, the transitions taken times the nesting depth (at most ``STEP_LIMIT`` transitions; a
cycle of eventless transitions raises ``Unsupported`` where the flattening raises an error),
each guard and assignment a compiled Python expression.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence
from typing import Any

from fsmbt.formats.scxml.structural import EXIT_MARK
from fsmbt.model.fsm import FSM, State, Transition
from fsmbt.model.fsm_data import ASSIGN, COND, DATAMODEL, ONEXIT, has_data, parse_lines
from fsmbt.semantics.machine import FINAL, LEAF_OUTCOMES, RUNNING
from fsmbt.verify.lazy_block import BlockUnsupported, ParallelBlock, holds_parallel
from fsmbt.verify.subset_expr import OutsideSubset, compile_subset

#: Most transitions one input may take (a cycle of eventless transitions is refused).
STEP_LIMIT = 10_000

Path = tuple[str, ...]  # the active states, top machine first, down to an atomic state
#: (configuration, variable values, the block's own state when the path ends at a block)
State_ = tuple[Path, tuple[tuple[str, Any], ...], Any]
Evaluator = Callable[[dict[str, Any]], Any]
#: A transition selected and the level (index in the path) of its source state.
Move = tuple[Transition, int]
#: One level of a configuration: its state and the state's transitions by event.
Level = tuple[State, dict[str | None, list[Transition]]]
_NONE: dict[str | None, list[Transition]] = {}
_EMPTY: list[Transition] = []
#: The internal event entering a final sub-state of ``P`` raises (W3C ``done.state.P``).
DONE = "done.state."


class Unsupported(Exception):
    """The machine is outside this runner's scope (the reason is the message)."""


_CACHE: dict[str, Evaluator] = {}


def _expr(text: str) -> Evaluator:
    found = _CACHE.get(text)
    if found is None:
        try:
            _canonical, found = compile_subset(text, subtract=True)
        except OutsideSubset:
            raise Unsupported(f"expression {text!r}") from None
        _CACHE[text] = found
    return found


def _value(text: str, values: dict[str, Any]) -> Any:
    """``text`` evaluated over ``values`` (a failure is out of scope: W3C would raise
    ``error.execution``, which this runner does not model). The subset cannot assign, so the
    values are read in place."""
    evaluate = _expr(text)
    try:
        return evaluate(values)
    except Exception as exc:  # noqa: BLE001 - any evaluation failure of the user's text
        raise Unsupported(f"expression {text!r} fails ({type(exc).__name__})") from None


_BLOCKS: dict[str, tuple[tuple[str, str], ...]] = {}


def _assign(text: str, values: dict[str, Any]) -> None:
    """Run the ``name=expr`` lines of ``text`` in order (parsed once per distinct text)."""
    if not text:
        return
    block = _BLOCKS.get(text)
    if block is None:
        block = _BLOCKS[text] = tuple(parse_lines(text))
    for var, expr in block:
        values[var] = _value(expr, values)


class LazyDataMachine:
    """``Machine`` over leaf outcomes for a machine of the module docstring's scope, stepped
    on demand by the reading ``FSMLeafMachine`` gives it."""

    follows_environment = True

    def __init__(self, fsm: FSM) -> None:
        self.fsm = fsm
        self.name = fsm.name
        self.w3c = has_data(fsm)
        if fsm.initial is None or fsm.initial not in fsm.states:
            raise Unsupported("no initial state")
        #: (id of a machine, source) -> event -> transitions in document order (event None:
        #: eventless, or a composite state's completions)
        self.table: dict[tuple[int, str], dict[str | None, list[Transition]]] = {}
        #: configuration -> per level, its state and that state's transitions by event
        #: (filled on demand: one lookup per configuration a step visits)
        self.levels: dict[Path, tuple[Level, ...]] = {}
        #: (id of a machine, state) -> the block that state is (``verify/lazy_block.py``)
        self.blocks: dict[tuple[int, str], ParallelBlock] = {}
        self.block_at: dict[Path, ParallelBlock | None] = {}
        #: the block entered during the current start or step: (its state, its outputs)
        self._inside: tuple[Any, tuple[str, ...]] | None = None
        declared = {var for var, _text in parse_lines(fsm.attrs.get(DATAMODEL, ""))}
        stack = [(fsm, "the top machine")]
        while stack:  # every machine once, without recursion
            machine, where = stack.pop()
            for state in machine.states.values():
                if self.w3c and holds_parallel(state):
                    self._add_block(machine, state, declared, where)
                    continue
                self._check_state(machine, state, where)
                if state.regions:
                    stack.append((state.regions[0], f"the sub-machine of {state.name}"))
            for t in machine.transitions:
                self._check_target(machine, t, where)
                arms = self.table.setdefault((id(machine), t.source), {})
                arms.setdefault(t.event, []).append(t)
        values: dict[str, Any] = {}
        if self.w3c:
            for var, text in parse_lines(fsm.attrs.get(DATAMODEL, "")):
                values[var] = _value(text, values)
        self.initial_values = tuple(sorted(values.items()))

    def _add_block(self, machine: FSM, state: State, declared: set[str], where: str) -> None:
        """``state`` (holding a parallel state) as a block, or ``Unsupported``."""
        what = f"state {state.name} in {where} holds a parallel state"
        if any(t.event is not None for t in machine.outgoing(state.name)):
            raise Unsupported(f"{what} and is left by an event")
        try:
            self.blocks[(id(machine), state.name)] = ParallelBlock(self.fsm, state, declared)
        except BlockUnsupported as exc:
            raise Unsupported(f"{what}, not run as a block: {exc}") from None

    def _block(self, path: Path) -> ParallelBlock | None:
        """The block ``path`` ends at, if it ends at one (cached)."""
        if path not in self.block_at:
            machine = self.fsm
            for name in path[:-1]:
                machine = machine.states[name].regions[0]
            self.block_at[path] = self.blocks.get((id(machine), path[-1]))
        return self.block_at[path]

    def _check_state(self, machine: FSM, state: State, where: str) -> None:
        """Refuse a shape this runner does not read as ``FSMLeafMachine`` does."""
        if len(state.regions) > 1:
            raise Unsupported(f"state {state.name} in {where} is a parallel state")
        if not state.regions:
            if self.w3c and state.attrs.get(EXIT_MARK) == "true":
                raise Unsupported(f"state {state.name} in {where} is an exit state")
            return
        sub = state.regions[0]
        if sub.initial is None or sub.initial not in sub.states:
            raise Unsupported(f"the sub-machine of {state.name} has no initial state")
        one = len(sub.states) == 1 and sub.name in sub.states and sub.name != state.name
        if self.w3c and one:  # the SCXML writer writes it as a parallel state
            raise Unsupported(f"state {state.name} in {where} is a one-region parallel state")

    def _check_target(self, machine: FSM, t: Transition, where: str) -> None:
        """With data, refuse what the SCXML writer refuses (the whole machine then has no
        meaning): a transition to an unknown state, a completion waiting for a state that is
        not a final sub-state. (A transition from an unknown state is not written: never
        taken, here either.)"""
        if not self.w3c:
            return
        if t.target not in machine.states:
            raise Unsupported(f"{where}: a transition to an unknown state {t.target}")
        source = machine.states.get(t.source)
        if source is not None and t.event is None and t.exit is not None and source.regions:
            final = source.regions[0].states.get(t.exit)
            if final is None or not final.final or final.regions:
                raise Unsupported(f"{where}: a completion waits for {t.exit}, not a final")

    # -- Machine protocol --------------------------------------------------------------------
    def start(self) -> tuple[State_, tuple[str, ...]]:
        assert self.fsm.initial is not None
        values = dict(self.initial_values)
        self._inside = None
        if self.w3c:
            queue: deque[Path] = deque()
            path = self._enter((), self.fsm.initial, queue, values)
            path = self._stabilise(path, values, queue)
        else:
            path = self._settle(self._descend((), self.fsm.initial))
        return self._result(path, values)

    def _result(self, path: Path, values: dict[str, Any]) -> tuple[State_, tuple[str, ...]]:
        """The state reached and its outputs (a block's own when the run stopped in one)."""
        inside, self._inside = self._inside, None
        if inside is not None:
            return (path, tuple(sorted(values.items())), inside[0]), inside[1]
        return (path, tuple(sorted(values.items())), None), self._outputs(path)

    def inputs(self, state: State_) -> Sequence[str]:
        return () if self.status(state) == FINAL else LEAF_OUTCOMES

    def status(self, state: State_) -> str:
        path = state[0]
        if state[2] is not None:  # in a block: a state holding sub-states, never the end
            return RUNNING
        return FINAL if len(path) == 1 and self.fsm.states[path[0]].final else RUNNING

    def describe(self, state: State_) -> str:
        inner = state[2]
        return "/".join(state[0]) + ("" if inner is None else f"[{inner[1]}]")

    def step(self, state: State_, symbol: str) -> tuple[State_, tuple[str, ...]]:
        if self.status(state) == FINAL:
            return state, ()
        path, frozen, inner = state
        values = dict(frozen)
        self._inside = None
        if self.w3c:
            queue: deque[Path] = deque()
            if inner is not None:
                path = self._block_step(path, inner, symbol, queue)
                if self._inside is not None:  # still in the block: nothing else moves
                    return self._result(path, values)
            else:
                move = self._select(path, symbol, values)
                if move is not None:
                    path = self._take(path, move, values, queue)
            path = self._stabilise(path, values, queue)
        else:
            move = self._flat_select(path, symbol)
            if move is not None:
                path = self._settle(self._descend(path[: move[1]], move[0].target))
        return self._result(path, values)

    def _block_step(self, path: Path, inner: Any, symbol: str, queue: deque[Path]) -> Path:
        """``symbol`` inside the block ``path`` ends at: still in it (``_inside`` set), or at
        the final sub-state it reached with ``done.state`` queued."""
        block = self._block(path)
        assert block is not None
        if any(self._arms(path, level, symbol) for level in range(len(path))):
            # W3C would offer the event to these states too (a region taking none)
            raise Unsupported(f"a state around parallel state block {path[-1]} takes {symbol!r}")
        return self._in_block(path, queue, lambda: block.step(inner, symbol))

    def _in_block(
        self,
        path: Path,
        queue: deque[Path],
        run: Callable[[], tuple[Any, tuple[str, ...], str | None]],
    ) -> Path:
        """``run`` (a block's start or step) at the block ``path`` ends at: still in it
        (``_inside`` set, ``path``), or at the final sub-state it reached, ``done.state``
        queued."""
        try:
            at, outputs, final = run()
        except BlockUnsupported as exc:
            raise Unsupported(f"parallel state block {path[-1]}: {exc}") from None
        if final is None:
            self._inside = (at, outputs)
            return path
        queue.append(path)
        return (*path, final)

    # -- both readings -----------------------------------------------------------------------
    def _levels(self, path: Path) -> tuple[Level, ...]:
        """Per level of ``path``, its state and that state's transitions by event (cached)."""
        found = self.levels.get(path)
        if found is None:
            machine, built = self.fsm, []
            for name in path:
                state = machine.states[name]
                built.append((state, self.table.get((id(machine), name), _NONE)))
                if state.regions:
                    machine = state.regions[0]
            found = self.levels[path] = tuple(built)
        return found

    def _state(self, path: Path) -> State:
        """The state ``path`` ends in."""
        return self._levels(path)[-1][0]

    def _arms(self, path: Path, level: int, event: str | None) -> list[Transition]:
        """The transitions of ``path[level]`` on ``event``, in document order."""
        return self._levels(path)[level][1].get(event, _EMPTY)

    def _outputs(self, path: Path) -> tuple[str, ...]:
        """The action of the configuration: its atomic state's."""
        action = self._state(path).action
        if self.w3c and not action:  # the SCXML writer writes no action and "" alike
            return ()
        return () if action is None else (action,)

    def _descend(self, prefix: Path, name: str) -> Path:
        """The configuration entering ``name`` (a state of ``prefix``'s machine) gives: down
        its initial sub-states to an atomic state or a block."""
        machine = self.fsm if not prefix else self._state(prefix).regions[0]
        path = prefix
        for _level in range(STEP_LIMIT):
            state = machine.states.get(name)
            if state is None:
                raise Unsupported(f"a transition to an unknown state {name}")
            path = (*path, name)
            if not state.regions or (id(machine), name) in self.blocks:
                return path  # an atomic state, or a block (its own flattening goes on)
            machine = state.regions[0]
            name = machine.initial or ""
        raise Unsupported("sub-machines nest deeper than the step limit")

    # -- without data: model/flatten.py ------------------------------------------------------
    def _flat_select(self, path: Path, event: str) -> Move | None:
        """The transition ``event`` fires: innermost first, a state marked final handling none
        (guards are not read)."""
        levels = self._levels(path)
        for level in range(len(path) - 1, -1, -1):
            state, arms = levels[level]
            if not state.final and arms.get(event):
                return arms[event][0], level
        return None

    def _settle(self, path: Path) -> Path:
        """Completions until none applies (the atomic state's first eventless transition, else
        its parent's first completion on that final state)."""
        for _step in range(STEP_LIMIT):
            level = len(path) - 1
            eventless = self._arms(path, level, None)
            if eventless:
                path = self._descend(path[:level], eventless[0].target)
                continue
            if level == 0 or not self._state(path).final:
                return path
            done = [t for t in self._arms(path, level - 1, None) if t.exit in (None, path[-1])]
            if not done:
                return path
            path = self._descend(path[: level - 1], done[0].target)
        raise Unsupported("eventless transitions form a cycle")

    # -- with data: the W3C algorithm --------------------------------------------------------
    def _select(self, path: Path, event: str, values: dict[str, Any]) -> Move | None:
        """The first enabled transition on ``event``, innermost state first."""
        for level in range(len(path) - 1, -1, -1):
            for t in self._arms(path, level, event):
                cond = t.attrs.get(COND)
                if cond is None or _value(cond, values):
                    return t, level
        return None

    def _completion(self, path: Path, done: Path, values: dict[str, Any]) -> Move | None:
        """The completion ``done.state.P`` selects (``done``: P's configuration prefix),
        while P is still active: its first whose guard holds (``In(exit)`` unless written)."""
        if path[: len(done)] != done:
            return None
        level = len(done) - 1
        for t in self._arms(path, level, None):
            cond = t.attrs.get(COND)
            if cond is not None:  # the transition's guard replaces In(exit) when written
                if _value(cond, values):
                    return t, level
            elif t.exit is None or t.exit == path[level + 1]:
                return t, level
        return None

    def _take(self, path: Path, move: Move, values: dict[str, Any], queue: deque[Path]) -> Path:
        """One micro step: exit the states from the source down (``onexit``, deepest first),
        run the assignments, enter the target."""
        t, level = move
        levels = self._levels(path)
        for depth in range(len(path) - 1, level - 1, -1):
            _assign(levels[depth][0].attrs.get(ONEXIT, ""), values)
        _assign(t.attrs.get(ASSIGN, ""), values)
        return self._enter(path[:level], t.target, queue, values)

    def _enter(self, prefix: Path, name: str, queue: deque[Path], values: dict[str, Any]) -> Path:
        """Enter ``name`` and its initial sub-states; a final sub-state queues its parent's
        ``done.state``. A block is started with ``values`` (``_inside`` set while it runs)."""
        path = self._descend(prefix, name)
        block = self._block(path) if self.blocks else None
        if block is not None:
            return self._in_block(path, queue, lambda: block.start(values))
        if len(path) > 1 and self._state(path).final:
            queue.append(path[:-1])
        return path

    def _stabilise(self, path: Path, values: dict[str, Any], queue: deque[Path]) -> Path:
        for _step in range(STEP_LIMIT):
            if len(path) == 1 and self.fsm.states[path[0]].final:
                return path  # the run is over (W3C: a top-level final)
            if self._inside is not None:
                return path  # in a block: its own eventless steps ran in its flattening
            move = None
            for t in self._arms(path, len(path) - 1, None):  # the atomic state's eventless
                cond = t.attrs.get(COND)
                if cond is None or _value(cond, values):
                    move = (t, len(path) - 1)
                    break
            while move is None and queue:
                move = self._completion(path, queue.popleft(), values)
            if move is None:
                return path
            path = self._take(path, move, values, queue)
        raise Unsupported("eventless transitions or completions form a cycle")
