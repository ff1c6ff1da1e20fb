"""The ``transitions`` format's registration (docs/formats/transitions.md): detection and the
reader and writer of ``config``."""

from __future__ import annotations

import re

from fsmbt.formats.registry import Format, register
from fsmbt.formats.transitions.config import read_transitions, write_transitions

_JSON_HINT = re.compile(r'"trigger"\s*:')
_YAML_HINT = re.compile(r"^\s*-?\s*trigger\s*:", re.M)
_STATES = re.compile(r'^(\s*"states"\s*:|states\s*:)', re.M)


def _sniff(text: str) -> bool:
    head = text[:65536]
    if _STATES.search(head) is None:
        return False
    if head.lstrip().startswith("{"):
        return _JSON_HINT.search(head) is not None and '"kind"' not in head[:4096]
    return _YAML_HINT.search(head) is not None and re.search(r"^kind\s*:", head, re.M) is None


register(
    Format(
        "transitions",
        (".transitions.json", ".transitions.yaml", ".transitions.yml"),
        frozenset({"fsm"}),
        "pytransitions MarkupMachine configuration (JSON or YAML; read and write)",
        read_transitions,
        write_transitions,
        _sniff,
        priority=25,
        cannot_hold="parallel states, transitions between levels, completion transitions",
    )
)
