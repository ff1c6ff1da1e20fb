"""Replay a recorded execution through a model's semantics (docs/conform.md, 'The replay';
docs/semantics.md §4 'The leaf-execution machine' and §4b, whose rules this implements).

The model is read as its leaf-execution machine with the root ticked again after it returns
(``loop``): a BT as ``LeafMachine`` (the faithful interpreter), an FSM as ``FSMLeafMachine``
(the leaf <-> state mapping: a state is the leaf about to be ticked, named by its action). The
log is a sequence of node status transitions; the replay reads it in order:

- a leaf's transition to SUCCESS, FAILURE or RUNNING is a tick of that leaf with that outcome:
  it must be the leaf the model ticks next (a BT: the same node, by the log's UID -> model node
  mapping; an FSM: the same label), with an outcome the model allows there (a condition never
  returns RUNNING); the model then takes that outcome;
- a RUNNING leaf ticked again and still RUNNING changes no status, so it leaves no transition:
  when the log goes on with another leaf while the model expects the leaf that last returned
  RUNNING, the replay gives it RUNNING again (never twice into the same state);
- the root's transition to SUCCESS or FAILURE must come exactly when the model's tree returns
  that result, before the next leaf tick;
- transitions to IDLE (halts, resets) and those of inner nodes are not verdicts: they are
  counted for the node-outcome coverage. The tree the log embeds only maps UIDs to nodes.

The UID -> model node mapping: the model node at the same path when its label or type is the
same, else the model node with that label whose path shares the longest prefix with it, else
none (ticking such a leaf is a deviation: the model has no such leaf). Internal leaves of the
model (``AlwaysSuccess``, ``Script``...) are not ticked by the machine and are skipped.

The first deviation stops the replay of that log: its transition number, time stamp, node,
what happened and what the model allows there. Coverage: states (BT: leaves ticked; FSM:
states entered), transitions (BT: leaf outcomes; FSM: transitions taken) and node outcomes (BT:
every node's SUCCESS/FAILURE/RUNNING seen, conditions two, the rest three).

Costs: O(transitions) plus one machine step per distinct (state, outcome) (memoised).
"""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from fsmbt.conform.log import (
    FAILURE,
    IDLE,
    OUTCOMES,
    RUNNING,
    SKIPPED,
    STATUS_NAMES,
    SUCCESS,
    LoggedNode,
    RecordedLog,
)
from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError, SourceLocation
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import CompiledNode
from fsmbt.semantics.leaf_machine import LeafMachine
from fsmbt.semantics.machine import FSMLeafMachine

RESULTS = ("SUCCESS", "FAILURE")
#: RUNNING re-ticks assumed in a row before the replay calls the next leaf a deviation.
MAX_SILENT_RETICKS = 64


@dataclass
class Deviation:
    """Where a log first leaves the model.

    Attributes:
        index: the transition's number in the log (1-based).
        time_us: its time stamp, microseconds since the log's start.
        absolute_us: microseconds since the epoch (``None`` when the log has no clock).
        node: the logged node (``label@path`` in the log's tree).
        happened: what the log records.
        allowed: what the model allows there.
    """

    index: int
    time_us: int
    absolute_us: int | None
    node: str
    happened: str
    allowed: str

    def text(self) -> str:
        """One line."""
        stamp = f"t=+{self.time_us / 1e6:.6f} s"
        if self.absolute_us:
            when = datetime.fromtimestamp(self.absolute_us / 1e6, tz=UTC)
            stamp += f" ({when.isoformat(timespec='microseconds')})"
        return (
            f"transition #{self.index}, {stamp}, node {self.node}: {self.happened}; "
            f"the model allows: {self.allowed}"
        )


@dataclass
class Coverage:
    """What the logs reached, as (seen, total) pairs; ``None``: not defined for the model."""

    states: tuple[int, int]
    transitions: tuple[int, int]
    node_outcomes: tuple[int, int] | None

    @staticmethod
    def share(pair: tuple[int, int] | None) -> str:
        if pair is None:
            return "n/a"
        seen, total = pair
        return f"{seen}/{total} ({100 * seen / total:.0f}%)" if total else "0/0"

    def text(self) -> str:
        return (
            f"coverage: states {self.share(self.states)}, transitions "
            f"{self.share(self.transitions)}, node outcomes {self.share(self.node_outcomes)}"
        )


@dataclass
class LogResult:
    """One log replayed."""

    path: str
    format: str
    transitions: int
    leaf_ticks: int
    deviation: Deviation | None

    @property
    def conforms(self) -> bool:
        return self.deviation is None


class _Sink:
    """The coverage the logs reach, summed over every log of one model."""

    def __init__(self) -> None:
        self.states: set[Hashable] = set()
        self.transitions: set[tuple[Hashable, str]] = set()
        self.node_outcomes: set[tuple[str, int]] = set()


class Replayer:
    """Replays logs against one model; ``coverage()`` sums what every log reached."""

    def __init__(self, model: FSM | BTDocument) -> None:
        self.model = model
        self.machine: Any
        if isinstance(model, BTDocument):
            self.machine = LeafMachine(model, loop=True, generic=True)
            self.compiled: list[CompiledNode] = list(self.machine.tree.nodes)
            self.by_path = {node.path: node for node in self.compiled}
            self.by_label: dict[str, list[CompiledNode]] = {}
            for node in self.compiled:
                self.by_label.setdefault(node.label, []).append(node)
        else:
            self.machine = FSMLeafMachine(model, loop=True)
            self.compiled = []
        self.sink = _Sink()
        self._steps: dict[tuple[Hashable, str], tuple[Hashable, tuple[str, ...]]] = {}

    # -- mapping -------------------------------------------------------------------------------
    def map_node(self, node: LoggedNode) -> CompiledNode | None:
        """The model node a logged node stands for (BT models; see the module docstring)."""
        if not self.compiled:
            return None
        same = self.by_path.get(node.path)
        if same is not None and node.label in (same.label, same.type):
            return same
        named = self.by_label.get(node.label, [])
        if not named:
            return None
        return max(named, key=lambda c: (_common_prefix(c.path, node.path), -len(c.path)))

    def check_related(self, log: RecordedLog) -> None:
        """Refuse a log of another tree: none of its leaves is a leaf of the model.

        Raises:
            InputError: no leaf in common (located at the log).
        """
        leaves = [n for n in log.nodes.values() if n.leaf]
        if isinstance(self.model, BTDocument):
            known = sum(1 for n in leaves if self.map_node(n) is not None)
        else:
            labels = {self.machine.inner.entry_outputs(s)[-1:] for s in self.machine.fsm.states}
            known = sum(1 for n in leaves if (n.label,) in labels)
        if leaves and known == 0:
            raise InputError(
                f"the log records another tree: none of its {len(leaves)} leaves is in the model",
                location=SourceLocation(log.path),
            )

    # -- machine -------------------------------------------------------------------------------
    def _step(self, state: Hashable, outcome: str) -> tuple[Hashable, tuple[str, ...]]:
        key = (state, outcome)
        hit = self._steps.get(key)
        if hit is None:
            nxt, out = self.machine.step(state, outcome)
            hit = (nxt, tuple(out))
            self._steps[key] = hit
        return hit

    def _expected(self, state: Hashable, label: str) -> str:
        if isinstance(self.model, BTDocument):
            leaf = self.machine.leaf(state)
            return f"{leaf.label}@{leaf.path or 'root'}" if leaf is not None else str(state)
        return f"{label} (state {state})"

    def _matches(self, state: Hashable, label: str, logged: LoggedNode, mapped: Any) -> bool:
        if isinstance(self.model, BTDocument):
            leaf = self.machine.leaf(state)
            return mapped is not None and leaf is not None and leaf.path == mapped.path
        return logged.label == label

    # -- the replay ----------------------------------------------------------------------------
    def replay(self, log: RecordedLog) -> LogResult:
        """Replay ``log`` from the model's start (see the module docstring)."""
        self.check_related(log)
        machine, sink = self.machine, self.sink
        mapping = {uid: self.map_node(node) for uid, node in log.nodes.items()}
        state, out = machine.start()
        label = out[-1] if out else ""
        pending: str | None = None
        last_running: Hashable | None = None
        ticks = 0
        times, uids, statuses = log.times, log.uids, log.statuses
        nodes, root = log.nodes, log.root
        is_bt = isinstance(self.model, BTDocument)

        def deviation(i: int, node: LoggedNode, happened: str, allowed: str) -> LogResult:
            absolute = log.start_us + times[i] if log.start_us else None
            where = f"{node.label}@{node.path or 'root'}"
            found = Deviation(i + 1, times[i], absolute, where, happened, allowed)
            return LogResult(log.path, log.format, len(log), ticks, found)

        for i in range(len(uids)):
            uid, status = uids[i], statuses[i]
            logged = nodes[uid]
            mapped = mapping[uid]
            if mapped is not None and RUNNING <= status <= FAILURE:
                sink.node_outcomes.add((mapped.path, status))
            if uid == root and status in (SUCCESS, FAILURE) and not logged.leaf:
                name = STATUS_NAMES[status]
                if pending == name:
                    pending = None
                    continue
                allowed = (
                    f"the tree returns {pending}"
                    if pending is not None
                    else f"the tree is still running: it ticks {self._expected(state, label)} next"
                )
                return deviation(i, logged, f"the tree returned {name}", allowed)
            if not logged.leaf or status == IDLE:
                continue
            if is_bt and mapped is not None and not mapped.is_env_leaf:
                continue  # an internal leaf (AlwaysSuccess, Script...): not an input
            if status == SKIPPED:
                return deviation(
                    i, logged, "was skipped", f"the model ticks {self._expected(state, label)}"
                )
            outcome = OUTCOMES[status]
            if pending is not None:
                return deviation(
                    i,
                    logged,
                    f"ticked, returned {outcome}",
                    f"the tree returns {pending} first (the log has no such root result)",
                )
            silent: set[Hashable] = set()
            while not self._matches(state, label, logged, mapped):
                if (
                    last_running is not None
                    and self._ident(state) == last_running
                    and state not in silent
                    and len(silent) < MAX_SILENT_RETICKS
                    and "running" in machine.inputs(state)
                ):
                    silent.add(state)  # ticked again, still RUNNING: no transition logged
                    state, out = self._step(state, "running")
                    label = out[-1] if out else label
                    results = [o for o in out[:-1] if o in RESULTS]
                    if results:
                        pending = results[-1]
                        break
                    continue
                unknown = " (a node the model does not have)" if is_bt and mapped is None else ""
                return deviation(
                    i,
                    logged,
                    f"ticked, returned {outcome}{unknown}",
                    f"it ticks {self._expected(state, label)} next",
                )
            if pending is not None:
                return deviation(
                    i,
                    logged,
                    f"ticked, returned {outcome}",
                    f"the tree returns {pending} first (the log has no such root result)",
                )
            allowed = machine.inputs(state)
            if outcome not in allowed:
                return deviation(
                    i,
                    logged,
                    f"returned {outcome}",
                    f"{self._expected(state, label)} returns {' or '.join(allowed)}",
                )
            ident = self._ident(state)
            sink.states.add(ident)
            sink.transitions.add((ident, outcome))
            state, out = self._step(state, outcome)
            ticks += 1
            label = out[-1] if out else label
            results = [o for o in out[:-1] if o in RESULTS]
            if results:
                pending = results[-1]
            last_running = ident if outcome == "running" else None
        return LogResult(log.path, log.format, len(log), ticks, None)

    def _ident(self, state: Hashable) -> Hashable:
        """The leaf a machine state is about to tick: its path (BT) or the state (FSM)."""
        if isinstance(self.model, BTDocument):
            leaf = self.machine.leaf(state)
            return leaf.path if leaf is not None else state
        return state

    # -- coverage ------------------------------------------------------------------------------
    def coverage(self) -> Coverage:
        """What every log replayed so far reached."""
        sink = self.sink
        if isinstance(self.model, BTDocument):
            leaves = [n for n in self.compiled if n.is_env_leaf]
            outcomes = sum(2 if n.is_condition else 3 for n in leaves)
            every = sum(2 if n.kind is NodeKind.CONDITION else 3 for n in self.compiled)
            return Coverage(
                (len(sink.states), len(leaves)),
                (len(sink.transitions), outcomes),
                (len(sink.node_outcomes), every),
            )
        fsm = self.machine.fsm
        taken = {
            (s, e)
            for s, e in sink.transitions
            if any(t.source == s and t.event == e for t in fsm.transitions)
        }
        return Coverage(
            (len(sink.states), len(fsm.states)),
            (len(taken), len(fsm.transitions)),
            None,
        )


def _common_prefix(a: str, b: str) -> int:
    parts_a, parts_b = a.split("/"), b.split("/")
    n = 0
    for x, y in zip(parts_a, parts_b, strict=False):
        if x != y:
            break
        n += 1
    return n
