"""The SCXML corpus table: of the well-formed SCXML files (``<corpus>/fsm/**/*.scxml`` without
``_malformed`` and ``_legacy_draft``), how many read, convert (FSM -> BT, rules engine) and
verify equivalent with the native checker, and why the others do not (the first reason
reported, grouped). Prints a Markdown table per file, then the totals by remaining reason.

    .venv/bin/python benchmarks/corpus_scxml.py [CORPUS]   (default: $FSMBT_CORPUS or
                                                            ../shared/corpus)
"""

from __future__ import annotations

import os
import re
import sys
import time
from collections import Counter
from pathlib import Path

from fsmbt import api
from fsmbt.model.errors import FsmbtError


def reason_of(error: Exception) -> str:
    """A short group name for a refusal (``unsupported: <send> with a delay``)."""
    text = str(error)
    found = re.search(
        r"(unsupported: [^,(]+|not an SCXML document[^:(]*|unknown SCXML "
        r"element <\w+>)",
        text,
    )
    reason = (found.group(1) if found else text.split(": ", 2)[-1]).strip()
    return re.sub(r"'[^']*'", "'…'", reason)[:70]


def main() -> int:
    default = os.environ.get(
        "FSMBT_CORPUS", str(Path(__file__).resolve().parents[1] / ".." / "shared" / "corpus")
    )
    corpus = Path(sys.argv[1] if len(sys.argv) > 1 else default) / "fsm"
    files = sorted(
        p
        for p in corpus.rglob("*.scxml")
        if "_malformed" not in p.parts and "_legacy_draft" not in p.parts
    )
    if not files:
        print(f"no SCXML files under {corpus}", file=sys.stderr)
        return 2
    print("| file | result | reader | states | ms |")
    print("|---|---|---|---|---|")
    reasons: Counter[str] = Counter()
    readers: Counter[str] = Counter()
    verified = 0
    for path in files:
        start = time.perf_counter()
        try:
            outcome = api.convert_file(path, to="btcpp")
            word = api.verdict_word(outcome.report)
            states = len(getattr(outcome.source.model, "states", {}))
            w3c = any("W3C algorithm" in w for w in outcome.source.warnings)
            reader = "W3C algorithm (flat)" if w3c else "structural"
            readers[reader] += 1
            if outcome.report is not None and outcome.report.equivalent:
                verified += 1
                result = "converts + verifies"
            else:
                result = f"converts, verdict {word}"
                reasons[f"not verified ({word})"] += 1
        except FsmbtError as exc:
            result, states, reader = reason_of(exc), 0, ""
            reasons[result] += 1
        ms = (time.perf_counter() - start) * 1000
        print(f"| {path.relative_to(corpus)} | {result} | {reader} | {states or ''} | {ms:.0f} |")
    total = len(files)
    print(
        f"\n**{verified} of {total} well-formed SCXML files convert and verify "
        f"({100 * verified / total:.0f} %); read by "
        + ", ".join(f"{name} {count}" for name, count in sorted(readers.items()))
        + ".**\n"
    )
    print("| remaining reason | files |")
    print("|---|---|")
    for reason, count in reasons.most_common():
        print(f"| {reason} | {count} |")
    abstracted = 0
    for path in files:  # the same files with the opt-in abstraction of timers
        try:
            outcome = api.convert_file(path, to="btcpp", options={"abstract": "time"})
            abstracted += bool(outcome.report is not None and outcome.report.equivalent)
        except FsmbtError:
            pass
    print(
        f"\nWith the abstraction `abstract=time` (a delayed <send> is an environment input): "
        f"**{abstracted} of {total} ({100 * abstracted / total:.0f} %)** convert and verify."
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
