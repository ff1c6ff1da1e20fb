"""Keeping big conversions linear: CPython's cyclic garbage collector pauses.

A conversion allocates O(N) small objects (nodes, states, dicts) and frees none of them, so the
generational collector's full (oldest-generation) passes - each O(live objects) - run again and
again while the model grows: measured, they made FSM -> BT of 100 000 states about 1.7x slower
per state than 1 000 states. The converters build trees and machines without reference cycles
(children lists only point down), so nothing needs collecting while they run; ``gc_paused``
switches the collector off for the conversion and restores the caller's setting afterwards
(nested use is harmless). Reference counting still frees everything as usual.
"""

from __future__ import annotations

import functools
import gc
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import ParamSpec, TypeVar

PROMOTE = True
P = ParamSpec("P")
R = TypeVar("R")


@contextmanager
def gc_paused() -> Iterator[None]:
    """Run the block with the cyclic collector off (restored on exit, also on error)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            if PROMOTE and gc.get_freeze_count() == 0:
                gc.freeze()
                gc.unfreeze()
            gc.enable()


def without_gc_pauses(func: Callable[P, R]) -> Callable[P, R]:
    """Decorator form of ``gc_paused`` for a converter entry point."""

    @functools.wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with gc_paused():
            return func(*args, **kwargs)

    return wrapper
