"""A certificate unit's tables built from transitions a search already made, without a second
search (issue 27; docs/verification.md §6, "Certificates").

Why: the per-node check (``verify/pernode.py``) explores each local problem as a lockstep
product of its two sides. The certificate needs the same thing the native checker's
``Witness.to_data`` gives - each side's explored table and the relation - and running the
native checker a second time on the same problem doubled the proof's time. Every transition
the certificate lists was computed by the product already: the search hands its steps here
(``Rows``) and this module only numbers them.

Rules (the format ``fsmbt.verify.certificate`` replays, its module docstring step 3):

- a side's states get ids breadth first from its start, each state's edges in the order of its
  offered inputs, a state met for the first time taking the next id: exactly the numbering the
  checker reproduces when it steps the rebuilt machine along the listed edges;
- every state's row must list every offered input (the local machines explore them all); a
  state whose row is missing or short is a bug of the caller, refused with ``ValueError``;
- the relation is the product's pairs, renamed to the two sides' ids.

Nothing here is trusted by the checker: it rebuilds both machines from the models and replays
every edge. Cost: O(edges) dictionary look-ups, no machine step.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterable
from dataclasses import dataclass
from typing import Any

#: One side's transitions: state -> input -> (next state, outputs).
Rows = dict[Hashable, dict[str, tuple[Hashable, tuple[str, ...]]]]


@dataclass(frozen=True)
class Side:
    """What one side's table says of a state besides its edges: its description, its status and
    its offered inputs (in the order the edges are listed)."""

    describe: Callable[[Any], str]
    status: Callable[[Any], str]
    inputs: Callable[[Any], tuple[str, ...]]


class _Outputs:
    """Output tuples interned as ids shared by both tables."""

    def __init__(self) -> None:
        self.index: dict[tuple[str, ...], int] = {}
        self.values: list[tuple[str, ...]] = []

    def id(self, value: tuple[str, ...]) -> int:
        found = self.index.get(value)
        if found is None:
            found = self.index[value] = len(self.values)
            self.values.append(value)
        return found


def _table(
    start: Hashable, rows: Rows, side: Side, outputs: _Outputs, role: str
) -> tuple[dict[str, Any], dict[Hashable, int]]:
    """One side's table (``Witness.to_data``'s machine form) and its state ids."""
    states: list[Hashable] = [start]
    index: dict[Hashable, int] = {start: 0}
    sets: dict[tuple[str, ...], int] = {}
    listed_states: list[list[Any]] = []
    edges: list[list[list[Any]]] = []
    x = 0
    while x < len(states):
        state = states[x]
        x += 1
        offered = side.inputs(state)
        set_id = sets.setdefault(offered, len(sets))
        listed_states.append([side.describe(state), side.status(state), set_id])
        row = rows.get(state)
        if row is None or len(row) != len(offered):
            raise ValueError(f"the {role} side's state {x - 1} was not fully explored")
        listed: list[list[Any]] = []
        for symbol in offered:
            nxt, out = row[symbol]
            found = index.get(nxt)
            if found is None:
                found = index[nxt] = len(states)
                states.append(nxt)
            listed.append([symbol, found, outputs.id(out)])
        edges.append(listed)
    data = {
        "start_outputs": outputs.id(()),
        "input_sets": [list(key) for key in sets],
        "states": listed_states,
        "edges": edges,
    }
    return data, index


@dataclass
class TableWitness:
    """A certificate unit's proof (the shape ``native.Witness.to_data`` gives), built from rows."""

    data: dict[str, Any]

    def to_data(self) -> dict[str, Any]:
        return self.data


def witness_from_rows(
    starts: tuple[Hashable, Hashable],
    rows: tuple[Rows, Rows],
    sides: tuple[Side, Side],
    pairs: Iterable[tuple[Hashable, Hashable]],
) -> TableWitness:
    """The two sides' tables (source first) and the relation ``pairs`` in their ids. Both
    machines start with no output (the local machines' contract).

    Raises:
        ValueError: a state reached along the rows has no full row, or a pair names a state
            neither table reaches (a bug of the search that recorded them).
    """
    outputs = _Outputs()
    outputs.id(())
    source, src_ids = _table(starts[0], rows[0], sides[0], outputs, "source")
    result, res_ids = _table(starts[1], rows[1], sides[1], outputs, "result")
    try:
        relation = [[src_ids[s], res_ids[r]] for s, r in pairs]
    except KeyError:
        raise ValueError("a related pair names a state its side never reaches") from None
    return TableWitness(
        {
            "outputs": [list(v) for v in outputs.values],
            "machines": {"source": source, "result": result},
            "relation": relation,
        }
    )
