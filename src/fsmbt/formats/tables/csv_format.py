"""Transition tables in CSV (the paper's "table" input); the row logic is shared with Markdown.

A table has a header row naming the columns ``source, event, target`` and optionally
``action`` (any order, any case, surrounding spaces ignored). Meaning (docs/semantics.md,
'Models'; docs/formats/tables.md):

- no initial-state column: the first row's source is the initial state, unless
  ``ReadContext.options["initial"]`` names another;
- a state with no outgoing transition is final (a table cannot mark finals otherwise);
- the ``action`` cell gives the action of the row's TARGET state (the action runs on entering
  it); an empty cell says nothing, and a state no row gives an action to runs its own name.
  Two different actions for one state is an error naming both rows;
- an empty ``event`` cell is an eventless (completion) transition, ``null`` in JSON.

Writers produce the same shape, initial state's rows first, and refuse (``UnsupportedError``)
what a table cannot say: hierarchy, a start pseudo-state, final states with transitions,
non-final dead ends, states no row mentions, or an action on a state no row enters.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model import Model
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State

REQUIRED_COLUMNS = ("source", "event", "target")
OPTIONAL_COLUMNS = ("action",)


@dataclass(frozen=True)
class TableRow:
    """One data row with the line it came from (1-based, for messages)."""

    line: int
    cells: tuple[str, ...]


def column_index(header: Sequence[str], ctx: ReadContext, line: int) -> dict[str, int]:
    """Map column name -> position; errors name the missing or unknown column."""
    names = [cell.strip().lower() for cell in header]
    index: dict[str, int] = {}
    for position, name in enumerate(names):
        if name not in REQUIRED_COLUMNS + OPTIONAL_COLUMNS:
            raise InputError(
                f"unknown column '{header[position].strip()}' in the header "
                f"(columns: source, event, target[, action])",
                location=ctx.location(line),
            )
        if name in index:
            raise InputError(
                f"column '{name}' appears twice in the header", location=ctx.location(line)
            )
        index[name] = position
    missing = [c for c in REQUIRED_COLUMNS if c not in index]
    if missing:
        raise InputError(
            f"header lacks column(s) {', '.join(missing)} "
            f"(columns: source, event, target[, action])",
            location=ctx.location(line),
        )
    return index


def is_header(cells: Sequence[str]) -> bool:
    """Does this row name at least the three required columns (for content sniffing)?"""
    names = {cell.strip().lower() for cell in cells}
    return set(REQUIRED_COLUMNS) <= names


def fsm_from_rows(
    header: Sequence[str], header_line: int, rows: Iterable[TableRow], ctx: ReadContext
) -> FSM:
    """Build the FSM a transition table describes (rules in the module docstring). O(rows)."""
    index = column_index(header, ctx, header_line)
    name = ctx.path.stem if ctx.path is not None else "fsm"
    fsm = FSM(name=name)
    action_of: dict[str, tuple[str, int]] = {}  # state -> (action, line that gave it)
    first_source: str | None = None
    for row in rows:
        if len(row.cells) != len(header):
            raise InputError(
                f"row has {len(row.cells)} cells, the header has {len(header)}",
                location=ctx.location(row.line),
            )
        cell = {column: row.cells[position].strip() for column, position in index.items()}
        source, event, target = cell["source"], cell["event"], cell["target"]
        for column in ("source", "target"):
            if not cell[column]:
                raise InputError(f"empty '{column}' cell", location=ctx.location(row.line))
        for state_name in (source, target):
            if state_name not in fsm.states:
                fsm.add_state(State(state_name, action=state_name, location=ctx.location(row.line)))
        if first_source is None:
            first_source = source
        action = cell.get("action", "")
        if action:
            previous = action_of.get(target)
            if previous is not None and previous[0] != action:
                raise InputError(
                    f"state '{target}' gets action '{action}' here but '{previous[0]}' on line "
                    f"{previous[1]}; the action column is the target state's action",
                    location=ctx.location(row.line),
                    element=target,
                )
            action_of[target] = (action, row.line)
            fsm.states[target].action = action
        fsm.add_transition(source, event or None, target, location=ctx.location(row.line))
    if first_source is None:
        raise InputError("the table has a header but no transitions", location=ctx.location())
    initial = ctx.options.get("initial")
    if initial is not None:
        if str(initial) not in fsm.states:
            raise InputError(
                f"initial state '{initial}' (from the option) is not in the table",
                location=ctx.location(),
            )
        fsm.initial = str(initial)
    else:
        fsm.initial = first_source
    sources = {t.source for t in fsm.transitions}
    for state in fsm.states.values():
        state.final = state.name not in sources
    return fsm


def rows_from_fsm(model: Model, table: str) -> tuple[list[str], list[list[str]]]:
    """Header and rows for ``model``: transitions in model order, except that the initial
    state's come first when they do not already. Refuses, with the reason, every FSM a table cannot express exactly."""
    if not isinstance(model, FSM):
        raise UnsupportedError(f"a {table} transition table holds an FSM, not a behavior tree")
    fsm = model
    if fsm.is_hierarchical:
        raise UnsupportedError(
            f"a {table} transition table cannot hold composite states; "
            "flatten the machine first (e.g. write JSON or Mermaid)"
        )
    if fsm.start_name is not None or fsm.initial_event is not None:
        raise UnsupportedError(
            f"a {table} transition table cannot mark a start pseudo-state "
            f"('{fsm.start_name}' --{fsm.initial_event}-->); use JSON, "
            "YAML or the paper's XML"
        )
    if fsm.initial is None or fsm.initial not in fsm.states:
        raise UnsupportedError(f"a {table} transition table needs an initial state")
    sources = {t.source for t in fsm.transitions}
    targets = {t.target for t in fsm.transitions}
    if not fsm.transitions:
        raise UnsupportedError(f"a {table} transition table needs at least one transition")
    if not fsm.outgoing(fsm.initial):
        raise UnsupportedError(
            f"initial state '{fsm.initial}' has no outgoing transition, so "
            "a table cannot put it first"
        )
    for state in fsm.states.values():
        if state.final == (state.name in sources):
            why = (
                "is final but has outgoing transitions"
                if state.final
                else "has no outgoing transition but is not final"
            )
            raise UnsupportedError(
                f"state '{state.name}' {why}; in a table a state is final "
                "exactly when it has no outgoing transition"
            )
        if state.name not in sources | targets:
            raise UnsupportedError(f"state '{state.name}' has no transition, so no row names it")
        if state.action != state.name and state.name not in targets:
            raise UnsupportedError(
                f"state '{state.name}' has action '{state.action}' but no "
                "transition enters it, and the action column gives the "
                "target's action"
            )
        if state.action is None:
            raise UnsupportedError(f"state '{state.name}' has no action; a table cannot say so")
    with_action = any(s.action != s.name for s in fsm.states.values())
    header = ["source", "event", "target"] + (["action"] if with_action else [])
    ordered = list(fsm.transitions)
    if ordered[0].source != fsm.initial:  # the first row's source is the initial state
        ordered.sort(key=lambda t: t.source != fsm.initial)  # stable: otherwise as given
    rows = []
    for t in ordered:
        row = [t.source, t.event or "", t.target]
        if with_action:
            target_action = fsm.states[t.target].action or ""  # never None: checked above
            row.append(target_action if target_action != t.target else "")
        rows.append(row)
    return header, rows


def read_csv(text: str, ctx: ReadContext) -> Model:
    reader = csv.reader(io.StringIO(text, newline=""), skipinitialspace=True)
    header: list[str] | None = None
    header_line = 0
    rows: list[TableRow] = []
    try:
        for record in reader:
            line = reader.line_num  # the line the record ends on (quoted cells may span lines)
            if not any(cell.strip() for cell in record) or record[0].lstrip().startswith("#"):
                continue  # blank lines and '#' comment lines
            if header is None:
                header, header_line = record, line
                continue
            rows.append(TableRow(line, tuple(record)))
    except csv.Error as exc:
        raise InputError(f"invalid CSV: {exc}", location=ctx.location(reader.line_num)) from None
    if header is None:
        raise InputError("empty table: no header row", location=ctx.location())
    return fsm_from_rows(header, header_line, rows, ctx)


def write_csv(model: Model) -> str:
    header, rows = rows_from_fsm(model, "CSV")
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return out.getvalue()


def _sniff(text: str) -> bool:
    """The first non-blank, non-comment line is a header naming source, event and target."""
    for line in text[:4096].splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        return "," in line and is_header(line.split(","))
    return False


register(
    Format(
        "csv",
        (".csv",),
        frozenset({"fsm"}),
        "transition table, CSV (source,event,target[,action])",
        read_csv,
        write_csv,
        _sniff,
        priority=40,
        cannot_hold="composite or parallel states, a start pseudo-state, final states "
        "with transitions, states without an action",
    )
)
