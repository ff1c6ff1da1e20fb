"""``fsmbt conform``: recorded executions checked against a model (docs/conform.md).

``read_logs(path)`` reads a BehaviorTree.CPP ``FileLogger2`` log (``btlog.py``), a
BehaviorTree.CPP ``SqliteLogger`` database (``db3.py``: one log per recording session) or the
Python runtime's py_trees trace (``trace.py``), told apart by their first bytes; ``conform(model,
logs)`` replays each through the model's leaf-execution semantics (``replay.py``) and returns
one result per log and the coverage they reached together. This package sits above ``api``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from fsmbt import api
from fsmbt.conform.btlog import MAGIC, read_btlog
from fsmbt.conform.db3 import SQLITE_MAGIC, read_db3
from fsmbt.conform.log import LoggedNode, RecordedLog
from fsmbt.conform.replay import Coverage, Deviation, LogResult, Replayer
from fsmbt.conform.trace import TraceWriter, read_trace
from fsmbt.model.errors import InputError, SourceLocation


def read_log(path: str | Path) -> RecordedLog:
    """A log file of any supported format, detected from its first bytes (a ``.db3`` of
    several sessions: use ``read_logs``).

    Raises:
        InputError: an unreadable file, an unknown format, or a ``.db3`` of several sessions
            (located).
    """
    logs = read_logs(path)
    if len(logs) != 1:
        raise InputError(
            f"the SQLite log holds {len(logs)} sessions: read it with read_logs",
            location=SourceLocation(str(path)),
        )
    return logs[0]


def read_logs(path: str | Path) -> list[RecordedLog]:
    """Every log a file holds (one, except a ``.db3`` of several sessions), its format detected
    from its first bytes.

    Raises:
        InputError: an unreadable file or an unknown format (located).
    """
    location = SourceLocation(str(path))
    try:
        with Path(path).open("rb") as stream:
            head = stream.read(32)
    except OSError as exc:
        raise InputError(f"cannot read the log: {exc.strerror}", location=location) from None
    if head.startswith(MAGIC):
        return [read_btlog(path)]
    if head.lstrip().startswith(b"{"):
        return [read_trace(path)]
    if head.startswith(SQLITE_MAGIC):
        return read_db3(path)
    raise InputError(
        "not a log fsmbt reads: neither a BehaviorTree.CPP FileLogger2 log (.btlog), a "
        "SqliteLogger log (.db3) nor a fsmbt py_trees trace (JSON lines)",
        location=location,
    )


@dataclass
class ConformReport:
    """Every log against one model."""

    model: str
    results: list[LogResult]
    coverage: Coverage

    @property
    def conforms(self) -> bool:
        return all(r.conforms for r in self.results)


def conform(model: api.Model, logs: list[RecordedLog], *, name: str = "model") -> ConformReport:
    """Replay every log through ``model`` (docs/conform.md)."""
    replayer = Replayer(model)
    results = [replayer.replay(log) for log in logs]
    return ConformReport(name, results, replayer.coverage())


def conform_files(
    model: str | Path,
    logs: list[str | Path],
    *,
    options: dict[str, object] | api.ReadOptions | None = None,
) -> ConformReport:
    """Read the model and the logs, then ``conform``.

    Raises:
        InputError: a model or log that does not load (located).
    """
    loaded = api.load(model, options=options)
    return conform(loaded.model, [log for p in logs for log in read_logs(p)], name=str(model))


__all__ = [
    "ConformReport",
    "Coverage",
    "Deviation",
    "LogResult",
    "LoggedNode",
    "RecordedLog",
    "TraceWriter",
    "conform",
    "conform_files",
    "read_btlog",
    "read_db3",
    "read_log",
    "read_logs",
    "read_trace",
]
