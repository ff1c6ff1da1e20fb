"""Conversion between FSMs and BTs: ``convert(model)`` picks the direction from the model's kind.

Engines are looked up by name (``fsmbt.convert.engines``): ``rules`` (default; FSM -> BT: the
structured tree for outcome-driven machines, the dispatch form for event-driven ones, the LEBT
with ``style="lebt"``; BT -> FSM: depth compression + conversion units), and whatever the
baselines and the LLM path register (``bsd``, ``chds``, ``llm`` ...).
"""

from __future__ import annotations

from fsmbt.convert.engines import Engine, converter_for, engines, get_engine, register_engine
from fsmbt.convert.result import ConversionResult
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM


def convert(
    model: FSM | BTDocument, *, engine: str = "rules", style: str = "auto", **options: object
) -> ConversionResult:
    """Convert an FSM into a BT or a BT into a (hierarchical) FSM with ``engine``.

    Args:
        model: The source model; its kind picks the direction.
        engine: A registered engine name (``rules``, ``bsd``, ``chds``, ``llm``, ...).
        style: The engine's output style (rules engine: ``auto``, ``structured``, ``dispatch``,
            ``lebt``/``paper``).
        **options: Passed to the engine (e.g. ``loop=True`` for BT -> FSM,
            ``hierarchy="flatten"`` for FSM -> BT).

    Returns:
        The converted model with the engine's name, the direction, figures and warnings.

    Raises:
        InputError: Unknown engine, or one that does not convert this kind of model.
        UnsupportedError: The model uses something the engine cannot convert (located).
    """
    return converter_for(engine, model)(model, style=style, **options)


__all__ = [
    "convert",
    "ConversionResult",
    "Engine",
    "engines",
    "get_engine",
    "register_engine",
    "converter_for",
]
