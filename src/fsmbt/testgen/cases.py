"""Test cases from a specification: input sequences covering every transition, with the
observations expected (docs/testgen.md, 'The cases').

The specification is read as its leaf-execution machine ([semantics.md] §4: a BT as
``LeafMachine``, an FSM as ``FSMLeafMachine``, the leaf <-> state mapping): a state is the leaf
about to be ticked, an input the outcome that leaf returns, the outputs the next leaf's label
and, when the tree finishes, the root's result.

Coverage target: every *transition* of the specification - an FSM: every (state, outcome) its
transitions name (only those outcomes are scripted: the FSM does not say which leaves are
conditions); a BT: every outcome of every leaf at every place it is reached, i.e. every
(leaf, outcome) edge of the explored machine, grouped by (leaf path, outcome) - which also
drives every inner node through the outcomes its children can give it. Greedy: the targets in
breadth-first order; for the first one not yet covered, the shortest input sequence from the
start that takes it, continued by the shortest way to the end of the run (the root's result)
when there is one; every transition on that sequence is then covered. So the number of cases is
at most the number of targets, usually far fewer.

A case is a list of steps ``(label, outcome)`` - the leaf the tree must tick and the outcome the
test scripts for it - and the root's result expected at its end, or, when the run does not end
(a tree that never returns), the label of the leaf ticked next (``then``). Costs: one breadth-first exploration of the machine (bounded by
``max_states``), O(states x inputs) for the shortest ways to an end, O(cases x length).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable
from dataclasses import dataclass, field
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import LimitError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.leaf_machine import LeafMachine
from fsmbt.semantics.machine import FSMLeafMachine

RESULTS = ("SUCCESS", "FAILURE")
#: States of the specification's machine explored at most.
DEFAULT_MAX_STATES = 200_000


@dataclass
class Case:
    """One generated test: ``steps`` are (leaf label, scripted outcome); ``result`` the root's
    result expected at the end, or ``None``."""

    name: str
    steps: list[tuple[str, str]]
    result: str | None
    then: str | None = None
    covers: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "steps": [list(s) for s in self.steps],
            "result": self.result,
            "then": self.then,
        }


@dataclass
class Suite:
    """The cases and what they cover."""

    cases: list[Case]
    targets: int
    covered: int

    @property
    def steps(self) -> int:
        return sum(len(c.steps) for c in self.cases)


def spec_machine(spec: FSM | BTDocument) -> Any:
    """The specification's leaf-execution machine (the run ends at the root's result)."""
    if isinstance(spec, BTDocument):
        return LeafMachine(spec, loop=False, generic=True)
    return FSMLeafMachine(spec, loop=False)


def _ident(machine: Any, state: Any) -> str:
    if isinstance(machine, LeafMachine):
        leaf = machine.leaf(state)
        return leaf.path if leaf is not None else str(state)
    return str(state)


def generate(spec: FSM | BTDocument, *, max_states: int = DEFAULT_MAX_STATES) -> Suite:
    """The cases covering every transition of ``spec`` (see the module docstring).

    Raises:
        LimitError: the machine has more than ``max_states`` states.
    """
    machine = spec_machine(spec)
    inputs = machine.inputs
    if isinstance(machine, FSMLeafMachine):
        # an FSM state's leaf may return what its transitions name (the FSM does not say which
        # leaves are conditions): only those are scripted
        named: dict[str, list[str]] = {}
        for t in machine.fsm.transitions:
            if t.event is not None and t.event not in named.setdefault(t.source, []):
                named[t.source].append(t.event)

        def inputs(state: Any) -> list[str]:
            return [o for o in machine.inputs(state) if o in named.get(str(state), [])]

    start, start_out = machine.start()
    index: dict[Hashable, int] = {start: 0}
    states: list[Hashable] = [start]
    parent: list[tuple[int, str, tuple[str, ...]] | None] = [None]
    edges: list[list[tuple[str, int, tuple[str, ...]]]] = []
    cursor = 0
    while cursor < len(states):
        state = states[cursor]
        row: list[tuple[str, int, tuple[str, ...]]] = []
        for outcome in inputs(state):
            nxt, out = machine.step(state, outcome)
            found = index.get(nxt)
            if found is None:
                if len(states) >= max_states:
                    raise LimitError(
                        f"the specification has more than {max_states} leaf-execution states"
                    )
                found = len(states)
                index[nxt] = found
                states.append(nxt)
                parent.append((cursor, outcome, tuple(out)))
            row.append((outcome, found, tuple(out)))
        edges.append(row)
        cursor += 1
    # shortest way from each state to an end (a state with no inputs), reverse BFS
    to_end: list[tuple[str, int, tuple[str, ...]] | None] = [None] * len(states)
    dist = [-1] * len(states)
    reverse: list[list[tuple[int, str, tuple[str, ...]]]] = [[] for _ in states]
    queue: deque[int] = deque()
    for x, row in enumerate(edges):
        if not row:
            dist[x] = 0
            queue.append(x)
        for outcome, y, out in row:
            reverse[y].append((x, outcome, out))
    while queue:
        y = queue.popleft()
        for x, outcome, out in reverse[y]:
            if dist[x] < 0:
                dist[x] = dist[y] + 1
                to_end[x] = (outcome, y, out)
                queue.append(x)
    targets: dict[tuple[str, str], tuple[int, str]] = {}
    for x, row in enumerate(edges):
        for outcome, _y, _out in row:
            targets.setdefault((_ident(machine, states[x]), outcome), (x, outcome))
    covered: set[tuple[str, str]] = set()
    cases: list[Case] = []
    first_label = start_out[-1] if start_out else ""
    for key, (x, outcome) in targets.items():
        if key in covered:
            continue
        path: list[tuple[int, str, tuple[str, ...]]] = []  # (from state, outcome, outputs)
        y = x
        while parent[y] is not None:
            p, o, out = parent[y]  # type: ignore[misc]
            path.append((p, o, out))
            y = p
        path.reverse()
        y, last = next((z, o) for o2, z, o in edges[x] if o2 == outcome)
        path.append((x, outcome, last))
        while to_end[y] is not None:
            o, z, out2 = to_end[y]  # type: ignore[misc]
            path.append((y, o, out2))
            y = z
        steps: list[tuple[str, str]] = []
        label = first_label
        result: str | None = None
        for frm, o, outs in path:
            covered.add((_ident(machine, states[frm]), o))
            steps.append((label, o))
            results = [s for s in outs if s in RESULTS]
            if results:
                result = results[-1]
            labels = [s for s in outs if s not in RESULTS]
            if labels:
                label = labels[-1]
        then = None if result is not None else label
        name = f"case_{len(cases) + 1:03d}"
        cases.append(Case(name, steps, result, then, [f"{key[0]}:{key[1]}"]))
    return Suite(cases, len(targets), len(covered))
