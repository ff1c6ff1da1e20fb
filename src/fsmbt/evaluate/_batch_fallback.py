"""A private stand-in for ``fsmbt.batch`` (issue 14) until that package is merged.

DELETE AT MERGE: ``fsmbt.evaluate.runner`` imports ``fsmbt.batch`` first and uses this module
only when it is missing. Same names and contract as the batch runner: ``Job``, ``JobResult``
(``to_row``), ``make_jobs``, ``run_job``, ``ResultStore`` (SQLite: ``done``, ``put``,
``results``, ``summary``), ``run_jobs`` (skips done keys, so a killed run resumes).

Every job calls ``fsmbt.api.convert_file``; nothing of the pipeline is redone here. Limits: the
``local`` executor is a process pool; ``ray`` is refused (the real runner has it); there is no
per-job time limit (the checker's ``max_states`` bounds each verification).
Costs: one SQLite row per job, committed as it arrives.
"""

from __future__ import annotations

import hashlib
import json
import sqlite3
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from fsmbt import api
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.verify.native import DEFAULT_MAX_STATES

EQUIVALENT = "equivalent"
NOT_EQUIVALENT = "not_equivalent"
NOT_VERIFIED = "not_verified"
REFUSED = "refused"
BAD_INPUT = "bad_input"
ERROR = "error"
LIMIT = "limit"
STATUSES = (EQUIVALENT, NOT_EQUIVALENT, NOT_VERIFIED, REFUSED, BAD_INPUT, ERROR, LIMIT)


@dataclass(frozen=True)
class Job:
    """One input to convert and verify (see ``fsmbt.batch.Job``)."""

    input: str
    output: str | None = None
    engine: str = "rules"
    verify_engine: str = "native"
    options: dict[str, Any] = field(default_factory=dict)
    overwrite: bool = False
    key: str = ""

    def __post_init__(self) -> None:
        if not self.key:
            settings = json.dumps(
                [
                    self.input,
                    self.output,
                    self.engine,
                    self.verify_engine,
                    sorted(self.options.items()),
                ],
                default=str,
            )
            object.__setattr__(self, "key", hashlib.sha256(settings.encode()).hexdigest()[:32])

    def __hash__(self) -> int:
        return hash(self.key)


@dataclass
class JobResult:
    """What happened to one input (see ``fsmbt.batch.JobResult``)."""

    key: str
    input: str
    status: str
    verdict: str | None = None
    properties: dict[str, bool] = field(default_factory=dict)
    error_class: str | None = None
    error_message: str | None = None
    timings: dict[str, float] = field(default_factory=dict)
    output: str | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    engine: str = "rules"
    verify_engine: str = "native"

    def to_row(self) -> dict[str, Any]:
        """A flat, JSON-ready dict."""
        return asdict(self)


def make_jobs(
    inputs: Sequence[str | Path],
    outdir: Path,
    *,
    engine: str = "rules",
    verify_engine: str = "native",
    options: dict[str, Any] | None = None,
    to: str | None = None,
) -> list[Job]:
    """One job per input file, outputs named after the inputs under ``outdir``."""
    job_options = dict(options or {})
    if to is not None:
        job_options["to"] = to
    return [
        Job(
            str(path),
            str(Path(outdir) / f"{Path(path).name}.out"),
            engine,
            verify_engine,
            dict(job_options),
        )
        for path in inputs
    ]


def run_job(job: Job) -> JobResult:
    """Convert and verify one input with ``fsmbt.api.convert_file``; problems become rows."""
    started = time.perf_counter()
    result = JobResult(
        job.key, job.input, ERROR, engine=job.engine, verify_engine=job.verify_engine
    )
    options = dict(job.options)
    try:
        outcome = api.convert_file(
            job.input,
            job.output,
            to=options.pop("to", None),
            source_format=options.pop("source_format", None),
            engine=job.engine,
            loop=bool(options.pop("loop", False)),
            verify=job.verify_engine != "none",
            verify_engine=job.verify_engine if job.verify_engine != "none" else "native",
            max_states=int(options.pop("max_states", DEFAULT_MAX_STATES)),
            overwrite=job.overwrite,
            keep_not_equivalent=bool(options.pop("keep_not_equivalent", False)),
            options=options,
        )
    except Exception as error:  # noqa: BLE001 - every problem of a model is a row
        name = type(error).__name__
        result.status = (
            REFUSED
            if isinstance(error, UnsupportedError)
            else LIMIT
            if name == "StateLimitError"
            else BAD_INPUT
            if isinstance(error, InputError | RecursionError)
            else ERROR
        )
        result.error_class = name
        result.error_message = " ".join(str(error).split()) or name
        result.timings = {"total": time.perf_counter() - started}
        return result
    result.timings = {**outcome.timings, "total": time.perf_counter() - started}
    result.stats = {
        "conversion": outcome.conversion.stats,
        "direction": outcome.conversion.direction,
        "source_format": outcome.source.format,
    }
    result.verdict = outcome.verdict
    if outcome.report is None:
        result.status = NOT_VERIFIED
    else:
        result.status = EQUIVALENT if outcome.report.equivalent else NOT_EQUIVALENT
        result.properties = outcome.report.verdicts()
    if outcome.written and outcome.output is not None:
        result.output = str(outcome.output)
    return result


class ResultStore:
    """The SQLite store: one row per job key, committed as it arrives."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._db = sqlite3.connect(str(self.path))
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute(
            "CREATE TABLE IF NOT EXISTS results (key TEXT PRIMARY KEY, status TEXT, row TEXT)"
        )
        self._db.commit()

    def put(self, result: JobResult) -> None:
        """Store (or replace) the row of ``result.key``."""
        with self._db:
            self._db.execute(
                "INSERT OR REPLACE INTO results VALUES (?, ?, ?)",
                (result.key, result.status, json.dumps(result.to_row())),
            )

    def done(self, key: str) -> bool:
        """Whether a row for ``key`` is stored."""
        return (
            self._db.execute("SELECT 1 FROM results WHERE key = ?", (key,)).fetchone() is not None
        )

    def results(self) -> list[JobResult]:
        """Every stored row."""
        names = set(JobResult.__dataclass_fields__)
        return [
            JobResult(**{k: v for k, v in json.loads(text).items() if k in names})
            for (text,) in self._db.execute("SELECT row FROM results ORDER BY rowid")
        ]

    def summary(self) -> dict[str, Any]:
        """Rows per status and the total."""
        counts = dict(self._db.execute("SELECT status, COUNT(*) FROM results GROUP BY status"))
        return {"total": sum(counts.values()), "statuses": counts}

    def close(self) -> None:
        """Close the database."""
        self._db.close()


_WARM_UP = (
    '{"kind": "fsm", "name": "warm_up", "initial": "A", "states": [{"name": "A", '
    '"action": "a"}, {"name": "B", "action": "b"}], "transitions": [{"source": "A", '
    '"event": "e", "target": "B"}, {"source": "B", "event": "f", "target": "A"}]}'
)


def warm_up() -> None:
    """Import and run the pipeline once per worker, both directions and every rule engine, so a
    worker's first job is not charged the library's imports (seconds)."""
    for engine in ("rules", "bsd", "chds"):
        outcome = api.convert_loaded(api.load_text(_WARM_UP, "json"), engine=engine)
        api.convert_loaded(api.load_text(outcome.text, outcome.output_format), engine=engine)


def run_jobs(
    jobs: Sequence[Job],
    *,
    store: ResultStore | None = None,
    executor: str = "local",
    workers: int = 1,
    ray_address: str | None = None,
    on_result: Callable[[JobResult], None] | None = None,
) -> list[JobResult]:
    """Run the jobs whose key is not in ``store``; store each result as it arrives."""
    if executor != "local":
        raise InputError(
            f"the executor {executor!r} needs fsmbt.batch (issue 14); "
            "this stand-in runs local processes only"
        )
    todo = [job for job in jobs if store is None or not store.done(job.key)]
    collected: list[JobResult] = []

    def deliver(result: JobResult) -> None:
        if store is not None:
            store.put(result)
        collected.append(result)
        if on_result is not None:
            on_result(result)

    if workers <= 1:
        if todo:
            warm_up()
        for job in todo:
            deliver(run_job(job))
        return collected
    with ProcessPoolExecutor(max_workers=workers, initializer=warm_up) as pool:
        pending = set()
        queue = iter(todo)
        for job in queue:
            pending.add(pool.submit(run_job, job))
            if len(pending) >= workers * 4:
                break
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in finished:
                deliver(future.result())
                nxt = next(queue, None)
                if nxt is not None:
                    pending.add(pool.submit(run_job, nxt))
    return collected
