"""NuSMV as the second, independent verification engine (docs/verification.md, docs/nusmv.md).

``check(source, result, loop=False)`` encodes both models as SMV modules from their structure
(the BT's tick rules as transition relations, never the native interpreter's explored graph),
builds the product and the five properties as CTL specs, runs NuSMV once and returns the same
``Report`` the native checker gives, counterexamples decoded to ``TraceStep`` s.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from typing import TYPE_CHECKING, TypeAlias

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.verify.nusmv.binary import NuSMVNotFound, find_nusmv, require_nusmv
from fsmbt.verify.nusmv.encode_bt import LeafBTEncoder
from fsmbt.verify.nusmv.encode_fsm import FSMEncoder
from fsmbt.verify.nusmv.runner import NuSMVError, NuSMVLimitError, run_nusmv
from fsmbt.verify.nusmv.smv import Symbols
from fsmbt.verify.nusmv.specs import product
from fsmbt.verify.nusmv.traces import Context, Encoder, build_report
from fsmbt.verify.report import Report

if TYPE_CHECKING:
    from fsmbt.verify.nusmv.encode_lebt import LebtEncoder  # noqa: F401 - in Encoder

Encoders: TypeAlias = tuple[Encoder, Encoder, Symbols, Symbols, str]

MACRO_STEP = "macro-step"
LEAF_EXECUTION = "leaf-execution"


def _union(*groups: Iterable[str]) -> list[str]:
    seen: dict[str, None] = {}
    for group in groups:
        for item in group:
            seen.setdefault(item, None)
    return list(seen)


def encode(source: FSM | BTDocument, result: FSM | BTDocument, *, loop: bool = False) -> Encoders:
    """The two machine encoders, the shared symbol tables and the mode for a pair of models
    (the same pairing as ``fsmbt.verify.pairing.machines_for``)."""
    from fsmbt.verify.pairing import lebt_guard_events, sub_machine_events

    inputs, outputs = Symbols("in_"), Symbols("out_")
    if isinstance(source, FSM) and isinstance(result, FSM):
        alphabet = _union(source.events(), result.events(), *sub_machine_events(source, result))
        return (
            FSMEncoder(source, "source", inputs, outputs, alphabet=alphabet),
            FSMEncoder(result, "result", inputs, outputs, alphabet=alphabet),
            inputs,
            outputs,
            MACRO_STEP,
        )
    if isinstance(source, FSM) and isinstance(result, BTDocument):
        from fsmbt.model.flatten import flatten
        from fsmbt.verify.nusmv.encode_lebt import LebtEncoder

        alphabet = _union(flatten(source).events(), lebt_guard_events(result))
        return (
            FSMEncoder(source, "source", inputs, outputs, alphabet=alphabet),
            LebtEncoder(result, "result", inputs, outputs, alphabet=alphabet),
            inputs,
            outputs,
            MACRO_STEP,
        )
    if isinstance(source, BTDocument) and isinstance(result, FSM):
        return (
            LeafBTEncoder(source, "source", inputs, outputs, loop=loop),
            FSMEncoder(result, "result", inputs, outputs, alphabet=(), leaf=True, loop=loop),
            inputs,
            outputs,
            LEAF_EXECUTION,
        )
    if isinstance(source, BTDocument) and isinstance(result, BTDocument):
        return (
            LeafBTEncoder(source, "source", inputs, outputs, loop=loop),
            LeafBTEncoder(result, "result", inputs, outputs, loop=loop),
            inputs,
            outputs,
            LEAF_EXECUTION,
        )
    raise InputError(f"cannot compare a {type(source).__name__} with a {type(result).__name__}")


def build_model(
    source: FSM | BTDocument, result: FSM | BTDocument, *, loop: bool = False
) -> tuple[str, list[str], Context]:
    """The SMV text of the product, the spec names and what is needed to decode traces."""
    src_enc, res_enc, inputs, outputs, mode = encode(source, result, loop=loop)
    src, res = src_enc.encode(), res_enc.encode()
    extra: list[tuple[str, str]] = getattr(res_enc, "extra_specs", lambda: [])()
    prod = product(src, res, inputs, extra)
    text = src.text + "\n" + res.text + "\n" + prod.text
    return text, prod.spec_names, (src, res, src_enc, res_enc, inputs, outputs, mode, prod.order)


def check(
    source_model: FSM | BTDocument,
    result_model: FSM | BTDocument,
    *,
    loop: bool = False,
    timeout: float | None = None,
) -> Report:
    """Verify ``result_model`` against ``source_model`` with NuSMV; see the module docstring.

    ``timeout`` defaults to ``fsmbt.limits.current().nusmv_max_seconds``; the memory cap is
    ``nusmv_max_memory_mb``. Raises ``UnsupportedError`` for BT node types the encoding does not
    model (docs/nusmv.md), ``NuSMVLimitError`` past a cap and ``NuSMVNotFound`` when no binary is
    available.
    """
    started = time.perf_counter()
    text, names, context = build_model(source_model, result_model, loop=loop)
    encoded = time.perf_counter()
    results, nusmv_seconds = run_nusmv(text, len(names), order=context[-1], timeout=timeout)
    report = build_report(names, results, context, source_model, result_model)
    report.stats.update(
        {
            "smv_lines": text.count("\n"),
            "encode_seconds": round(encoded - started, 6),
            "nusmv_seconds": round(nusmv_seconds, 6),
            "seconds": round(time.perf_counter() - started, 6),
        }
    )
    return report


__all__ = [
    "check",
    "build_model",
    "find_nusmv",
    "require_nusmv",
    "NuSMVNotFound",
    "NuSMVError",
    "NuSMVLimitError",
]
