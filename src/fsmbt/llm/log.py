"""The per-conversion JSONL log: one line per LLM conversion or extraction.

Each line says what was asked (engine, direction, prompt label, endpoint model), how it went
(first-pass success, regenerations, per-round stage and problems) and what it cost (tokens in
and out, latency), and the final verdict. It is what the accuracy benchmark aggregates. The key
is never written. A log that cannot be written is reported once on stderr and never fails the
conversion itself.
"""

from __future__ import annotations

import json
import logging
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

LOG = logging.getLogger("fsmbt.llm")

#: Final verdicts a record can carry.
EQUIVALENT = "equivalent"
NOT_EQUIVALENT = "not_equivalent"
INVALID_ANSWER = "invalid_answer"  # never parsed or never passed the structural check
EXTRACTED = "extracted"
UNAVAILABLE = "endpoint_unavailable"


@dataclass
class RoundRecord:
    """One request/answer round. ``stage`` is where the answer stopped: parse, structure,
    verify, ok, or unavailable (the endpoint failed every attempt of this round).
    ``failures`` says why each failed attempt failed (cut-off, reset, timeout, HTTP status)."""

    round: int
    stage: str
    problems: list[str]
    tokens_in: int
    tokens_out: int
    latency_s: float
    attempts: int
    failures: list[str] = field(default_factory=list)  # cause of each failed attempt, in order


@dataclass
class ConversionRecord:
    engine: str
    task: str  # fsm_to_bt | bt_to_fsm | extract
    prompt: str
    model: str
    source: str
    verdict: str = INVALID_ANSWER
    first_pass_success: bool = False
    regenerations: int = 0
    tokens_in: int = 0
    tokens_out: int = 0
    latency_s: float = 0.0
    rounds: list[RoundRecord] = field(default_factory=list)
    time: str = field(default_factory=lambda: time.strftime("%Y-%m-%dT%H:%M:%S%z"))
    extra: dict[str, Any] = field(default_factory=dict)

    def add_round(self, entry: RoundRecord) -> None:
        self.rounds.append(entry)
        self.tokens_in += entry.tokens_in
        self.tokens_out += entry.tokens_out
        self.latency_s = round(self.latency_s + entry.latency_s, 4)
        self.regenerations = len(self.rounds) - 1
        self.first_pass_success = self.rounds[0].stage == "ok"

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def append_record(path: Path | None, record: ConversionRecord) -> None:
    """Append one JSON line to ``path`` (``None`` = logging off)."""
    if path is None:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("a", encoding="utf-8") as handle:
            handle.write(json.dumps(record.to_dict(), ensure_ascii=False) + "\n")
    except OSError as exc:
        # the library does not print (presentation is the CLI's): a logged warning, which
        # Python shows on stderr when no handler is configured
        LOG.warning("warning: cannot write the LLM log %s: %s", path, exc.strerror)


def read_records(path: Path) -> list[dict[str, Any]]:
    """Every record of a log file (for benchmarks and tests)."""
    if not path.exists():
        return []
    return [
        json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line.strip()
    ]
