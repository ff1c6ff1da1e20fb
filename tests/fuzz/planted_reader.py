"""A reader with planted bugs, registered only by the harness self-test (never in fsmbt).

``!`` in the input raises ``KeyError`` (a crash), ``~`` loops forever (a timeout), ``^``
allocates far past any memory cap (``MemoryError``), `` ` `` sleeps (no CPU: only the hard,
wall-clock alarm stops it, by killing the worker); anything else is a clean ``InputError``.
Single characters, so a short fuzz run reaches each of them.
"""

from __future__ import annotations

import time

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model.errors import InputError


def read_planted(text: str, ctx: ReadContext) -> object:
    if "!" in text:
        return {}["planted"]
    if "~" in text:
        while True:
            pass
    if "`" in text:
        time.sleep(3600)
    if "^" in text:
        return bytearray(64 * 1024**3)
    raise InputError("not a planted model", location=ctx.location(1))


register(
    Format(
        "planted-bug",
        (".planted",),
        frozenset({"fsm"}),
        "harness self-test only",
        read_planted,
        None,
        None,
        priority=99,
    )
)
