"""Keeping big conversions linear: CPython's cyclic garbage collector.

A conversion allocates O(N) small objects (nodes, lists, states) and frees none of the result,
so two things cost time that grows faster than the work while the model grows:

- the generational collector's passes during the build - each full (oldest-generation) pass is
  O(live objects) and runs again and again as the model grows: measured, they made FSM -> BT
  of 100 000 states about 1.7x slower per state than 1 000 states. ``gc_paused`` switches the
  collector off for the conversion (the converters build trees and machines without reference
  cycles - children lists only point down - so nothing needs collecting while they run;
  reference counting still frees every temporary object at once);
- the young-generation pass that the first allocation after ``gc.enable()`` triggers: every
  object allocated while the collector was off is still "young", so that one pass traverses the
  whole result (about 7 objects tracked by the collector per FSM state), and the
  middle-generation pass a little later traverses it again. At 100 000 states the result does
  not fit in the processor's caches and these passes cost more per state than the whole
  conversion (``benchmarks/bench_convert.py``, figures in docs/conversion.md, 'Cost of
  FSM -> BT'). On exit,
  ``gc_paused`` therefore moves the young objects straight into the oldest generation with
  ``gc.freeze()`` + ``gc.unfreeze()`` - two O(1) list splices, no traversal - which is where
  two passes would have put the long-lived result anyway.

Costs and consequences of the promotion: nothing is lost or leaked. The next full collection
examines the promoted objects as it examines every long-lived object. Young objects of the
caller's own are promoted with the result, so any reference cycle of the caller's that became
garbage just before the conversion is freed by the next full collection instead of the next
young one (later, never missed). The promotion is skipped when the caller has frozen objects
(``gc.get_freeze_count() > 0``, e.g. a pre-fork server): ``gc.unfreeze()`` would thaw them.
The caller's collector setting is restored either way; nested use is harmless (only the
outermost block promotes and re-enables).
"""

from __future__ import annotations

import functools
import gc
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import ParamSpec, TypeVar

P = ParamSpec("P")
R = TypeVar("R")

#: Whether ``gc_paused`` promotes the block's young objects on exit (see the module docstring).
#: Only the benchmark switches it off, to measure what the promotion saves.
PROMOTE_ON_EXIT = True


def promote_young_objects() -> bool:
    """Move every object of the young and middle generations into the oldest one, in O(1).

    Returns:
        True when done; False when the caller has frozen objects (then nothing is moved).
    """
    if gc.get_freeze_count() > 0:
        return False
    gc.freeze()  # young + middle + old generations -> the permanent one (list splices)
    gc.unfreeze()  # the permanent generation -> the oldest one (one list splice)
    return True


@contextmanager
def gc_paused() -> Iterator[None]:
    """Run the block with the cyclic collector off; on exit promote what the block allocated
    to the oldest generation (see the module docstring) and restore the caller's setting
    (also on error)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            if PROMOTE_ON_EXIT:
                promote_young_objects()
            gc.enable()


def without_gc_pauses(func: Callable[P, R]) -> Callable[P, R]:
    """Decorator form of ``gc_paused`` for a converter entry point."""

    @functools.wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with gc_paused():
            return func(*args, **kwargs)

    return wrapper
