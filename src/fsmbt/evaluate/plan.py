"""Which engine runs on which model: the evaluation's jobs, and the engines that cannot run.

Rules:
- ``rules``, ``bsd`` and ``chds`` run on every readable model, verified by the native checker.
- NuSMV verifies a stated sample (``nusmv_models``): the examples named in ``NUSMV_EXAMPLES``
  (the robot BT of the paper, ~1 s per engine, and the predator FSM), then ``nusmv_sample``
  models drawn with the run's seed from the readable generated ones of at most
  ``NUSMV_MAX_STATES`` states / ``NUSMV_MAX_NODES`` nodes; each converted by the three rule
  engines and checked with ``both`` (native and NuSMV must agree; a disagreement is an
  ``error`` row naming it). Why a sample: NuSMV is 100x-5 000x slower than the native checker
  and the ratio grows with size (docs/nusmv.md, "Cost"); the native checker covers every model.
- ``llm``, ``nllm`` and the SCP ablations (``llm`` without one SCP module each: the paper's
  Tables II/VII) run only when an OpenAI-compatible endpoint is configured
  (``fsmbt.llm.config.resolve_settings``), once per ``--llm-model``. Otherwise every table
  shows them as ``NOT_RUN`` ("not run: no endpoint"), never as a number.
- A job's key is ``<model id>|<method>|<verifier>|<sha256 prefix>``: the same model, method
  and verifier on an unchanged file is the same job, so a resumed run skips it.
- Results are written as fsmbt JSON (both kinds) so the element counts read them back exactly;
  a result that is not equivalent is kept too (``keep_not_equivalent``) so it can be measured.

Cost: O(models x methods) jobs, built in memory.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fsmbt.evaluate.dataset import Entry
from fsmbt.evaluate.runner import Job

RULE_ENGINES = ("rules", "bsd", "chds")
#: The rules engine's structured style, a method of its own on outcome-driven machines (the
#: SMACH/FlexBE/YASMIN files: Python sources); not the paper's, so not in ``RULE_ENGINES``.
STRUCTURED = "structured"
LLM_METHODS = ("llm", "nllm")
#: The SCP modules of each direction (fsmbt.llm.prompts.MODULES), one ablation each.
ABLATIONS = ("structure_recognition", "lebt_mapping", "depth_compression", "hierarchical_rules")
NOT_RUN = "not run: no endpoint"
#: The checker's state limit per job (products of 30-state FSMs stay far below it).
MAX_STATES = 200_000


@dataclass(frozen=True)
class Planned:
    """A job and what it measures."""

    job: Job
    entry_id: str
    method: str  # engine name, "llm[model]" or "llm-no-<module>[model]"
    verifier: str


def endpoint_models(requested: list[str]) -> tuple[list[str], str | None]:
    """The LLM models to run, or none with the reason.

    Args:
        requested: the ``--llm-model`` values (empty: the configured default model).

    Returns:
        ``(models, None)`` when an endpoint is configured, else ``([], reason)``.
    """
    from fsmbt.llm.config import LLMConfigError, resolve_settings

    try:
        settings = resolve_settings(model=requested[0] if requested else None)
    except LLMConfigError:
        return [], NOT_RUN
    return (requested or [settings.model]), None


def llm_method_names(models: list[str]) -> list[str]:
    """Every LLM method label of a run (``llm[m]``, ``nllm[m]``, ``llm-no-<module>[m]``)."""
    names = []
    for model in models:
        names += [f"llm[{model}]", f"nllm[{model}]"]
        names += [f"llm-no-{module}[{model}]" for module in ABLATIONS]
    return names


def outcome_driven(entry: Entry) -> bool:
    """An FSM read from a Python source (SMACH, FlexBE, YASMIN): its events are outcomes."""
    return entry.kind == "fsm" and entry.path.endswith(".py")


def method_style(engine: str) -> dict[str, Any]:
    """``rules`` is the paper's LEBT shape (``--style lebt``) whatever the model: the
    evaluation measures the paper's method (the structured style is not the paper's)."""
    return {"style": "lebt"} if engine == "rules" else {}


def _job(
    entry: Entry, outdir: Path, method: str, engine: str, verifier: str, options: dict[str, Any]
) -> Planned:
    folder = method if verifier == "native" else f"{method}-{verifier}"
    output = outdir / "outputs" / folder / f"{entry.id}.json"
    job = Job(
        input=entry.path,
        output=str(output),
        engine=engine,
        verify_engine=verifier,
        options={"to": "json", "keep_not_equivalent": True, "max_states": MAX_STATES, **options},
        overwrite=True,
        key=f"{entry.id}|{method}|{verifier}|{entry.sha256[:16]}",
    )
    return Planned(job, entry.id, method, verifier)


#: The NuSMV sample is drawn from models at most this large (NuSMV's BDDs of a 30-state
#: FSM's loop-execution BT take minutes; the native checker covers every model anyway).
NUSMV_MAX_STATES = 10
NUSMV_MAX_NODES = 30


#: Examples always in the NuSMV sample when ``nusmv_sample`` > 0 and they are in the dataset.
NUSMV_EXAMPLES = ("example_robot_bt.xml", "example_predator_fsm.csv")


def _small(entry: Entry) -> bool:
    if entry.kind == "fsm":
        return entry.size.get("states", 0) <= NUSMV_MAX_STATES
    return entry.size.get("nodes", 0) <= NUSMV_MAX_NODES


def nusmv_models(entries: list[Entry], *, seed: int, count: int) -> list[Entry]:
    """The models NuSMV also checks (see the module text).

    Args:
        entries: the dataset.
        seed: the run's seed.
        count: how many generated models to draw (0: no NuSMV at all).

    Returns:
        The ``NUSMV_EXAMPLES`` present and readable, then ``count`` drawn generated models.
    """
    if count <= 0:
        return []
    readable = [e for e in entries if e.readable]
    examples = [e for name in NUSMV_EXAMPLES for e in readable if e.id == name]
    pool = [e for e in readable if e.source == "generated" and _small(e)]
    return examples + random.Random(f"nusmv:{seed}").sample(pool, min(count, len(pool)))


def plan(
    entries: list[Entry], outdir: Path, *, seed: int, nusmv_sample: int, llm_models: list[str]
) -> list[Planned]:
    """Every job of the run, rule engines first (so the LLM's long jobs come last).

    Args:
        entries: the dataset.
        outdir: the report folder (outputs go to ``<outdir>/outputs/<method>/``).
        seed: the run's seed (draws the NuSMV sample).
        nusmv_sample: how many models NuSMV also checks (0: none).
        llm_models: the LLM models to run (empty: no LLM jobs).

    Returns:
        The planned jobs.
    """
    readable = [e for e in entries if e.readable]
    planned = [
        _job(e, outdir, engine, engine, "native", method_style(engine))
        for engine in RULE_ENGINES
        for e in entries
    ]
    planned += [
        _job(e, outdir, STRUCTURED, "rules", "native", {"style": STRUCTURED})
        for e in readable
        if outcome_driven(e)
    ]
    sample = nusmv_models(readable, seed=seed, count=nusmv_sample)
    planned += [
        _job(e, outdir, engine, engine, "both", method_style(engine))
        for engine in RULE_ENGINES
        for e in sample
    ]
    for model in llm_models:
        llm = {"llm_model": model}
        for e in readable:
            planned.append(_job(e, outdir, f"llm[{model}]", "llm", "native", llm))
            planned.append(_job(e, outdir, f"nllm[{model}]", "nllm", "native", llm))
            direction_modules = ABLATIONS[:2] if e.kind == "fsm" else ABLATIONS[2:]
            for module in direction_modules:
                planned.append(
                    _job(
                        e,
                        outdir,
                        f"llm-no-{module}[{model}]",
                        "llm",
                        "native",
                        {**llm, "ablate": [module]},
                    )
                )
    return planned
