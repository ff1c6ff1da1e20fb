"""The ``pystatemachine`` format's registration (docs/formats/pystatemachine.md): detection and
the reader and writer of ``classes``."""

from __future__ import annotations

import re

from fsmbt.formats.pystatemachine.classes import read_pystatemachine, write_pystatemachine
from fsmbt.formats.registry import Format, register

_IMPORT = re.compile(r"^\s*(import\s+statemachine\b|from\s+statemachine(\.\w+)*\s+import\b)", re.M)


def _sniff(text: str) -> bool:
    return _IMPORT.search(text[:65536]) is not None


register(
    Format(
        "pystatemachine",
        (".sm.py",),
        frozenset({"fsm"}),
        "python-statemachine class (read statically, never run; write the class)",
        read_pystatemachine,
        write_pystatemachine,
        _sniff,
        priority=33,
        cannot_hold="composite or parallel states (flatten first), guards, names that are "
        "not Python identifiers",
    )
)
