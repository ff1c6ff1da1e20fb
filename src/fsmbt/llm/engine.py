"""The engines ``llm``, ``nllm`` and ``hybrid`` in the converter's registry.

``fsmbt.convert.engines`` imports this module (its ``_PLUGIN_MODULES``), so
``fsmbt convert --engine llm|nllm|hybrid`` finds them; ``rules`` stays the default there.

- ``llm``: the paper's method: four-part prompt with the SCP, verification, feedback rounds.
- ``nllm``: the same request without the SCP (the paper's baseline), same loop.
- ``hybrid``: the LLM's only job is extracting the source model from what no parser reads
  (``fsmbt.llm.extract``); the rules engine converts and the checker verifies, so the result's
  correctness never depends on the LLM. Given a model a parser already read, hybrid makes no
  LLM call at all.

Options an engine takes (all optional; the environment and config files fill the rest):
``llm_base_url``, ``llm_model``, ``llm_api_key``, ``llm_timeout``, ``llm_log``,
``max_regenerations``, ``verify_engine`` (``native``/``nusmv``/``both``), ``ablate`` (SCP
modules to drop), ``source_name``. An LLM engine only returns a result the checker found
equivalent; otherwise it raises ``LLMConversionError`` (one line, exit 2) naming what was wrong.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from fsmbt.convert.engines import converter_for, register_engine
from fsmbt.convert.result import ConversionResult
from fsmbt.llm.client import LLMClient
from fsmbt.llm.config import resolve_settings
from fsmbt.llm.pipeline import LLMOutcome, convert_with_llm, default_verifier
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError, Hint, UnsupportedError
from fsmbt.model.fsm import FSM

Model = FSM | BTDocument
DIRECTION = {True: "fsm->bt", False: "bt->fsm"}


class LLMConversionError(FsmbtError):
    """No answer of the model passed parsing, the structural check and verification (exit 2)."""


def client_from_options(options: dict[str, Any]) -> LLMClient:
    """An ``LLMClient`` from engine options + environment + config (``LLMConfigError`` if none)."""
    settings = resolve_settings(
        base_url=options.get("llm_base_url"),
        model=options.get("llm_model"),
        api_key=options.get("llm_api_key"),
        timeout_s=options.get("llm_timeout"),
        max_regenerations=options.get("max_regenerations"),
        log_path=options.get("llm_log"),
    )
    return LLMClient(settings)


def _refuse_loop(engine: str, options: dict[str, Any]) -> None:
    if options.get("loop"):
        raise UnsupportedError(
            f"engine '{engine}' converts without the loop option", hints=(Hint.RULES_ENGINE,)
        )


def _run(engine: str, model: Model, scp: bool, options: dict[str, Any]) -> ConversionResult:
    _refuse_loop(engine, options)
    client = options.get("client") or client_from_options(options)
    outcome = convert_with_llm(
        model,
        client,
        scp=scp,
        disabled_modules=_modules(options.get("ablate")),
        max_regenerations=options.get("max_regenerations"),
        verifier=default_verifier(options.get("verify_engine") or "native"),
        engine_name=engine,
        source_name=str(options.get("source_name") or "<input>"),
    )
    if not outcome.equivalent or outcome.result is None:
        raise LLMConversionError(_failure_message(engine, outcome))
    return ConversionResult(
        outcome.result, engine, DIRECTION[isinstance(model, FSM)], stats=_stats(outcome)
    )


def _failure_message(engine: str, outcome: LLMOutcome) -> str:
    record = outcome.record
    last = record.rounds[-1] if record.rounds else None
    why = "; ".join(last.problems[:3]) if last and last.problems else "no usable answer"
    stage = {
        "parse": "unreadable answer",
        "structure": "structurally wrong answer",
        "verify": "not equivalent",
    }.get(last.stage if last else "", "failed")
    return f"engine '{engine}': {stage} after {len(record.rounds)} round(s) ({record.model}): {why}"


def _stats(outcome: LLMOutcome) -> dict[str, Any]:
    r = outcome.record
    return {
        "prompt": r.prompt,
        "llm_model": r.model,
        "first_pass_success": r.first_pass_success,
        "regenerations": r.regenerations,
        "tokens_in": r.tokens_in,
        "tokens_out": r.tokens_out,
        "latency_s": r.latency_s,
        "verdict": r.verdict,
    }


def _modules(value: Any) -> Iterable[str]:
    if not value:
        return ()
    if isinstance(value, str):
        return [v.strip() for v in value.split(",") if v.strip()]
    return list(value)


def hybrid(model: Model, **options: Any) -> ConversionResult:
    """Rules conversion of an (LLM-extracted or parsed) model, verified before it is returned."""
    rules = converter_for("rules", model)
    rules_options = {k: v for k, v in options.items() if k in ("style", "loop")}
    converted = rules(model, **rules_options)
    report = default_verifier(options.get("verify_engine") or "native")(model, converted.model)
    if not report.equivalent:
        failing = ", ".join(p.name for p in report.properties.values() if not p.holds)
        raise LLMConversionError(
            f"engine 'hybrid': the rules result failed verification ({failing})"
        )
    stats = dict(converted.stats)
    stats.update(
        {
            "verified": True,
            "verify_engine": report.engine,
            "extracted_by_llm": bool(options.get("extracted_by_llm", False)),
        }
    )
    return ConversionResult(
        converted.model, "hybrid", converted.direction, stats, list(converted.warnings)
    )


register_engine(
    "llm",
    lambda m, **o: _run("llm", m, True, o),
    lambda m, **o: _run("llm", m, True, o),
    "an LLM with the paper's structured prompt, verified, with feedback rounds",
)
register_engine(
    "nllm",
    lambda m, **o: _run("nllm", m, False, o),
    lambda m, **o: _run("nllm", m, False, o),
    "baseline: the same LLM request without the stepwise procedure",
)
register_engine(
    "hybrid",
    hybrid,
    hybrid,
    "the LLM only extracts the source model; rules convert; the checker verifies",
)
