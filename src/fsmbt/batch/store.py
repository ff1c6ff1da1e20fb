"""The results store: one SQLite file in the output folder, one row per job key.

Schema (docs/batch.md, "The store"): table ``results`` with the key as primary key and a
column per ``JobResult`` attribute (dicts as JSON text), plus ``state`` (``pending`` while a
job is out, ``done`` once its result is in). Rows are written by the driver only, one
transaction per result (``put``), per group of results that reached the driver together (a
chunk: ``put_many``) or per batch of claims (``claim``), in WAL mode, so a
process killed at any point (SIGKILL included) leaves every committed row intact and no row
twice: ``INSERT OR REPLACE`` on the key.

Why claims: a worker writes its output before the driver stores the row. When the driver dies
in between, the output exists and its row does not. A ``pending`` row, committed before the
job was handed out and only when its output did not exist (or ``--force``), says the file there
is this batch's own work, so the resumed run may replace it (``pending_output``).

Costs: ``put`` and ``done`` are one indexed statement each (``put_many``: one per row, one
commit for all); ``results`` and ``summary`` read
the whole table.
"""

from __future__ import annotations

import json
import sqlite3
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from fsmbt.batch.jobs import Job, public_options
from fsmbt.batch.result import STATUSES, JobResult

#: 2: the ``dependencies`` column (a store of version 1 gets it, empty, when opened).
SCHEMA_VERSION = 2
#: The store's file name in the output folder.
STORE_NAME = "fsmbt-batch.sqlite"

_COLUMNS = (
    "key",
    "input",
    "status",
    "verdict",
    "properties",
    "error_class",
    "error_message",
    "timings",
    "output",
    "stats",
    "engine",
    "verify_engine",
    "options",
    "attempts",
    "retry",
    "finished_at",
    "dependencies",
)
_JSON_COLUMNS = ("properties", "timings", "stats", "options", "dependencies")

_CREATE = """
CREATE TABLE IF NOT EXISTS results (
    key TEXT PRIMARY KEY,
    input TEXT NOT NULL,
    state TEXT NOT NULL CHECK (state IN ('pending', 'done')),
    status TEXT,
    verdict TEXT,
    properties TEXT,
    error_class TEXT,
    error_message TEXT,
    timings TEXT,
    output TEXT,
    stats TEXT,
    engine TEXT,
    verify_engine TEXT,
    options TEXT,
    attempts INTEGER,
    retry INTEGER,
    finished_at REAL,
    dependencies TEXT
);
CREATE TABLE IF NOT EXISTS meta (name TEXT PRIMARY KEY, value TEXT);
"""


class ResultStore:
    """The SQLite results store of one batch (a context manager; ``close`` when done).

    Args:
        path: the database file, or a folder (the store is ``STORE_NAME`` inside it); created
            with its folder when missing.
    """

    def __init__(self, path: str | Path) -> None:
        path = Path(path)
        if path.is_dir() or path.suffix == "":
            path = path / STORE_NAME
        path.parent.mkdir(parents=True, exist_ok=True)
        self.path = path
        self._db = sqlite3.connect(str(path), timeout=30.0, isolation_level=None)
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=NORMAL")  # durable across a process crash
        self._db.executescript(_CREATE)
        columns = {row[1] for row in self._db.execute("PRAGMA table_info(results)")}
        if "dependencies" not in columns:  # a version 1 store: its rows have no dependencies
            self._db.execute("ALTER TABLE results ADD COLUMN dependencies TEXT")
        self._db.execute(
            "INSERT OR REPLACE INTO meta VALUES ('schema_version', ?)", (str(SCHEMA_VERSION),)
        )

    # -- writing (the driver only) --------------------------------------------------------

    def put(self, result: JobResult) -> None:
        """Store one finished result, replacing any row with its key (one transaction)."""
        self.put_many([result])

    def put_many(self, results: Iterable[JobResult]) -> None:
        """Store finished results, each replacing any row with its key, in one transaction
        (all of them are committed, or none: a kill mid-way leaves the earlier commits)."""
        rows = []
        for result in results:
            if not result.finished_at:
                result.finished_at = time.time()
            rows.append(("done", *_encode(result)))
        if not rows:
            return
        marks = ", ".join("?" for _ in range(len(_COLUMNS) + 1))
        statement = (
            f"INSERT OR REPLACE INTO results (state, {', '.join(_COLUMNS)}) VALUES ({marks})"
        )
        if len(rows) == 1:
            self._db.execute(statement, rows[0])  # autocommit: one transaction
            return
        with self._transaction():
            self._db.executemany(statement, rows)

    def claim(self, jobs: Iterable[Job]) -> None:
        """Mark jobs as handed out (``pending``), in one transaction; done rows are kept."""
        with self._transaction():
            for job in jobs:
                self._db.execute(
                    "INSERT INTO results (key, input, state, output, engine, verify_engine, "
                    "options) VALUES (?, ?, 'pending', ?, ?, ?, ?) ON CONFLICT(key) DO NOTHING",
                    (
                        job.key,
                        job.input,
                        job.output,
                        job.engine,
                        job.verify_engine,
                        json.dumps(public_options(job.options), sort_keys=True, default=str),
                    ),
                )

    def _transaction(self) -> _Transaction:
        return _Transaction(self._db)

    # -- reading --------------------------------------------------------------------------

    def get(self, key: str) -> JobResult | None:
        """The finished result stored under ``key``, or ``None``."""
        row = self._db.execute(
            f"SELECT {', '.join(_COLUMNS)} FROM results WHERE key = ? AND state = 'done'", (key,)
        ).fetchone()
        return _decode(row) if row is not None else None

    def done(self, key: str) -> bool:
        """Whether ``key`` has a finished result that a resumed batch skips (not retryable)."""
        row = self._db.execute(
            "SELECT retry FROM results WHERE key = ? AND state = 'done'", (key,)
        ).fetchone()
        return row is not None and not row[0]

    def pending_output(self, key: str) -> bool:
        """Whether ``key`` was claimed by an earlier run (its output, if any, is this batch's)."""
        row = self._db.execute(
            "SELECT state, error_class FROM results WHERE key = ?", (key,)
        ).fetchone()
        return row is not None and (row[0] == "pending" or row[1] == "WorkerDied")

    def results(self) -> list[JobResult]:
        """Every finished result, in the order they were stored."""
        rows = self._db.execute(
            f"SELECT {', '.join(_COLUMNS)} FROM results "
            "WHERE state = 'done' ORDER BY finished_at, key"
        ).fetchall()
        return [_decode(row) for row in rows]

    def summary(self) -> dict[str, Any]:
        """Counts per status and what is left.

        Returns:
            ``{"total": rows, "pending": jobs handed out without a result, "retry": finished
            rows a resume runs again, "statuses": {status: count} for every status, "store":
            the file, "bytes": its size with the WAL}``.
        """
        counts = dict.fromkeys(STATUSES, 0)
        for status, count in self._db.execute(
            "SELECT status, COUNT(*) FROM results WHERE state = 'done' GROUP BY status"
        ):
            counts[str(status)] = int(count)
        pending = self._db.execute(
            "SELECT COUNT(*) FROM results WHERE state = 'pending'"
        ).fetchone()[0]
        retry = self._db.execute(
            "SELECT COUNT(*) FROM results WHERE state = 'done' AND retry"
        ).fetchone()[0]
        return {
            "total": sum(counts.values()) + int(pending),
            "pending": int(pending),
            "retry": int(retry),
            "statuses": counts,
            "store": str(self.path),
            "bytes": self.size_bytes(),
        }

    def size_bytes(self) -> int:
        """The store's size on disk (database, WAL and shared-memory files)."""
        total = 0
        for suffix in ("", "-wal", "-shm"):
            candidate = Path(f"{self.path}{suffix}")
            if candidate.exists():
                total += candidate.stat().st_size
        return total

    def close(self) -> None:
        """Checkpoint the WAL and close the connection."""
        try:
            self._db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        finally:
            self._db.close()

    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _Transaction:
    def __init__(self, db: sqlite3.Connection) -> None:
        self._db = db

    def __enter__(self) -> None:
        self._db.execute("BEGIN IMMEDIATE")

    def __exit__(self, kind: object, *rest: object) -> None:
        self._db.execute("COMMIT" if kind is None else "ROLLBACK")


def _encode(result: JobResult) -> tuple[Any, ...]:
    values: list[Any] = []
    for name in _COLUMNS:
        value = getattr(result, name)
        if name in _JSON_COLUMNS:
            value = json.dumps(value, sort_keys=True, default=str)
        elif name == "retry":
            value = int(bool(value))
        values.append(value)
    return tuple(values)


def _decode(row: tuple[Any, ...]) -> JobResult:
    fields: dict[str, Any] = {}
    for name, value in zip(_COLUMNS, row):
        if name in _JSON_COLUMNS:
            value = json.loads(value) if value else {}
        elif name == "retry":
            value = bool(value)
        fields[name] = value
    return JobResult(**fields)
