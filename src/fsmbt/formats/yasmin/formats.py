"""The ``yasmin`` (XML) and ``yasmin-py`` (Python) formats' registration (docs/formats/yasmin.md):
detection, and the readers and writer of this package."""

from __future__ import annotations

import re

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.formats.xml_safe import root_tag
from fsmbt.formats.yasmin.build import build
from fsmbt.formats.yasmin.py_read import read_python
from fsmbt.formats.yasmin.xml_read import XmlReader
from fsmbt.formats.yasmin.xml_write import write_yasmin
from fsmbt.model.fsm import FSM

_YASMIN_IMPORT = re.compile(r"^\s*(import\s+yasmin\b|from\s+yasmin(\.\w+)*\s+import\b)", re.M)


def read_yasmin_xml(text: str, ctx: ReadContext) -> FSM:
    """Read a ``yasmin_factory`` XML state machine (see ``xml_read``)."""
    return build(XmlReader(ctx).read(text), ctx)


def read_yasmin_python(text: str, ctx: ReadContext) -> FSM:
    """Read a YASMIN Python state machine statically (see ``py_read``)."""
    return build(read_python(text, ctx), ctx)


def _sniff_xml(text: str) -> bool:
    return root_tag(text) == "StateMachine"


def _sniff_python(text: str) -> bool:
    return _YASMIN_IMPORT.search(text[:65536]) is not None


register(
    Format(
        "yasmin",
        (".yasmin.xml",),
        frozenset({"fsm"}),
        "YASMIN (ROS 2) state machine XML of yasmin_factory (read and write)",
        read_yasmin_xml,
        write_yasmin,
        _sniff_xml,
        priority=30,
        cannot_hold="parallel states not read from a concurrence, composites left on an event "
        "(flatten first)",
    )
)
register(
    Format(
        "yasmin-py",
        (".py",),
        frozenset({"fsm"}),
        "YASMIN (ROS 2) state machine in Python (read statically, never run)",
        read_yasmin_python,
        None,
        _sniff_python,
        priority=36,  # after SMACH and FlexBE: a .py file no import identifies stays theirs
    )
)
