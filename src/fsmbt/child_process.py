"""Bounds for a child process fsmbt starts (NuSMV, a load check beside a proof): one place.

Why: fsmbt runs unattended (batch workers, the web page), so a child it starts must never
outlive it nor take the machine with it. A child gets, before ``exec``:

- an address-space cap (``RLIMIT_AS``), so a blow-up ends in the child;
- a CPU-time cap (``RLIMIT_CPU``) a little past its wall cap: a backstop should the parent be
  unable to kill it;
- ``PR_SET_PDEATHSIG`` (Linux): it is killed when the process that started it dies, so a CLI
  run or a worker killed with SIGKILL leaves nothing behind.

This module imports nothing from fsmbt (any layer may use it). Cost: one ``prctl`` lookup per
child started.
"""

from __future__ import annotations

import ctypes
import math
import os
import signal
import sys
from collections.abc import Callable

PR_SET_PDEATHSIG = 1  # <linux/prctl.h>
#: Seconds of CPU a child may run past its wall cap before ``RLIMIT_CPU`` stops it.
CPU_BACKSTOP_SECONDS = 5


def _prctl() -> Callable[..., int] | None:
    """Linux's ``prctl``, looked up in the parent (the child must not load libraries between
    ``fork`` and ``exec``), or ``None`` elsewhere."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        return ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None


def bounded_child(megabytes: int, seconds: float) -> Callable[[], None]:
    """A ``preexec_fn`` (it runs in the child, before ``exec``) that bounds the child for good:
    ``megabytes`` of address space, CPU ``seconds`` plus ``CPU_BACKSTOP_SECONDS`` (none when
    ``seconds`` is infinite), and death with its parent (module docstring)."""
    import resource

    prctl = _prctl()
    parent = os.getpid()
    cpu = max(1, int(seconds) + CPU_BACKSTOP_SECONDS) if math.isfinite(seconds) else None

    def apply() -> None:
        cap = megabytes * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        if cpu is not None:
            resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
        if prctl is not None:
            prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
            if os.getppid() != parent:  # the parent died before the request took effect
                os._exit(1)

    return apply
