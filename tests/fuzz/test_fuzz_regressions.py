"""Every input the fuzzer ever found (tests/fuzz/regressions/<reader>/*.input) now ends in an
allowed outcome: a model, or an InputError/UnsupportedError with a one-line located cause.

The rule is the fuzz worker's own (``check_input`` in fuzz/fuzz_readers.py), so a regression is
judged exactly as the fuzzer judged it. The ``.cause`` file next to each input says what it did
when it was found.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt.formats import formats, get_format
from support.fuzz_harness_loader import REGRESSIONS, harness

INPUTS = sorted(REGRESSIONS.glob("*/*.input"))


def test_regression_folder_holds_inputs_for_known_readers_only() -> None:
    readers = {f.name for f in formats() if f.read is not None}
    assert INPUTS, "no saved fuzz inputs: the regression folder is missing"
    unknown = sorted({p.parent.name for p in INPUTS} - readers)
    assert not unknown, f"regression inputs for readers that do not exist: {unknown}"


@pytest.mark.parametrize("path", INPUTS, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_saved_fuzz_input_gives_an_allowed_outcome(path: Path, tmp_path: Path) -> None:
    reader = path.parent.name
    fake = tmp_path / f"input{get_format(reader).extensions[0]}"
    outcome = harness().check_input(reader, path.read_bytes(), fake)
    cause = path.with_suffix(".cause")
    found = cause.read_text(encoding="utf-8").strip() if cause.exists() else "?"
    assert outcome is None, f"{outcome} (when found: {found})"
