"""The web server's settings: limits, folders, workers (docs/web.md, 'Limits').

Defaults are safe for a page on a developer's machine: 2 MB request bodies, 30 s per
conversion or verification, two worker processes, the repository's ``examples/`` folder, no
report folder. Nothing here comes from a request.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import fsmbt
from fsmbt.web.answers import DEFAULT_CACHE_BYTES

#: Bytes of an over-limit body read and thrown away so the client gets its 413 instead of a
#: reset (``fsmbt.web.errors.BodyLimit``); past this the connection is closed. Defined here,
#: not beside ``BodyLimit``: the command line reads these defaults without importing FastAPI.
DEFAULT_DRAIN_CAP_BYTES = 64 * 1024 * 1024

#: Largest request body accepted (bytes).
DEFAULT_MAX_BODY_BYTES = 2 * 1024 * 1024
#: Wall seconds one conversion or verification may take in a worker.
DEFAULT_TIMEOUT_S = 30.0
#: CPU seconds one conversion or verification may use in a worker.
DEFAULT_CPU_LIMIT_S = 20.0
#: Requests that may wait for a worker before new ones get 503 (well above a burst of 200).
DEFAULT_MAX_WAITING = 1000
#: Worker processes.
DEFAULT_WORKERS = 2
#: Requests a second each client may sustain (token bucket per client address,
#: ``fsmbt.web.admission``); past it 429 with ``Retry-After``. Loopback clients are exempt
#: unless ``rate_limit_loopback``.
DEFAULT_RATE_LIMIT = 20.0
#: Requests a client may send at once (the bucket's size): a burst of 200 fits.
DEFAULT_RATE_BURST = 400


def default_examples_dir() -> Path | None:
    """The ``examples/`` folder of the checkout fsmbt is installed from (``pip install -e .``),
    or ``None`` when there is none (an installed wheel)."""
    candidate = Path(fsmbt.__file__).resolve().parents[2] / "examples"
    return candidate if candidate.is_dir() else None


@dataclass(frozen=True)
class WebSettings:
    """What ``create_app`` needs.

    Attributes:
        max_body_bytes: requests with a larger body are refused with 413.
        timeout_s: the wall-time limit of one conversion or verification (408 past it).
        cpu_limit_s: the CPU-time limit of one conversion or verification (422 past it).
        max_waiting: requests that may wait for a worker (503 with ``Retry-After`` beyond).
        cache_bytes: the in-memory bound of the answer cache (0: no cache; ``answers``).
        cache_dir: where the answer cache is also kept on disk (``None``: memory only).
        drain_cap_bytes: an over-limit body is read and dropped up to this size so the client
            gets its 413 (``errors.BodyLimit``); past it the connection is closed.
        workers: worker processes.
        rate_limit: requests a second each client may sustain (0: no per-client limit); past
            it 429 with ``Retry-After`` (``fsmbt.web.admission``).
        rate_burst: requests a client may send at once.
        rate_limit_loopback: limit loopback clients too (exempt by default).
        trusted_proxies: addresses or networks of reverse proxies whose ``X-Forwarded-For``
            names the client (empty: the header is ignored).
        examples_dir: the folder whose model files the page offers as examples (``None``: none).
        reports_dir: the folder of evaluation reports and batch stores browsed read-only
            (``None``: browsing is off).
    """

    max_body_bytes: int = DEFAULT_MAX_BODY_BYTES
    timeout_s: float = DEFAULT_TIMEOUT_S
    cpu_limit_s: float = DEFAULT_CPU_LIMIT_S
    max_waiting: int = DEFAULT_MAX_WAITING
    drain_cap_bytes: int = DEFAULT_DRAIN_CAP_BYTES
    cache_bytes: int = DEFAULT_CACHE_BYTES
    cache_dir: Path | None = None
    workers: int = DEFAULT_WORKERS
    rate_limit: float = DEFAULT_RATE_LIMIT
    rate_burst: int = DEFAULT_RATE_BURST
    rate_limit_loopback: bool = False
    trusted_proxies: tuple[str, ...] = ()
    examples_dir: Path | None = None
    reports_dir: Path | None = None

    @classmethod
    def default(cls, **changes: object) -> WebSettings:
        """The defaults, with the checkout's examples folder and ``changes`` applied."""
        values: dict[str, object] = {"examples_dir": default_examples_dir()}
        values.update(changes)
        return cls(**values)  # type: ignore[arg-type]
