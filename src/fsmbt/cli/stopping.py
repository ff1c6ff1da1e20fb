"""Requested stops: SIGTERM (what systemd, Docker and Kubernetes send) is handled like SIGINT
(Ctrl-C), so every command stops the same clean way (docs/batch.md, 'Stopping').

Rules:

- ``installed()`` makes SIGTERM (and SIGINT) raise ``StopRequested`` (a ``KeyboardInterrupt``) in the main
  thread, so the ``finally`` blocks and context managers of the running command run exactly as
  for Ctrl-C: ``subprocess.run`` kills its NuSMV / C++ child, the batch executor lets in-flight
  jobs finish for a short grace and kills its workers (their claimed rows stay ``pending``:
  the next run resumes them), the store commits or rolls back whole transactions.
- ``requested_stop(exc)`` tells ``fsmbt.cli.main`` that an interruption was a stop someone
  asked for: the command then exits 0 with one line on stderr, not 130.
- Nothing is started in its own session or process group, so a signal sent to the group
  reaches every child too.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType


class StopRequested(KeyboardInterrupt):
    """SIGTERM arrived: stop as for Ctrl-C."""


#: The signals received since ``install`` (typer turns the interruption into exit code 130,
#: so ``fsmbt.cli.main`` asks here whether it was a requested stop).
RECEIVED: list[int] = []


def _on_signal(signum: int, frame: FrameType | None) -> None:
    RECEIVED.append(signum)
    raise StopRequested()


@contextmanager
def installed() -> Iterator[None]:
    """While it is open, SIGTERM and SIGINT raise ``StopRequested`` in the main thread, noted
    in ``RECEIVED``; the previous handlers come back afterwards (a no-op off the main
    thread, e.g. when a test calls ``main`` from a thread)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    RECEIVED.clear()
    previous = {sig: signal.signal(sig, _on_signal) for sig in (signal.SIGTERM, signal.SIGINT)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def stop_was_requested() -> bool:
    """Whether SIGTERM or SIGINT arrived since ``install``."""
    return bool(RECEIVED)


def requested_stop(exc: BaseException) -> bool:
    """Whether ``exc`` (or what it wraps, e.g. click's ``Abort``) is SIGINT or SIGTERM."""
    seen: BaseException | None = exc
    for _ in range(4):  # a short chain: Abort from KeyboardInterrupt
        if seen is None:
            return False
        if isinstance(seen, KeyboardInterrupt):
            return True
        seen = seen.__cause__ or seen.__context__
    return False
