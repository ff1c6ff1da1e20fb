"""Every corpus file that parses converts and verifies equivalent, or is rejected with a clear
``InputError``/``UnsupportedError`` (never another exception). Counts are printed (-s)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.model.errors import InputError
from support.conv_helpers import check
from support.corpus import CORPUS

MAX_CHECK_STATES = 200_000


def _files() -> list[Path]:
    if not CORPUS.is_dir():
        return []
    return sorted(
        p
        for p in CORPUS.rglob("*")
        if p.suffix in (".xml", ".scxml")
        and "_malformed" not in p.parts
        and "_legacy_draft" not in p.parts
        and "LICENSES" not in p.parts
    )


def test_corpus_converts_or_is_rejected_clearly() -> None:
    files = _files()
    if not files:
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    counts: Counter[str] = Counter()
    failures: list[str] = []
    for path in files:
        try:
            model = api.load(path).model
        except InputError:
            counts["unreadable"] += 1
            continue
        try:
            result = convert(model)
            report = check(model, result.model, max_states=MAX_CHECK_STATES)
        except InputError as exc:
            assert str(exc).strip(), path
            counts[f"rejected: {type(exc).__name__}"] += 1
            continue
        if report.equivalent:
            counts[f"equivalent {result.direction}"] += 1
        else:
            failures.append(str(path))
    print(f"\ncorpus conversion ({len(files)} files): {dict(counts)}")
    assert failures == []
    assert sum(v for k, v in counts.items() if k.startswith("equivalent")) > 0
