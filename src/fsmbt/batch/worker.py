"""One job in a worker: the library's pipeline for one input, every problem turned into a row.

``run_job`` calls ``fsmbt.api`` and nothing else does the work: ``convert_file`` for the
parser-read engines, ``load_for_llm`` then ``convert_loaded`` for the LLM engines (so the
client can be wrapped in the batch's per-minute limit). It never raises for a model's problem;
each exception becomes a status (``fsmbt.batch.result``):

=========================================  ==============
``DestinationExists``                      refused (retryable: ``--force`` replaces it)
``UnsupportedError``                       refused
``LimitError`` (a bound of fsmbt.limits)   limit
the per-model time limit                   timeout
``LLMUnavailableError``                    error (retryable: run again on resume)
other ``InputError``, deep or huge input   bad_input
anything else                              error (class and message kept)
=========================================  ==============

The time limit (``options["timeout_s"]``) is enforced in the worker by ``SIGALRM``
(``signal.setitimer``) when the job runs on the process's main thread, which is where pool and
Ray workers run tasks; the driver's watchdog kills a worker that overruns it by far (a model
stuck in C code), see ``fsmbt.batch.local``.

Pool and Ray workers call ``warm_up`` once before their first job, so no input's time includes
the library's imports. Executors hand jobs out in chunks (``run_chunk``: several jobs per task,
one pickled round trip).

Costs: those of the pipeline, plus one ``model_stats`` pass over each model.
"""

from __future__ import annotations

import json
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import Any

from fsmbt import api
from fsmbt.batch.jobs import Job, content_hash, public_options
from fsmbt.batch.ratelimit import MinuteRateLimit, RateLimitedClient
from fsmbt.batch.result import (
    BAD_INPUT,
    EQUIVALENT,
    ERROR,
    LIMIT,
    NOT_EQUIVALENT,
    NOT_VERIFIED,
    REFUSED,
    RETRYABLE_ERRORS,
    TIMEOUT,
    JobResult,
)
from fsmbt.model.errors import InputError, LimitError, UnsupportedError
from fsmbt.model.files import recording_reads
from fsmbt.model.fsm import FSM
from fsmbt.model.stats import model_stats

#: The options ``run_job`` hands to ``fsmbt.api`` as keyword arguments, not engine options.
PIPELINE_OPTIONS = (
    "to",
    "source_format",
    "style",
    "loop",
    "hierarchy",
    "max_states",
    "keep_not_equivalent",
)


class JobTimeout(BaseException):
    """The per-model time limit passed (a ``BaseException``: library code cannot swallow it)."""


@contextmanager
def time_limit(seconds: float | None) -> Iterator[None]:
    """Raise ``JobTimeout`` in the block after ``seconds`` (main thread only; else no limit).

    Args:
        seconds: the limit, or ``None``/``0`` for none.
    """
    if not seconds or threading.current_thread() is not threading.main_thread():
        yield
        return

    def expire(signum: int, frame: FrameType | None) -> None:
        raise JobTimeout(f"no result within the time limit of {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, float(seconds))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _size(model: Any) -> dict[str, Any]:
    stats: Any = model_stats(model)  # FSMStats for an FSM, BTStats for a BT
    if isinstance(model, FSM):
        return {"kind": "fsm", "states": stats.all_states, "transitions": stats.all_transitions}
    return {"kind": "bt", "nodes": stats.nodes, "depth": stats.depth}


def _one_line(error: BaseException) -> str:
    return " ".join(str(error).split()) or type(error).__name__


def _classify(error: BaseException) -> tuple[str, bool]:
    """The status and whether a resume runs it again, for an exception out of the pipeline."""
    name = type(error).__name__
    retry = name in RETRYABLE_ERRORS
    if isinstance(error, JobTimeout):
        return TIMEOUT, False
    if isinstance(error, LimitError):
        return LIMIT, False
    if isinstance(error, api.DestinationExists):
        return REFUSED, True
    if isinstance(error, UnsupportedError):
        return REFUSED, False
    if name == "LLMUnavailableError":
        return ERROR, True
    if isinstance(error, InputError):
        return BAD_INPUT, False
    if isinstance(error, (RecursionError, MemoryError)):
        return BAD_INPUT, False
    return ERROR, retry


def _pipeline(job: Job, options: dict[str, Any], timings: dict[str, float]) -> api.Outcome:
    """The library's pipeline for ``job`` (see the module text).

    The job's JSON options become one ``ConvertRequest``: the pipeline options by name, the
    reader options (``nodes``, ``abstract``...) and engine options through the request's own
    split, so the batch takes every option ``convert`` takes and validates it the same way.
    A limit left unset is the limits in force (``FSMBT_MAX_CHECKER_STATES``...), as in ``convert``.
    """
    options.pop("timeout_s", None)
    pipeline = {name: options.pop(name) for name in PIPELINE_OPTIONS if name in options}
    verify = job.verify_engine != "none"
    request = api.convert_request(
        engine=job.engine,
        verify=verify,
        verify_engine=job.verify_engine if verify else "native",
        overwrite=job.overwrite,
        options=options,
        **pipeline,
    )
    if job.engine not in api.LLM_ENGINES:
        return api.convert_file(job.input, job.output, request)
    if job.output is not None:
        api.check_destination(job.output, overwrite=job.overwrite)
    started = time.perf_counter()
    loaded, client = api.load_for_llm(job.input, request)
    timings["read"] = time.perf_counter() - started
    per_minute = job.runtime.get("llm_rate_per_minute")
    rate_file = job.runtime.get("llm_rate_file")
    if per_minute and rate_file:
        if client is None:
            from fsmbt.llm.engine import client_from_options

            client = client_from_options(dict(request.engine_options))
        client = RateLimitedClient(client, MinuteRateLimit(rate_file, int(per_minute)))
    return api.convert_loaded(loaded, job.output, request, llm_client=client)


#: A two-state FSM converted both ways by ``warm_up``.
_WARM_UP_MODEL = json.dumps(
    {
        "kind": "fsm",
        "name": "warm_up",
        "initial": "A",
        "states": [{"name": "A", "action": "a"}, {"name": "B", "action": "b"}],
        "transitions": [
            {"source": "A", "event": "e", "target": "B"},
            {"source": "B", "event": "f", "target": "A"},
        ],
    }
)
_warmed = False


def warm_up() -> None:
    """Import and exercise the pipeline once per worker process (both directions, verified).

    Without it the first job of every worker pays the library's imports (seconds), which
    would show as that input's time in the batch's "slowest inputs". Idempotent.
    """
    global _warmed
    if _warmed:
        return
    _warmed = True
    try:
        outcome = api.convert_loaded(api.load_text(_WARM_UP_MODEL, "json"))
        api.convert_loaded(api.load_text(outcome.text, outcome.output_format))
    except Exception:  # noqa: BLE001 - warming is an optimisation; jobs report real problems
        pass


def _dependencies(job: Job, reads: list[Path]) -> dict[str, str]:
    """The files other than the input that the job asked for -> their content hash now
    (``JobResult.dependencies``; the output is written, never read, so it is not one)."""
    try:
        own = Path(job.input).resolve()
    except (OSError, RuntimeError):
        own = Path(job.input).absolute()
    return {str(path): content_hash(path) for path in reads if path != own}


def run_job(job: Job) -> JobResult:
    """Convert and verify one input; every problem becomes the row's status.

    Args:
        job: the job.

    Returns:
        Its ``JobResult`` (``finished_at`` is set by the store).
    """
    started = time.perf_counter()
    timings: dict[str, float] = {}
    result = JobResult(
        job.key,
        job.input,
        ERROR,
        engine=job.engine,
        verify_engine=job.verify_engine,
        options=public_options(job.options),
    )
    options = {k: v for k, v in job.options.items()}
    try:
        with time_limit(job.options.get("timeout_s")), recording_reads() as reads:
            try:
                outcome = _pipeline(job, options, timings)
            finally:
                result.dependencies = _dependencies(job, reads)
            stats: dict[str, Any] = {
                "conversion": outcome.conversion.stats,
                "direction": outcome.conversion.direction,
                "source_format": outcome.source.format,
                "output_format": outcome.output_format,
                "source_size": _size(outcome.source.model),
                "result_size": _size(outcome.result),
                "warnings": len(outcome.warnings),
            }
            if outcome.load is not None:  # docs/semantics.md §5, "Every written tree loads"
                stats["loads"] = outcome.load.summary()
            if outcome.report is not None:
                for name in ("product_states", "product_edges", "source_states", "result_states"):
                    if name in outcome.report.stats:
                        stats[name] = outcome.report.stats[name]
    except BaseException as error:  # noqa: BLE001 - every problem of a model is a row
        if isinstance(error, (KeyboardInterrupt, SystemExit)):
            raise
        result.status, result.retry = _classify(error)
        result.error_class = type(error).__name__
        result.error_message = _one_line(error)
        timings["total"] = time.perf_counter() - started
        result.timings = timings
        return result
    result.timings = {**timings, **outcome.timings, "total": time.perf_counter() - started}
    result.stats = stats
    result.verdict = outcome.verdict
    if outcome.report is None:
        result.status = NOT_VERIFIED
    else:
        result.status = EQUIVALENT if outcome.report.equivalent else NOT_EQUIVALENT
        result.properties = outcome.report.verdicts()
    if outcome.written and outcome.output is not None:
        result.output = str(Path(outcome.output))
        # what the batch wrote: a re-run may replace this file only while it is still this
        result.stats["output_hash"] = content_hash(result.output)
    return result


def run_chunk(jobs: list[Job]) -> list[JobResult]:
    """Run jobs one after another in this worker, each under its own time limit (the body of
    a pool task or a Ray task: one round trip for several jobs). Warms the worker up first."""
    warm_up()
    return [run_job(job) for job in jobs]
