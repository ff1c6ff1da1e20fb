"""``fsmbt conform``: recorded executions checked against a model (docs/conform.md).

``read_log(path)`` reads a BehaviorTree.CPP ``FileLogger2`` log (``btlog.py``) or the Python
runtime's py_trees trace (``trace.py``), told apart by their first bytes; ``conform(model,
logs)`` replays each through the model's leaf-execution semantics (``replay.py``) and returns
one result per log and the coverage they reached together. This package sits above ``api``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from fsmbt import api
from fsmbt.conform.btlog import MAGIC, read_btlog
from fsmbt.conform.log import LoggedNode, RecordedLog
from fsmbt.conform.replay import Coverage, Deviation, LogResult, Replayer
from fsmbt.conform.trace import TraceWriter, read_trace
from fsmbt.model.errors import InputError, SourceLocation

#: The first bytes of a SQLite database (BehaviorTree.CPP's SqliteLogger writes .db3 files).
SQLITE_MAGIC = b"SQLite format 3\x00"


def read_log(path: str | Path) -> RecordedLog:
    """A log file of any supported format, detected from its first bytes.

    Raises:
        InputError: an unreadable file or an unknown or unsupported format (located).
    """
    location = SourceLocation(str(path))
    try:
        with Path(path).open("rb") as stream:
            head = stream.read(32)
    except OSError as exc:
        raise InputError(f"cannot read the log: {exc.strerror}", location=location) from None
    if head.startswith(MAGIC):
        return read_btlog(path)
    if head.lstrip().startswith(b"{"):
        return read_trace(path)
    if head.startswith(SQLITE_MAGIC):
        raise InputError(
            "a SQLite database (BehaviorTree.CPP's SqliteLogger .db3): not read by this "
            "version; record with FileLogger2 (.btlog) instead (docs/conform.md)",
            location=location,
        )
    raise InputError(
        "not a log fsmbt reads: neither a BehaviorTree.CPP FileLogger2 log (.btlog) nor a "
        "fsmbt py_trees trace (JSON lines)",
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
    return conform(loaded.model, [read_log(p) for p in logs], name=str(model))


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
    "read_log",
    "read_trace",
]
