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
from fsmbt.verify.report import PROPERTIES, REACHABILITY, PropertyResult, Report

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
    implied_reachability: bool = True,
) -> Report:
    """Verify ``result_model`` against ``source_model`` with NuSMV; see the module docstring.

    ``implied_reachability``: first run the model without the reachability spec (its frozen
    copies make it a transitive closure, the costliest spec: 7.7 of 8.1 s on a 30-state pair);
    when the other four properties hold, reachability follows from them (docs/nusmv.md,
    "Reachability implied") and is reported as such; otherwise the whole model is run again, so
    a failing pair gets reachability's own verdict and counterexample. ``False``: one run of
    every spec (the benchmarks' "before").

    ``timeout`` defaults to ``fsmbt.limits.current().nusmv_max_seconds``; the memory cap is
    ``nusmv_max_memory_mb``. Raises ``UnsupportedError`` for BT node types the encoding does not
    model (docs/nusmv.md), ``NuSMVLimitError`` past a cap and ``NuSMVNotFound`` when no binary is
    available.
    """
    started = time.perf_counter()
    text, names, context = build_model(source_model, result_model, loop=loop)
    encoded = time.perf_counter()
    report: Report | None = None
    runs = 1
    lean = without_spec(text, names, REACHABILITY) if implied_reachability else None
    if lean is not None:
        lean_text, lean_names = lean
        results, nusmv_seconds = run_nusmv(
            lean_text, len(lean_names), order=context[-1], timeout=timeout
        )
        report = build_report(lean_names, results, context, source_model, result_model)
        if all(p.holds for p in report.properties.values()):
            report.properties[REACHABILITY] = PropertyResult(REACHABILITY, True, IMPLIED_DETAIL)
            report.properties = {n: report.properties[n] for n in PROPERTIES}
        else:  # a failing pair: reachability is decided by its own spec (its counterexample)
            report = None
    if report is None:
        results, seconds = run_nusmv(text, len(names), order=context[-1], timeout=timeout)
        nusmv_seconds = seconds if lean is None else nusmv_seconds + seconds
        runs = 1 if lean is None else 2
        report = build_report(names, results, context, source_model, result_model)
    report.stats.update(
        {
            "smv_lines": text.count("\n"),
            "encode_seconds": round(encoded - started, 6),
            "nusmv_seconds": round(nusmv_seconds, 6),
            "nusmv_runs": runs,
            "seconds": round(time.perf_counter() - started, 6),
        }
    )
    return report


#: The reachability verdict when the other four hold (docs/nusmv.md, "Reachability implied").
IMPLIED_DETAIL = (
    "implied by the other four (every faithful pair steps on every input the source offers "
    "to an agreeing pair, so every state either side reaches is reached faithfully)"
)

_SPEC_PREFIXES = ("SPEC ", "INVARSPEC ", "LTLSPEC ")


def without_spec(text: str, names: list[str], dropped: str) -> tuple[str, list[str]] | None:
    """The model without the spec named ``dropped`` (specs are the lines starting with
    ``SPEC``/``INVARSPEC``/``LTLSPEC``, in ``names`` order), or ``None`` when the text does not
    have one spec line per name (then nothing is dropped)."""
    lines = text.split("\n")
    spec_lines = [i for i, line in enumerate(lines) if line.startswith(_SPEC_PREFIXES)]
    if len(spec_lines) != len(names) or dropped not in names:
        return None
    skip = spec_lines[names.index(dropped)]
    kept = [line for i, line in enumerate(lines) if i != skip]
    return "\n".join(kept), [n for n in names if n != dropped]


__all__ = [
    "check",
    "build_model",
    "find_nusmv",
    "require_nusmv",
    "NuSMVNotFound",
    "NuSMVError",
    "NuSMVLimitError",
]
