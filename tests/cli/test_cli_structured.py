"""``fsmbt convert --style`` through the real CLI: a SMACH file becomes its structured tree by
default with a summary line naming the style and what it found; ``--style lebt``/``paper``
keep the paper's shape; bad input (an unknown style, ``structured`` on an event-driven
machine, a machine with both external events and outcomes, an outcome mapped to both results)
is one line naming the place and the cause, exit 2."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api
from support.structured_machines import machine

REPO = Path(__file__).resolve().parents[2]
DELIVERY = REPO / "examples" / "delivery_smach.py"
PAPER = REPO / "examples" / "paper_fsm.xml"


def _convert(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "convert", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_a_smach_file_becomes_its_structured_tree_by_default(tmp_path: Path) -> None:
    out = tmp_path / "delivery.xml"
    done = _convert(str(DELIVERY), "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "structured: " in done.stdout and " flag" in done.stdout and "LEBT blocks" in done.stdout
    assert "verdict: EQUIVALENT" in done.stdout
    tree = api.load(out).model
    types = {node.type for _t, node in tree.nodes()}
    assert {"WaitForOrder", "Charge", "Drive", "Handover"} <= types
    assert not types & {"LebtGuard", "LebtState"}
    names = [node.name for _t, node in tree.nodes() if node.type in tree.node_models]
    assert {"IDLE", "CHARGE", "DRIVE", "HANDOVER"} <= set(names)


@pytest.mark.parametrize("style", ["lebt", "paper"])
def test_lebt_and_its_alias_paper_keep_the_papers_shape(tmp_path: Path, style: str) -> None:
    from fsmbt.cli import main

    out = tmp_path / "delivery.xml"
    assert main(["convert", str(DELIVERY), "--style", style, "-o", str(out)]) == 0
    types = {node.type for _t, node in api.load(out).model.nodes()}
    assert {"LebtGuard", "LebtState"} <= types


def _mixed(path: Path) -> None:
    fsm = machine({"Wait": {"ok": "succeeded", "bad": "aborted"}})
    fsm.add_transition("Wait", "timeout", "aborted")  # an external event beside the outcomes
    api.write(fsm, path)


@pytest.mark.parametrize(
    ("args", "cause"),
    [
        (["--style", "bogus"], r"--style: .*unknown style 'bogus' \(valid: auto, structured, lebt"),
        (["--style", "structured"], r"state 'A': --style structured needs an outcome-driven"),
        (["--outcomes", "arrived=success,arrived=failure"], r"outcome 'arrived' is mapped to both"),
        (["MIXED"], r"state 'Wait': event 'timeout' is not one of its declared outcomes"),
    ],
)
def test_bad_style_input_is_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], cause: str
) -> None:
    from fsmbt.cli import main

    source = PAPER if "--style" in args else DELIVERY
    if args == ["MIXED"]:
        source, args = tmp_path / "mixed.json", []
        _mixed(source)
    assert main(["convert", str(source), *args, "-o", str(tmp_path / "out.xml")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and re.search(cause, lines[0]), lines
    assert not (tmp_path / "out.xml").exists()


def test_verify_pairs_a_smach_file_with_its_structured_tree_in_either_order(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from fsmbt.cli import main

    out = tmp_path / "delivery.xml"
    assert main(["convert", str(DELIVERY), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["verify", str(DELIVERY), str(out)]) == 0
    assert main(["verify", str(out), str(DELIVERY)]) == 0
    assert capsys.readouterr().out.count("outcome-execution") == 2
    tree = out.read_text(encoding="utf-8")
    wrong = tmp_path / "wrong.xml"
    wrong.write_text(tree.replace('name="DRIVE"', 'name="HANDOVER_"', 1), encoding="utf-8")
    assert main(["verify", str(DELIVERY), str(wrong)]) == 1
