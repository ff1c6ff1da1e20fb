"""``fsmbt verify --engine both`` on trees with the built-ins NuSMV encodes since issue 12
(RetryUntilSuccessful, Repeat, Parallel...): both engines answer, no refusal (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt.cli import main

TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Fallback>
      <RetryUntilSuccessful num_attempts="{attempts}">
        <Sequence>
          <Condition ID="DoorOpen"/>
          <Action ID="PassDoor"/>
        </Sequence>
      </RetryUntilSuccessful>
      <Action ID="CallHelp"/>
    </Fallback>
  </BehaviorTree>
</root>
"""
PARALLEL = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Repeat num_cycles="2">
      <Parallel success_count="1" failure_count="-1">
        <Action ID="Scan"/>
        <Action ID="Listen"/>
      </Parallel>
    </Repeat>
  </BehaviorTree>
</root>
"""


def _write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


@pytest.fixture()
def retry_files(tmp_path: Path) -> dict[str, str]:
    tree = _write(tmp_path, "retry.xml", TREE.format(attempts=3))
    fsm = str(tmp_path / "retry_fsm.json")
    assert main(["convert", tree, "-o", fsm]) == 0
    return {"tree": tree, "fsm": fsm, "fewer": _write(tmp_path, "r2.xml", TREE.format(attempts=2))}


def test_retry_until_successful_verifies_with_both_engines(nusmv_binary, retry_files, capsys):
    """Before issue 12 this exited 2 (NuSMV refused RetryUntilSuccessful)."""
    capsys.readouterr()
    assert main(["verify", retry_files["tree"], retry_files["fsm"], "--engine", "both"]) == 0
    out = capsys.readouterr()
    assert "EQUIVALENT" in out.out and "native+nusmv" in out.out
    assert "does not support" not in out.err


def test_a_changed_attempt_count_fails_on_both_engines_alike(nusmv_binary, retry_files, capsys):
    """num_attempts 2 against the conversion of num_attempts 3: not equivalent (exit 1), and
    the engines agree on every property (a disagreement would exit 3)."""
    assert main(["verify", retry_files["fewer"], retry_files["fsm"], "--engine", "both"]) == 1
    assert "ENGINES DISAGREE" not in capsys.readouterr().err


def test_parallel_inside_repeat_verifies_with_both_engines(nusmv_binary, tmp_path, capsys):
    tree = _write(tmp_path, "par.xml", PARALLEL)
    fsm = str(tmp_path / "par_fsm.json")
    assert main(["convert", tree, "-o", fsm]) == 0
    capsys.readouterr()
    assert main(["verify", tree, fsm, "--engine", "both"]) == 0
    assert "EQUIVALENT" in capsys.readouterr().out
