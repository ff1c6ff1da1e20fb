"""state-machine-cat (``.smcat``): read and written (docs/formats/smcat.md).

The notation behaviour-model studies publish their extracted machines in; state-machine-cat
(npm) renders it. ``parse`` scans the text by state-machine-cat's own grammar, ``model`` maps
it to and from fsmbt's hierarchical FSM. Detected by the ``.smcat`` extension only (the text has
no marker a sniffer could trust).
"""

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
