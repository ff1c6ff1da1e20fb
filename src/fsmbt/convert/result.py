"""What every conversion engine returns, in a module of its own so that the converters and the
engine table (``fsmbt.convert.engines``) both import it without importing each other: the table
imports the converters, the converters import only this.

- ``ConversionResult``: the converted model, the engine, the direction, figures and warnings.
- ``Converter``: the type of an engine's direction, ``(model, **options) -> ConversionResult``.
- ``Model``: an FSM or a BT document.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM

Model = FSM | BTDocument


@dataclass
class ConversionResult:
    """A converted model with what a person wants to know about the conversion.

    ``direction`` is ``"fsm->bt"`` or ``"bt->fsm"``; ``stats`` holds engine-specific figures
    (LEBT: entry/loop state counts, nodes; BT->HFSM: ``k`` sub-FSMs, ``depth_before`` /
    ``depth_after`` compression ...); ``warnings`` are documented, non-fatal deviations (e.g.
    unreachable states dropped).
    """

    model: Model
    engine: str
    direction: str
    stats: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


Converter = Callable[..., ConversionResult]
