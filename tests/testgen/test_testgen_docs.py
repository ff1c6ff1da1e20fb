"""docs/testgen.md's example runs as written: the two commands print what the page shows and
the generated suite passes (both engines)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt.cli import main

pytest.importorskip("behaviortreepy")
pytest.importorskip("py_trees")
ROOT = Path(__file__).resolve().parents[2]
PAGE = (ROOT / "docs" / "testgen.md").read_text(encoding="utf-8")


def test_example(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    commands = [line.strip() for line in PAGE.splitlines() if line.startswith("    .venv/bin/")]
    [block] = re.findall(r"```text\n(.*?)```", PAGE, flags=re.S)
    convert, generate, run = (
        [a.replace("out/", f"{tmp_path}{os.sep}") for a in shlex.split(c)] for c in commands
    )
    assert main(convert[1:]) == 0
    capsys.readouterr()
    assert main(generate[1:]) == 0
    assert capsys.readouterr().out.replace(f"{tmp_path}{os.sep}", "out/") == block
    done = subprocess.run(
        [sys.executable, *run[1:], "-p", "no:xdist", "-p", "no:cacheprovider"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0 and "38 passed" in done.stdout, done.stdout[-500:]
