"""One row of a batch: what happened to one input (``JobResult``), and the status words.

The statuses (docs/batch.md, "Statuses"), each input gets exactly one:

- ``equivalent`` / ``not_equivalent``: converted and verified; the verdict says which.
- ``not_verified``: converted, verification switched off.
- ``refused``: the engine cannot convert this model exactly (``UnsupportedError``), or the
  output exists and replacing it was not asked for (``DestinationExists``).
- ``bad_input``: the input cannot be read as a model (``InputError``: unreadable, malformed,
  hostile, too large, too deep).
- ``timeout`` / ``limit``: the per-model time limit or the checker's state limit was reached.
- ``error``: anything else (an LLM endpoint that kept failing, a worker that died, an engine
  disagreement, an internal error), with the class and message.

A row is *retryable* when running it again may give a different answer without changing the
input or the options: an LLM request that failed, a worker that died, an output that existed.
A resumed batch runs retryable rows again and skips the rest.

Costs: constant per row.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

EQUIVALENT = "equivalent"
NOT_EQUIVALENT = "not_equivalent"
NOT_VERIFIED = "not_verified"
REFUSED = "refused"
BAD_INPUT = "bad_input"
ERROR = "error"
TIMEOUT = "timeout"
LIMIT = "limit"
#: Every status, in the order summaries list them.
STATUSES = (EQUIVALENT, NOT_EQUIVALENT, NOT_VERIFIED, REFUSED, BAD_INPUT, ERROR, TIMEOUT, LIMIT)
#: Error classes whose rows a resumed batch runs again.
RETRYABLE_ERRORS = ("LLMUnavailableError", "WorkerDied", "DestinationExists")


@dataclass
class JobResult:
    """What happened to one input.

    Attributes:
        key: the job's key (``Job.key``).
        input: the input file.
        status: one of ``STATUSES``.
        verdict: ``EQUIVALENT``, ``NOT EQUIVALENT``, ``NOT VERIFIED`` or ``None`` (no result).
        properties: the five properties' names -> holds (empty without a report).
        error_class: the error's class name, or ``None``.
        error_message: the error in one line (located), or ``None``.
        timings: seconds per step ("read", "convert", "verify", "write", "total").
        output: the file written, or ``None``.
        stats: the conversion's stats, the report's product states and the source/result
            sizes, the source format, the direction and the engine.
        engine: the conversion engine.
        verify_engine: the verifier.
        options: the job's options (limits included).
        attempts: how many times a worker started this job (more than one after a death).
        retry: a resumed batch runs this row again (see the module text).
        finished_at: seconds since the epoch when the row was stored.
        dependencies: the other files the model was made of (includes, SubTree and node
            files, invoked machines; missing ones too) -> their ``content_hash`` when the job
            ran; a resumed batch runs the row again when one of them changed.
    """

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
    options: dict[str, Any] = field(default_factory=dict)
    attempts: int = 1
    retry: bool = False
    finished_at: float = 0.0
    dependencies: dict[str, str] = field(default_factory=dict)

    @property
    def seconds(self) -> float:
        """The job's wall time in the worker (``timings["total"]``, else the steps' sum)."""
        if "total" in self.timings:
            return float(self.timings["total"])
        return float(sum(self.timings.values()))

    @property
    def reason(self) -> str:
        """The error message, or the verdict, for tables."""
        return self.error_message or self.verdict or self.status

    def to_row(self) -> dict[str, Any]:
        """A flat, JSON-ready dict (one per input; ``--json`` prints a list of these).

        Returns:
            Every attribute, plus ``seconds``.
        """
        row = asdict(self)
        row["seconds"] = round(self.seconds, 6)
        return row

    @classmethod
    def from_row(cls, row: dict[str, Any]) -> JobResult:
        """The inverse of ``to_row`` (unknown keys are ignored)."""
        names = set(cls.__dataclass_fields__)
        return cls(**{k: v for k, v in row.items() if k in names})
