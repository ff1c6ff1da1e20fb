"""Transition tables as Markdown pipe tables; same columns and meaning as the CSV tables.

The reader takes the first pipe table whose header names ``source``, ``event`` and ``target``
(text around it, headings and other tables before it are ignored, which lets a README hold the
table). A ``|`` inside a cell is written ``\\|``; cells may be wrapped in backticks, which are
removed. Rows and errors are numbered by the file's lines. Rules: ``tables.csv_format`` module docstring
and docs/formats/tables.md.
"""

from __future__ import annotations

import re

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.formats.tables.csv_format import TableRow, fsm_from_rows, is_header, rows_from_fsm
from fsmbt.model import Model
from fsmbt.model.errors import InputError

_SEPARATOR_CELL = re.compile(r"^\s*:?-{1,}:?\s*$")
_UNESCAPED_PIPE = re.compile(r"(?<!\\)\|")


def split_row(line: str) -> list[str]:
    """Cells of one pipe-table line (leading/trailing pipes optional, ``\\|`` escapes a pipe)."""
    body = line.strip()
    if body.startswith("|"):
        body = body[1:]
    if body.endswith("|") and not body.endswith("\\|"):
        body = body[:-1]
    cells = [c.replace("\\|", "|").strip() for c in _UNESCAPED_PIPE.split(body)]
    return [c[1:-1] if len(c) >= 2 and c[0] == c[-1] == "`" else c for c in cells]


def _is_separator(line: str) -> bool:
    cells = split_row(line)
    return bool(cells) and all(_SEPARATOR_CELL.match(c) for c in cells)


def _is_table_line(line: str) -> bool:
    return "|" in line and bool(line.strip())


def read_md(text: str, ctx: ReadContext) -> Model:
    lines = text.splitlines()
    for number, line in enumerate(lines):
        if not _is_table_line(line) or not is_header(split_row(line)):
            continue
        if number + 1 >= len(lines) or not _is_separator(lines[number + 1]):
            raise InputError(
                "a table header must be followed by a separator row like '|---|---|---|'",
                location=ctx.location(number + 2),
            )
        header = split_row(line)
        rows = []
        for row_number in range(number + 2, len(lines)):
            row_line = lines[row_number]
            if not _is_table_line(row_line):
                break  # the table ends at the first line that is not a table row
            rows.append(TableRow(row_number + 1, tuple(split_row(row_line))))
        return fsm_from_rows(header, number + 1, rows, ctx)
    raise InputError(
        "no Markdown table with columns source | event | target found", location=ctx.location()
    )


def _escape(cell: str) -> str:
    return cell.replace("|", "\\|")


def write_md(model: Model) -> str:
    header, rows = rows_from_fsm(model, "Markdown")
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(_escape(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def _sniff(text: str) -> bool:
    """A pipe-table header naming source, event and target among the first lines."""
    for line in text[:4096].splitlines()[:40]:
        if line.lstrip().startswith("|") and is_header(split_row(line)):
            return True
    return False


register(
    Format(
        "md",
        (".md", ".markdown"),
        frozenset({"fsm"}),
        "transition table, Markdown pipe table (source | event | target [| action])",
        read_md,
        write_md,
        _sniff,
        priority=41,
        cannot_hold="composite or parallel states, a start pseudo-state, final states "
        "with transitions, states without an action",
    )
)
