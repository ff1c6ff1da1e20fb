"""A per-minute limit on LLM requests, shared by every worker process of one machine.

Rules: at most ``per_minute`` requests start in any 60-second window, counted over all the
batch's workers. The window lives in a small file (one start time per line) guarded by an
exclusive ``fcntl`` lock, so processes that share nothing else (pool workers, Ray workers on the
same node) share the limit; a worker that wants a request when the window is full sleeps until
the oldest start leaves it. How many requests run *at once* is bounded by the driver, which
hands LLM jobs to at most ``llm_concurrency`` workers. 429 and 5xx answers are retried with
back-off by ``fsmbt.llm.client`` (``Retry-After`` honoured); a request that still fails is a
row with its cause, run again on resume.

On a Ray cluster of several machines the file is per node: set ``per_minute`` to the
endpoint's limit divided by the number of nodes (docs/batch.md, "LLM engines").

Costs: one lock, one small read and write per request.
"""

from __future__ import annotations

import fcntl
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

WINDOW_S = 60.0


class MinuteRateLimit:
    """Blocks ``acquire`` until a request may start under the per-minute limit.

    Args:
        path: the shared window file (created when missing).
        per_minute: requests allowed per 60 seconds (at least 1).
        clock, sleep: for tests (wall-clock time, since processes share it).
    """

    def __init__(
        self,
        path: str | Path,
        per_minute: int,
        *,
        clock: Callable[[], float] = time.time,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.path = Path(path)
        self.per_minute = max(1, int(per_minute))
        self._clock = clock
        self._sleep = sleep

    def acquire(self) -> float:
        """Wait for a free slot in the window and take it.

        Returns:
            The seconds spent waiting.
        """
        waited = 0.0
        self.path.parent.mkdir(parents=True, exist_ok=True)
        while True:
            wait = self._try_take()
            if wait <= 0:
                return waited
            self._sleep(wait)
            waited += wait

    def _try_take(self) -> float:
        handle = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o600)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX)
            with os.fdopen(os.dup(handle), "r+", encoding="ascii") as stream:
                now = self._clock()
                starts = [float(line) for line in stream.read().split() if _number(line)]
                recent = [t for t in starts if now - t < WINDOW_S]
                if len(recent) >= self.per_minute:
                    return max(0.01, WINDOW_S - (now - min(recent)))
                recent.append(now)
                stream.seek(0)
                stream.truncate()
                stream.write("\n".join(f"{t:.6f}" for t in recent))
                stream.flush()
                return 0.0
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
            os.close(handle)


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


class RateLimitedClient:
    """An LLM client whose every ``complete`` call first takes a slot of a ``MinuteRateLimit``.

    Args:
        client: the ``fsmbt.llm.client.LLMClient`` to wrap.
        limit: the shared limit.
    """

    def __init__(self, client: Any, limit: MinuteRateLimit) -> None:
        self._client = client
        self._limit = limit
        self.waited_s = 0.0
        self.requests = 0

    def complete(self, messages: list[dict[str, Any]]) -> Any:
        """``client.complete(messages)`` after the limit allows it."""
        self.waited_s += self._limit.acquire()
        self.requests += 1
        return self._client.complete(messages)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._client, name)
