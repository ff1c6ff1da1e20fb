"""docs/diff.md's example runs as written and prints what the page shows."""

from __future__ import annotations

import os
import re
import shlex
from pathlib import Path

import pytest

from fsmbt.cli import main

ROOT = Path(__file__).resolve().parents[2]
PAGE = (ROOT / "docs" / "diff.md").read_text(encoding="utf-8")


def _blocks() -> list[str]:
    return re.findall(r"```text\n(.*?)```", PAGE, flags=re.S)


def test_example_prints_what_the_page_shows(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    [command] = [
        line.strip() for line in PAGE.splitlines() if line.startswith("    .venv/bin/fsmbt diff ")
    ]
    args = shlex.split(command)[1:]
    monkeypatch.chdir(ROOT)
    args = [a.replace("out/", f"{tmp_path}{os.sep}") for a in args]
    assert main(args) == 1
    assert capsys.readouterr().out == _blocks()[0]
    for name in ("review.md", "review.svg", "junit.xml"):
        assert (tmp_path / "diff" / name).stat().st_size > 0


def test_bad_pair_message_is_the_page_s(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lebt = tmp_path / "paper_bt.xml"
    assert (
        main(
            [
                "convert",
                str(ROOT / "examples" / "paper_fsm.xml"),
                "--style",
                "lebt",
                "-o",
                str(lebt),
            ]
        )
        == 0
    )
    capsys.readouterr()
    assert main(["diff", str(lebt), str(ROOT / "examples" / "robot_bt.xml")]) == 2
    assert capsys.readouterr().err == _blocks()[1]
