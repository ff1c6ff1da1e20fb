"""BehaviorTree.CPP's ``SqliteLogger`` log (``.db3``), read as 4.8.2 writes it
(src/loggers/bt_sqlite_logger.cpp; docs/conform.md, 'The .db3 format').

A SQLite 3 database with three tables. ``Definitions(session_id, date, xml_tree)``: one row per
recording session (a logger opened with ``append`` adds a session to the file), ``xml_tree`` the
tree as ``WriteTreeToXML(tree, add_metadata=true, builtin_models=true)`` - the same XML a
``.btlog`` embeds, every node with its ``_uid``. ``Nodes(session_id, fullpath, node_uid)``: the
session's nodes. ``Transitions(timestamp, session_id, node_uid, duration, state, extra_data)``:
one row per status change, ``timestamp`` microseconds since the epoch made strictly increasing
by the logger (the table's primary key, so the rows read in timestamp order are the order they
happened), ``state`` the new ``NodeStatus`` (0 IDLE, 1 RUNNING, 2 SUCCESS, 3 FAILURE, 4 SKIPPED).

Each session is one log (``read_db3`` returns them in session order; a file of one session is
named by its path, otherwise ``PATH#session=N``). Times are microseconds since the session's
first transition (``start_us``).

The file is never trusted: it is opened read-only (``file:...?mode=ro`` URI, ``query_only``, no
trusted schema), only when it is a regular file within ``max_input_bytes``; the three names must
be tables (not views) with the columns above; every query runs under a SQLite progress handler
whose budget grows with the file's size (a crafted file cannot make a query run away), after
SQLite's ``quick_check`` (a file cut short or overwritten is refused, not read short); the
embedded XML is bounded by ``max_input_bytes`` and read by fsmbt's safe XML parser. Refused,
each with one located line (exit 2): not a SQLite database, a corrupt one, a database that is not a BT.CPP
SQLite log, no session, a session without its tree, a transition whose node UID the session's
tree does not have, a state outside 0..4 or not an integer.

Costs: O(rows) with one SQL scan per session; the transitions land in three flat lists.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path
from urllib.parse import quote

from fsmbt import limits
from fsmbt.conform.btlog import embedded_nodes
from fsmbt.conform.log import RecordedLog
from fsmbt.model.errors import InputError, SourceLocation

#: The first bytes of every SQLite 3 database file.
SQLITE_MAGIC = b"SQLite format 3\x00"

#: The columns each table of a 4.8.2 SqliteLogger database has (bt_sqlite_logger.cpp).
SCHEMA = {
    "Definitions": ("session_id", "date", "xml_tree"),
    "Nodes": ("session_id", "fullpath", "node_uid"),
    "Transitions": ("timestamp", "session_id", "node_uid", "duration", "state", "extra_data"),
}
#: SQLite virtual-machine steps allowed per byte of the file (and a floor): bounds every query.
STEPS_PER_BYTE = 64
MIN_STEPS = 10_000_000
#: The progress handler is called every this many VM steps.
PROGRESS_EVERY = 10_000


def _bad(path: str, message: str) -> InputError:
    return InputError(message, location=SourceLocation(path))


def read_db3(path: str | Path) -> list[RecordedLog]:
    """Every session of a ``.db3`` file, in session order (see the module docstring).

    Raises:
        InputError: the file is not a BehaviorTree.CPP SQLite log, or is inconsistent.
    """
    name = str(path)
    file = Path(path)
    size = _checked_size(file, name)
    uri = f"file:{quote(str(file.resolve()))}?mode=ro"
    try:
        connection = sqlite3.connect(uri, uri=True, isolation_level=None)
    except sqlite3.Error as exc:
        raise _bad(name, f"cannot open the SQLite log: {exc}") from None
    budget = max(MIN_STEPS, size * STEPS_PER_BYTE) // PROGRESS_EVERY
    calls = [0]

    def progress() -> int:
        calls[0] += 1
        return 1 if calls[0] > budget else 0  # non-zero interrupts the query

    connection.set_progress_handler(progress, PROGRESS_EVERY)
    try:
        connection.execute("PRAGMA query_only = ON")
        connection.execute("PRAGMA trusted_schema = OFF")
        _check_integrity(connection, name)
        _check_schema(connection, name)
        return _sessions(connection, name)
    except sqlite3.OperationalError as exc:
        if "interrupted" in str(exc):
            raise _bad(
                name,
                f"the SQLite log takes more than {budget * PROGRESS_EVERY} query steps to read "
                f"({size} bytes; a crafted or corrupt file)",
            ) from None
        raise _bad(name, f"not a readable BehaviorTree.CPP SQLite log: {exc}") from None
    except sqlite3.DatabaseError as exc:
        raise _bad(name, f"a corrupt SQLite database ({exc})") from None
    finally:
        connection.close()


def _checked_size(file: Path, name: str) -> int:
    try:
        if not file.is_file():
            raise _bad(name, "is not a regular file")
        size = file.stat().st_size
    except OSError as exc:
        raise _bad(name, f"cannot read the log: {exc.strerror}") from None
    limit = limits.current().max_input_bytes
    if size > limit:
        raise _bad(name, limits.exceeded(f"the file's {size} bytes", "max_input_bytes", limit))
    return size


def _check_integrity(connection: sqlite3.Connection, name: str) -> None:
    """SQLite's own ``quick_check`` (O(file)): a file cut short or overwritten is refused, not
    read as a shorter log."""
    problems = connection.execute("PRAGMA quick_check(1)").fetchall()
    if [tuple(row) for row in problems] != [("ok",)]:
        first = str(problems[0][0]) if problems else "no answer"
        raise _bad(name, f"a corrupt SQLite database (quick_check: {first[:200]})")


def _check_schema(connection: sqlite3.Connection, name: str) -> None:
    """The three tables with 4.8.2's columns; anything else is 'not a BT.CPP SQLite log'."""
    found = dict(
        connection.execute(
            "SELECT name, type FROM sqlite_master WHERE name IN (?, ?, ?)", tuple(SCHEMA)
        ).fetchall()
    )
    for table, columns in SCHEMA.items():
        if found.get(table) != "table":
            raise _bad(
                name,
                f"a SQLite database but not a BehaviorTree.CPP SqliteLogger log: it has no "
                f"table {table}",
            )
        # the table name comes from SCHEMA, never from the file
        have = tuple(row[1] for row in connection.execute(f"PRAGMA table_info({table})"))
        if have != columns:
            raise _bad(
                name,
                f"a SQLite database but not a BehaviorTree.CPP SqliteLogger log: table {table} "
                f"has columns ({', '.join(map(str, have))}), not ({', '.join(columns)})",
            )


def _sessions(connection: sqlite3.Connection, name: str) -> list[RecordedLog]:
    limit = limits.current().max_input_bytes
    definitions = connection.execute(
        "SELECT session_id, length(xml_tree) FROM Definitions ORDER BY session_id"
    ).fetchall()
    if not definitions:
        raise _bad(name, "the SQLite log holds no session (table Definitions is empty)")
    logs: list[RecordedLog] = []
    for session, length in definitions:
        label = name if len(definitions) == 1 else f"{name}#session={session}"
        if not isinstance(session, int) or not isinstance(length, int):
            raise _bad(label, "a session without an integer id or its tree's XML text")
        if length > limit:
            raise _bad(
                label, limits.exceeded(f"the tree's {length} bytes", "max_input_bytes", limit)
            )
        (xml,) = connection.execute(
            "SELECT xml_tree FROM Definitions WHERE session_id = ?", (session,)
        ).fetchone()
        if not isinstance(xml, str):
            raise _bad(label, f"session {session}: the tree (xml_tree) is not text")
        nodes, root = embedded_nodes(xml, label)
        log = RecordedLog(label, "db3", nodes, root)
        times, uids, statuses = log.times, log.uids, log.statuses
        rows = connection.execute(
            "SELECT timestamp, node_uid, state FROM Transitions WHERE session_id = ? "
            "ORDER BY timestamp",
            (session,),
        )
        start = None
        for number, (stamp, uid, state) in enumerate(rows, start=1):
            if not (isinstance(stamp, int) and isinstance(uid, int) and isinstance(state, int)):
                raise _bad(
                    label,
                    f"transition #{number}: timestamp, node_uid and state must be integers",
                )
            if not 0 <= state <= 4:
                raise _bad(
                    label,
                    f"transition #{number} (timestamp {stamp}): state {state} is not a "
                    "BehaviorTree.CPP NodeStatus (0..4)",
                )
            if uid not in nodes:
                raise _bad(
                    label,
                    f"transition #{number} (timestamp {stamp}): node UID {uid} is not in the "
                    "session's tree (a log of another tree, or a corrupt file)",
                )
            if start is None:
                start = stamp
                log.start_us = stamp
            times.append(stamp - start)
            uids.append(uid)
            statuses.append(state)
        logs.append(log)
    return logs
