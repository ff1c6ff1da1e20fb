"""The ``smcat`` format's registration (docs/formats/smcat.md): reader and writer of ``model``."""

from __future__ import annotations

from fsmbt.formats.registry import Format, register
from fsmbt.formats.smcat.model import read_smcat, write_smcat

register(
    Format(
        "smcat",
        (".smcat",),
        frozenset({"fsm"}),
        "state-machine-cat notation (read and write; rendered by the smcat tool)",
        read_smcat,
        write_smcat,
        None,
        priority=60,
        cannot_hold="parallel states, guards, history and choice pseudo-states",
    )
)
