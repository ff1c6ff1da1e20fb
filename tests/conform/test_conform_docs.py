"""docs/conform.md's examples run as written (real BehaviorTree.CPP runs: behaviortreepy and the
C++ driver) and print what the page shows (time stamps, shown as '…', masked)."""

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
ROOT = Path(__file__).resolve().parents[2]
PAGE = (ROOT / "docs" / "conform.md").read_text(encoding="utf-8")


def _commands() -> list[str]:
    return [line.strip() for line in PAGE.splitlines() if line.startswith("    .venv/bin/")]


def _pattern(block: str) -> re.Pattern[str]:
    return re.compile(
        "".join(".*?" if part == "…" else re.escape(part) for part in re.split("(…)", block)), re.S
    )


def test_example(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    blocks = re.findall(r"```text\n(.*?)```", PAGE, flags=re.S)
    outputs: list[tuple[int, str]] = []
    for command in _commands():
        args = [a.replace("out/", f"{tmp_path}{os.sep}") for a in shlex.split(command)]
        if args[0].endswith("python"):
            subprocess.run([sys.executable, *args[1:]], check=True, capture_output=True)
            continue
        code = main(args[1:])
        outputs.append((code, capsys.readouterr().out.replace(f"{tmp_path}{os.sep}", "out/")))
    # the last command conforms the C++ driver's .db3 and .btlog logs (docs: 'Recording a run
    # in C++'); seeded std::mt19937 outcomes, so its output is exact
    assert [code for code, _ in outputs] == [0, 1, 0, 0, 0]
    assert outputs[0][1] == blocks[0]
    assert outputs[4][1] == blocks[2]
    assert _pattern(blocks[1]).fullmatch(outputs[1][1]), outputs[1][1]
    assert "conforms" in outputs[3][1] and "DEVIATES" not in outputs[3][1]
