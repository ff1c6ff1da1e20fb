"""The native equivalence checker: the lockstep product of two deterministic machines, breadth first.

Both machines (``fsmbt.semantics.machine.Machine``) are fed the same inputs from their start. The
product ``P`` holds every pair ``(s, r)`` reachable that way, whether or not the two agreed on the
way (so every property is a plain invariant of ``P``, independent of the others and of search
order, and the NuSMV engine can state it the same way). The five properties, defined exactly in
docs/verification.md, 'The product and the five properties':

- completeness: on every product edge the source's outputs are a subsequence of the result's,
  and every input the source offers, the result accepts;
- no additional behaviour: on every product edge the result's outputs are a subsequence of the
  source's, and the result accepts no input the source refuses;
- termination consistency: both statuses agree in every product pair (the start included);
- deadlock absence: in no product pair is exactly one side dead (status running and no input
  sequence ever leads to an output or a status change);
- reachability: every state the source reaches on its own, and every result state in ``P``, is
  reached on a path where both machines agreed at every step (a *faithful* pair).

Equivalent iff all five hold, which is exactly: same offered inputs, same outputs and same status
after every input sequence. Breadth-first order makes every counterexample a shortest one.

Algorithm: each machine is explored alone first (its states interned as ints, its steps
memoised), which gives the source's reachable states and both machines' *dead* states (reverse
breadth-first search from the observable edges). The product then runs on those tables.
Machines may expose ``active_inputs(state)``: the inputs that may do anything; every other offered
input is promised to be a silent self-loop and is not stepped (an FSM with 10 000 events would
otherwise cost ``states x events`` steps). A machine with ``follows_environment = True`` takes the
source's inputs in the product instead of offering its own (an FSM read as a leaf-execution
machine has no notion of which leaves are conditions).

Complexity: ``O((|S| + |R|) · k · c + |P| · k)`` time and ``O(|S| + |R| + |P|)`` memory, for
``k`` explored inputs per state and ``c`` the cost of one machine step; ``|P| <= |S| · |R|`` and
``|P| ~ |S|`` for equivalent pairs. Exploration is iterative (no recursion).
"""

from __future__ import annotations

import gc
import time
from collections.abc import Hashable, Sequence
from dataclasses import dataclass, field
from typing import Any

from fsmbt import limits
from fsmbt.limits import Limits
from fsmbt.model.errors import Hint, InputError, LimitError
from fsmbt.semantics.machine import RUNNING, Machine
from fsmbt.verify.report import (
    COMPLETENESS,
    DEADLOCK_ABSENCE,
    NO_ADDITIONAL_BEHAVIOR,
    PROPERTIES,
    REACHABILITY,
    TERMINATION_CONSISTENCY,
    PropertyResult,
    Report,
    TraceStep,
)

#: Largest number of states (per machine, and of the product) explored before giving up
#: (the default lives in ``fsmbt.limits``: ``checker_max_states``).
DEFAULT_MAX_STATES = Limits.checker_max_states


class StateLimitError(LimitError):
    """A machine or the product has more reachable states than ``max_states`` allows.

    A ``LimitError`` and so an ``InputError`` (callers that only know that class still see bad
    input); the batch runner tells every ``LimitError`` apart to record the model as over a
    limit, not as malformed.
    """


class CheckerTimeLimitError(StateLimitError):
    """The checker ran past its wall-time limit (``fsmbt.limits``: ``checker_max_seconds``).

    A kind of ``StateLimitError``: both say the model is too large to decide within the bounds
    in force, and callers (the batch runner, the CLI's exit code) treat them alike.
    """


class _Deadline:
    """The wall-clock bound of one check, looked at every ``_EVERY`` new states or pairs.

    Reading the clock costs ~50 ns; every 1 024 states keeps that under 0.1 % of a machine step
    (the cheapest step, a table lookup, is ~1 µs), while a state takes at most a few ms to
    explore, so the check overshoots its limit by milliseconds at most.
    """

    _EVERY = 1024

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.ends = time.perf_counter() + seconds
        self._countdown = self._EVERY

    def tick(self, where: str) -> None:
        """Count one unit of work; past the deadline raise ``CheckerTimeLimitError``."""
        self._countdown -= 1
        if self._countdown:
            return
        self._countdown = self._EVERY
        if time.perf_counter() > self.ends:
            raise CheckerTimeLimitError(
                f"the native checker stopped after {self.seconds:g} s exploring {where} "
                "(undecided: the state space is too large for this time limit)",
                hints=(Hint.CHECKER_TIME,),
            )


_NO_OUTPUT: tuple[str, ...] = ()


# -- one machine on its own -----------------------------------------------------------------------
class _Explored:
    """One machine explored breadth first from its start, states interned as ints.

    ``edges[x]`` maps each explored input of state ``x`` to ``(next state id, outputs id)``;
    offered inputs that are not explored are silent self-loops (see ``active_inputs``).
    """

    def __init__(
        self,
        machine: Machine[Any],
        outputs: _Interner,
        max_states: int,
        role: str,
        deadline: _Deadline,
    ) -> None:
        self.machine = machine
        self.deadline = deadline
        self.role = role
        self.outputs = outputs
        self.max_states = max_states
        self.states: list[Hashable] = []
        self.index: dict[Hashable, int] = {}
        self.status: list[str] = []
        self.offered: list[int] = []  # id of the offered input set
        self.edges: list[dict[str, tuple[int, int]]] = []
        self.parent: list[int] = []
        self.parent_input: list[str | None] = []
        self.input_sets: list[tuple[str, ...]] = []
        self.input_frozen: list[frozenset[str]] = []
        self._input_index: dict[tuple[str, ...], int] = {}
        self._input_by_identity: dict[int, tuple[object, int]] = {}
        self.follows_environment = bool(getattr(machine, "follows_environment", False))
        self._active = getattr(machine, "active_inputs", None)
        start_state, start_out = machine.start()
        self.start_outputs = outputs.intern(tuple(start_out))
        self._intern(start_state, -1, None)
        self._explore()
        self.dist_to_observable, self.next_to_observable = self._observable_distances()

    # interning
    def _intern(self, state: Hashable, parent: int, symbol: str | None) -> int:
        found = self.index.get(state)
        if found is not None:
            return found
        if len(self.states) >= self.max_states:
            raise StateLimitError(
                f"the {self.role} machine has more than {self.max_states} reachable states "
                "(check the model for an unbounded counter)",
                element=getattr(self.machine, "name", self.role),
                hints=(Hint.MAX_STATES,),
            )
        self.deadline.tick(f"the {self.role} machine")
        new_id = len(self.states)
        self.index[state] = new_id
        self.states.append(state)
        self.status.append(self.machine.status(state))
        self.offered.append(self._intern_inputs(self.machine.inputs(state)))
        self.edges.append({})
        self.parent.append(parent)
        self.parent_input.append(symbol)
        return new_id

    def _intern_inputs(self, offered: Sequence[str]) -> int:
        cached = self._input_by_identity.get(id(offered))
        if cached is not None and cached[0] is offered:
            return cached[1]
        key = tuple(offered)
        set_id = self._input_index.get(key)
        if set_id is None:
            set_id = len(self.input_sets)
            self._input_index[key] = set_id
            self.input_sets.append(key)
            self.input_frozen.append(frozenset(key))
        self._input_by_identity[id(offered)] = (offered, set_id)
        return set_id

    def _explore(self) -> None:
        machine, outputs = self.machine, self.outputs
        step = machine.step
        cursor = 0
        while cursor < len(self.states):
            x = cursor
            cursor += 1
            state = self.states[x]
            offered = self.input_sets[self.offered[x]]
            if self._active is not None:
                allowed = self.input_frozen[self.offered[x]]
                candidates: Sequence[str] = [a for a in self._active(state) if a in allowed]
            else:
                candidates = offered
            row = self.edges[x]
            for symbol in candidates:
                if symbol in row:
                    continue
                nxt, out = step(state, symbol)
                row[symbol] = (self._intern(nxt, x, symbol), outputs.intern(tuple(out)))

    def _observable_distances(self) -> tuple[list[int], list[str | None]]:
        """Per state: the fewest inputs to an observable edge (output or status change), -1 if
        none is reachable; and the first input of such a shortest sequence. Reverse BFS, O(E)."""
        n = len(self.states)
        dist = [-1] * n
        first: list[str | None] = [None] * n
        reverse: list[list[tuple[int, str]]] = [[] for _ in range(n)]
        frontier: list[int] = []
        empty = self.outputs.intern(_NO_OUTPUT)
        for x in range(n):
            status_x = self.status[x]
            for symbol, (y, out) in self.edges[x].items():
                if y != x:
                    reverse[y].append((x, symbol))
                if dist[x] < 0 and (out != empty or self.status[y] != status_x):
                    dist[x] = 1
                    first[x] = symbol
                    frontier.append(x)
        while frontier:
            next_frontier: list[int] = []
            for y in frontier:
                for x, symbol in reverse[y]:
                    if dist[x] < 0:
                        dist[x] = dist[y] + 1
                        first[x] = symbol
                        next_frontier.append(x)
            frontier = next_frontier
        return dist, first

    # queries
    def is_dead(self, x: int) -> bool:
        return self.status[x] == RUNNING and self.dist_to_observable[x] < 0

    def accepts(self, x: int, symbol: str) -> bool:
        return symbol in self.input_frozen[self.offered[x]]

    def move(self, x: int, symbol: str) -> tuple[int, int]:
        """The memoised step; an offered but unexplored input is a silent self-loop."""
        hit = self.edges[x].get(symbol)
        if hit is not None:
            return hit
        if not self.follows_environment or self.accepts(x, symbol):
            return x, self.outputs.intern(_NO_OUTPUT)
        raise InputError(
            f"the {self.role} machine was given input {symbol!r} that it does not "
            "list among its inputs",
            element=getattr(self.machine, "name", self.role),
        )

    def path_to(self, x: int) -> list[str]:
        inputs: list[str] = []
        while self.parent[x] >= 0:
            inputs.append(self.parent_input[x])  # type: ignore[arg-type]
            x = self.parent[x]
        inputs.reverse()
        return inputs

    def path_to_observable(self, x: int) -> list[str]:
        inputs: list[str] = []
        while self.dist_to_observable[x] > 0:
            symbol = self.next_to_observable[x]
            assert symbol is not None
            inputs.append(symbol)
            nxt, out = self.edges[x][symbol]
            if out != self.outputs.intern(_NO_OUTPUT) or self.status[nxt] != self.status[x]:
                break
            x = nxt
        return inputs


class _Interner:
    """Output tuples as ints, so comparing two steps' outputs is an int comparison."""

    def __init__(self) -> None:
        self.index: dict[tuple[str, ...], int] = {}
        self.values: list[tuple[str, ...]] = []

    def intern(self, value: tuple[str, ...]) -> int:
        found = self.index.get(value)
        if found is None:
            found = len(self.values)
            self.index[value] = found
            self.values.append(value)
        return found


def _is_subsequence(small: tuple[str, ...], big: tuple[str, ...]) -> bool:
    it = iter(big)
    return all(any(item == other for other in it) for item in small)


# -- replay ---------------------------------------------------------------------------------------
@dataclass
class Replay:
    """Both machines run on one input sequence: the trace, and the steps where they differ."""

    steps: list[TraceStep]
    differences: list[str] = field(default_factory=list)

    @property
    def differs(self) -> bool:
        return bool(self.differences)


def replay(source: Machine[Any], result: Machine[Any], inputs: Sequence[str]) -> Replay:
    """Run ``inputs`` on both machines from their start and record what each did.

    A step differs when the outputs or the statuses differ, or one side refuses the input (it is
    not among its offered inputs; a ``follows_environment`` machine never refuses). The replay
    stops at a refusal. Used to show counterexamples and, by the tests, to confirm them.
    """
    follows = bool(getattr(result, "follows_environment", False))
    s, out_s = source.start()
    r, out_r = result.start()
    steps: list[TraceStep] = []
    differences: list[str] = []

    def record(
        index: int, symbol: str | None, o1: Sequence[str], o2: Sequence[str], note: str
    ) -> None:
        st_s, st_r = source.status(s), result.status(r)
        notes = [note] if note else []
        if tuple(o1) != tuple(o2):
            notes.append("outputs differ")
        if st_s != st_r:
            notes.append(f"status differs ({st_s} vs {st_r})")
        text = "; ".join(notes)
        if text:
            differences.append(f"step {index}: {text}")
        steps.append(
            TraceStep(
                index,
                symbol,
                list(o1),
                list(o2),
                source.describe(s),
                result.describe(r),
                st_s,
                st_r,
                note=text,
            )
        )

    record(0, None, out_s, out_r, "")
    for index, symbol in enumerate(inputs, start=1):
        source_ok = symbol in source.inputs(s)
        result_ok = follows or symbol in result.inputs(r)
        if not (source_ok and result_ok):
            side = "source" if not source_ok else "result"
            new_s, o1 = source.step(s, symbol) if source_ok else (s, ())
            new_r, o2 = result.step(r, symbol) if result_ok else (r, ())
            s, r = new_s, new_r
            record(index, symbol, o1, o2, f"the {side} does not accept input {symbol!r}")
            break
        s, o1 = source.step(s, symbol)
        r, o2 = result.step(r, symbol)
        record(index, symbol, o1, o2, "")
    return Replay(steps, differences)


# -- the product ----------------------------------------------------------------------------------
@dataclass
class _Violation:
    """Where a property first fails in breadth-first order: the pair, an input, and why."""

    pair: int
    symbol: str | None  # the offending input from ``pair`` (None: the pair itself)
    detail: str
    extension: list[str] = field(default_factory=list)


class _Product:
    def __init__(
        self, src: _Explored, res: _Explored, max_states: int, deadline: _Deadline
    ) -> None:
        self.src, self.res = src, res
        self.max_states = max_states
        self.deadline = deadline
        self.pair_s: list[int] = []
        self.pair_r: list[int] = []
        self.parent: list[int] = []
        self.parent_input: list[str | None] = []
        self.start_ok = False
        self.index: dict[int, int] = {}
        self.width = max(len(res.states), 1)
        self.edges = 0
        self.first: dict[str, _Violation] = {}
        self.counts: dict[str, int] = {name: 0 for name in PROPERTIES}
        #: every violation in breadth-first order, when ``frontier`` asked for them all
        self.every: list[tuple[str, _Violation]] | None = None
        self._input_diffs: dict[tuple[int, int], tuple[list[str], list[str]]] = {}

    def violate(self, name: str, violation: _Violation) -> None:
        self.counts[name] += 1
        self.first.setdefault(name, violation)
        if self.every is not None:
            self.every.append((name, violation))

    def pair(self, s: int, r: int, parent: int, symbol: str | None) -> int:
        key = s * self.width + r
        found = self.index.get(key)
        if found is not None:
            return found
        if len(self.pair_s) >= self.max_states:
            raise StateLimitError(
                f"the product of the two machines has more than {self.max_states} states",
                hints=(Hint.MAX_STATES,),
            )
        self.deadline.tick("the product of the two machines")
        new_id = len(self.pair_s)
        self.index[key] = new_id
        self.pair_s.append(s)
        self.pair_r.append(r)
        self.parent.append(parent)
        self.parent_input.append(symbol)
        return new_id

    def input_difference(self, s: int, r: int) -> tuple[list[str], list[str]]:
        key = (self.src.offered[s], self.res.offered[r])
        cached = self._input_diffs.get(key)
        if cached is None:
            mine = self.src.input_frozen[key[0]]
            theirs = self.res.input_frozen[key[1]]
            missing = [a for a in self.src.input_sets[key[0]] if a not in theirs]
            extra = [a for a in self.res.input_sets[key[1]] if a not in mine]
            cached = (missing, extra)
            self._input_diffs[key] = cached
        return cached

    def compare_outputs(self, p: int, symbol: str | None, o1: int, o2: int) -> None:
        values = self.src.outputs.values
        v1, v2 = values[o1], values[o2]
        where = "at the start" if symbol is None else f"on input {symbol!r}"
        if not _is_subsequence(v1, v2):
            self.violate(
                COMPLETENESS,
                _Violation(
                    p, symbol, f"{where} the source does {_show(v1)}, the result {_show(v2)}"
                ),
            )
        if not _is_subsequence(v2, v1):
            self.violate(
                NO_ADDITIONAL_BEHAVIOR,
                _Violation(
                    p, symbol, f"{where} the result does {_show(v2)}, the source {_show(v1)}"
                ),
            )

    def run(self) -> None:
        """Breadth first over agreeing steps only: every pair explored is faithful."""
        src, res = self.src, self.res
        start = self.pair(0, 0, -1, None)
        if src.start_outputs != res.start_outputs:
            self.compare_outputs(start, None, src.start_outputs, res.start_outputs)
        if src.status[0] != res.status[0]:
            self.violate(
                TERMINATION_CONSISTENCY,
                _Violation(
                    start,
                    None,
                    f"at the start the source is {src.status[0]!r}, the result {res.status[0]!r}",
                ),
            )
        self.start_ok = src.start_outputs == res.start_outputs and src.status[0] == res.status[0]
        if not self.start_ok:
            return
        follows = res.follows_environment
        cursor = 0
        while cursor < len(self.pair_s):
            p = cursor
            cursor += 1
            s, r = self.pair_s[p], self.pair_r[p]
            if src.is_dead(s) != res.is_dead(r):
                self._deadlock(p, s, r)
            if not follows:
                missing, extra = self.input_difference(s, r)
                if missing:
                    self.violate(
                        COMPLETENESS,
                        _Violation(
                            p,
                            missing[0],
                            f"the result does not accept input {missing[0]!r} "
                            f"(the source does; {len(missing)} such inputs)",
                        ),
                    )
                if extra:
                    self.violate(
                        NO_ADDITIONAL_BEHAVIOR,
                        _Violation(
                            p,
                            extra[0],
                            f"the result accepts input {extra[0]!r} that the source "
                            f"refuses ({len(extra)} such inputs)",
                        ),
                    )
            s_row, r_row = src.edges[s], res.edges[r]
            symbols = list(s_row)
            symbols.extend(a for a in r_row if a not in s_row)
            for symbol in symbols:
                if not src.accepts(s, symbol):
                    continue
                if not follows and not res.accepts(r, symbol):
                    continue
                s2, o1 = src.move(s, symbol)
                r2, o2 = res.move(r, symbol)
                self.edges += 1
                agree = True
                if o1 != o2:
                    self.compare_outputs(p, symbol, o1, o2)
                    agree = False
                if src.status[s2] != res.status[r2]:
                    self.violate(
                        TERMINATION_CONSISTENCY,
                        _Violation(
                            p,
                            symbol,
                            f"after input {symbol!r} the source is {src.status[s2]!r}, "
                            f"the result {res.status[r2]!r}",
                        ),
                    )
                    agree = False
                if agree:
                    self.pair(s2, r2, p, symbol)

    def _deadlock(self, p: int, s: int, r: int) -> None:
        src, res = self.src, self.res
        if src.is_dead(s):
            dead, live, live_side = "source", res, "result"
            live_state = r
        else:
            dead, live, live_side = "result", src, "source"
            live_state = s
        extension = (
            live.path_to_observable(live_state) if live.status[live_state] == RUNNING else []
        )
        self.violate(
            DEADLOCK_ABSENCE,
            _Violation(
                p,
                None,
                f"the {dead} is stuck in a non-terminal state (no input ever makes it "
                f"act) while the {live_side} can still act",
                extension,
            ),
        )

    def faithful(self) -> list[bool]:
        """Pairs reached on a path where both machines agreed at every step: all explored ones,
        unless the two already differ at the start."""
        return [self.start_ok] * len(self.pair_s)

    def path_to(self, p: int) -> list[str]:
        inputs: list[str] = []
        while self.parent[p] >= 0:
            inputs.append(self.parent_input[p])  # type: ignore[arg-type]
            p = self.parent[p]
        inputs.reverse()
        return inputs


def _show(outputs: tuple[str, ...]) -> str:
    return ", ".join(outputs) if outputs else "nothing"


# -- the checker ----------------------------------------------------------------------------------
def check(
    source: Machine[Any],
    result: Machine[Any],
    *,
    max_states: int = DEFAULT_MAX_STATES,
    max_seconds: float | None = None,
    mode: str = "lockstep",
) -> Report:
    """Compare two deterministic machines; the five properties, each with a shortest
    counterexample when it fails (see the module docstring and docs/verification.md).

    Args:
        source: the machine whose behaviour is the reference.
        result: the machine that must behave the same.
        max_states: states explored per machine, and product pairs, before ``StateLimitError``.
        max_seconds: wall seconds before ``CheckerTimeLimitError``; ``None``: the limits in
            force (``fsmbt.limits.current().checker_max_seconds``).
        mode: the name the report gives the comparison.

    Raises:
        StateLimitError: past ``max_states`` (``CheckerTimeLimitError`` past ``max_seconds``).
    """
    return check_witnessed(
        source, result, max_states=max_states, max_seconds=max_seconds, mode=mode
    )[0]


def check_witnessed(
    source: Machine[Any],
    result: Machine[Any],
    *,
    max_states: int = DEFAULT_MAX_STATES,
    max_seconds: float | None = None,
    mode: str = "lockstep",
) -> tuple[Report, Witness]:
    """``check``, and the explored machines and product kept as a ``Witness`` (the stuff of a
    certificate, ``fsmbt.verify.certificate``). Same arguments, same cost; the witness holds
    the tables the check built anyway (O(|S| + |R| + |P|) memory while it is kept)."""
    seconds = limits.current().checker_max_seconds if max_seconds is None else max_seconds
    collecting = gc.isenabled()
    gc.disable()  # millions of small, acyclic objects: the cyclic GC would rescan them all
    try:
        return _check(source, result, max_states, _Deadline(seconds), mode)
    finally:
        if collecting:
            gc.enable()


@dataclass
class Witness:
    """What one native check explored: both machines' tables and the product's pairs.

    For an equivalent pair, the product's pairs are a relation closed under both machines'
    steps from their starts on which outputs, statuses and offered inputs agree: a proof of
    equivalence that ``fsmbt.verify.certificate`` checks with one machine step per edge.
    """

    source: Machine[Any]
    result: Machine[Any]
    src: _Explored
    res: _Explored
    product: _Product
    report: Report

    def to_data(self) -> dict[str, Any]:
        """The tables as plain data (JSON-ready): outputs, per machine its start outputs,
        states (description, status, offered-input set), input sets and edges (in the order the
        search met them, which fixes every state's id), and the relation as pairs of ids."""
        product = self.product
        return {
            "outputs": [list(v) for v in self.src.outputs.values],
            "machines": {
                "source": _machine_data(self.src),
                "result": _machine_data(self.res),
            },
            "relation": [[s, r] for s, r in zip(product.pair_s, product.pair_r, strict=True)],
        }


def _machine_data(explored: _Explored) -> dict[str, Any]:
    describe = explored.machine.describe
    return {
        "start_outputs": explored.start_outputs,
        "input_sets": [list(key) for key in explored.input_sets],
        "states": [
            [describe(state), explored.status[x], explored.offered[x]]
            for x, state in enumerate(explored.states)
        ],
        "edges": [
            [[symbol, nxt, out] for symbol, (nxt, out) in row.items()] for row in explored.edges
        ],
    }


def _check(
    source: Machine[Any], result: Machine[Any], max_states: int, deadline: _Deadline, mode: str
) -> tuple[Report, Witness]:
    started = time.perf_counter()
    outputs = _Interner()
    src = _Explored(source, outputs, max_states, "source", deadline)
    res = _Explored(result, outputs, max_states, "result", deadline)
    explored = time.perf_counter()
    product = _Product(src, res, max_states, deadline)
    product.run()
    faithful = product.faithful()
    reachability = _reachability(src, res, product, faithful)
    if reachability is not None:
        product.violate(REACHABILITY, reachability)

    report = Report(
        engine="native",
        source=getattr(source, "name", "source"),
        result=getattr(result, "name", "result"),
        mode=mode,
    )
    for name in PROPERTIES:
        violation = product.first.get(name)
        if violation is None:
            report.properties[name] = PropertyResult(name, True, _passed_detail(name, src, product))
            continue
        inputs = product.path_to(violation.pair)
        if violation.symbol is not None:
            inputs.append(violation.symbol)
        inputs.extend(violation.extension)
        trace = replay(source, result, inputs).steps
        count = product.counts[name]
        more = f" ({count} violations in all)" if count > 1 else ""
        report.properties[name] = PropertyResult(name, False, violation.detail + more, trace)
    finished = time.perf_counter()
    report.stats = {
        "source_states": len(src.states),
        "result_states": len(res.states),
        "product_states": len(product.pair_s),
        "product_edges": product.edges,
        "faithful_states": sum(faithful),
        "explore_seconds": round(explored - started, 6),
        "product_seconds": round(finished - explored, 6),
        "seconds": round(finished - started, 6),
    }
    return report, Witness(source, result, src, res, product, report)


@dataclass(frozen=True)
class FrontierPoint:
    """One place where the two machines part: a faithful product pair and what breaks there.

    Attributes:
        property: the property the point violates (one of ``PROPERTIES``, never reachability).
        source_state, result_state: the two machines' states in the pair (both reached on one
            shortest input sequence on which they agreed at every step).
        symbol: the input on which they part, ``None`` when the pair itself differs (the
            start, or one side stuck).
        detail: the checker's sentence for it.
        witness: a shortest input sequence from the start that shows the difference (the path
            to the pair, ``symbol``, and for a stuck side the live side's way to act).
    """

    property: str
    source_state: Hashable
    result_state: Hashable
    symbol: str | None
    detail: str
    witness: tuple[str, ...]


@dataclass
class Frontier:
    """Every distinguishing frontier point of two machines, in breadth-first order."""

    points: list[FrontierPoint]
    stats: dict[str, Any]


def frontier(
    source: Machine[Any],
    result: Machine[Any],
    *,
    max_states: int = DEFAULT_MAX_STATES,
    max_seconds: float | None = None,
) -> Frontier:
    """All the points where ``source`` and ``result`` part, each with a shortest witness.

    The same product as ``check`` (one kernel): it explores agreeing steps only, so every
    violation it meets is a *frontier* point - the first step on some run where the two
    differ. ``check`` keeps the first point per property; this keeps them all, in
    breadth-first order (so the first point of any group of points is a shortest one). The
    reachability property is a consequence of the others (a state only reached after the runs
    part) and adds no point. A point where two properties fail on the same step is listed once.
    Costs: as ``check``, plus O(depth) per point for its witness.

    Raises:
        StateLimitError: past ``max_states`` (``CheckerTimeLimitError`` past ``max_seconds``).
    """
    seconds = limits.current().checker_max_seconds if max_seconds is None else max_seconds
    collecting = gc.isenabled()
    gc.disable()
    try:
        started = time.perf_counter()
        deadline = _Deadline(seconds)
        outputs = _Interner()
        src = _Explored(source, outputs, max_states, "source", deadline)
        res = _Explored(result, outputs, max_states, "result", deadline)
        product = _Product(src, res, max_states, deadline)
        product.every = []
        product.run()
        seen: set[tuple[int, str | None]] = set()
        points: list[FrontierPoint] = []
        for name, violation in product.every:
            key = (violation.pair, violation.symbol)
            if key in seen:
                continue
            seen.add(key)
            witness = product.path_to(violation.pair)
            if violation.symbol is not None:
                witness.append(violation.symbol)
            witness.extend(violation.extension)
            points.append(
                FrontierPoint(
                    name,
                    src.states[product.pair_s[violation.pair]],
                    res.states[product.pair_r[violation.pair]],
                    violation.symbol,
                    violation.detail,
                    tuple(witness),
                )
            )
        stats = {
            "source_states": len(src.states),
            "result_states": len(res.states),
            "product_states": len(product.pair_s),
            "product_edges": product.edges,
            "seconds": round(time.perf_counter() - started, 6),
        }
        return Frontier(points, stats)
    finally:
        if collecting:
            gc.enable()


def _reachability(
    src: _Explored, res: _Explored, product: _Product, faithful: list[bool]
) -> _Violation | None:
    """Source states, and result states, reachable on their own but never in a faithful pair.

    The counterexample is the shortest path to the first such state in that machine alone
    (replayed on both, it must differ somewhere: had every step agreed, the pair would be
    faithful); of the two sides the shorter wins. A ``follows_environment`` result's own
    inputs are not the environment's, so only the source side counts for it.
    """
    source_ok = [False] * len(src.states)
    result_ok = [False] * len(res.states)
    for p, ok in enumerate(faithful):
        if ok:
            source_ok[product.pair_s[p]] = True
            result_ok[product.pair_r[p]] = True
    unmatched_source = [x for x, ok in enumerate(source_ok) if not ok]
    unmatched_result = (
        [] if res.follows_environment else [x for x, ok in enumerate(result_ok) if not ok]
    )
    if not unmatched_source and not unmatched_result:
        return None
    parts = []
    if unmatched_source:
        parts.append(
            f"{len(unmatched_source)} source state(s) never reached with matching "
            f"behaviour: {_names(src, unmatched_source)}"
        )
    if unmatched_result:
        parts.append(
            f"{len(unmatched_result)} result state(s) reachable only through behaviour "
            f"the source does not have: {_names(res, unmatched_result)}"
        )
    paths = []
    if unmatched_source:
        paths.append(src.path_to(unmatched_source[0]))
    if unmatched_result:
        paths.append(res.path_to(unmatched_result[0]))
    # replayed from the start: anchored at the product's start pair
    return _Violation(0, None, "; ".join(parts), min(paths, key=len))


def _names(machine: _Explored, ids: list[int], limit: int = 5) -> str:
    shown: dict[str, None] = {}
    for x in ids:
        shown.setdefault(machine.machine.describe(machine.states[x]), None)
        if len(shown) > limit:
            break
    names = list(shown)
    return ", ".join(names[:limit]) + (", ..." if len(names) > limit else "")


def _passed_detail(name: str, src: _Explored, product: _Product) -> str:
    pairs = len(product.pair_s)
    return {
        REACHABILITY: f"all {len(src.states)} source states reached with matching behaviour",
        COMPLETENESS: f"every source step matched in {pairs} product states",
        NO_ADDITIONAL_BEHAVIOR: "the result never does or accepts more than the source",
        DEADLOCK_ABSENCE: "no product state where only one side is stuck",
        TERMINATION_CONSISTENCY: f"statuses agree in all {pairs} product states",
    }[name]
