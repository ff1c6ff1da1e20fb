"""state-machine-cat (``.smcat``): read and written (docs/formats/smcat.md).

The notation behaviour-model studies publish their extracted machines in; state-machine-cat
(npm) renders it. ``parse`` scans the text by state-machine-cat's own grammar, ``model`` maps
it to and from fsmbt's hierarchical FSM. Detected by the ``.smcat`` extension only (the text has
no marker a sniffer could trust).
"""
