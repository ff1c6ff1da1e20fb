"""What a new user meets in the first hour, through the real CLI (issue 13's points).

Each test runs ``fsmbt`` as a user would (``fsmbt.cli.main`` or a subprocess where a pipe or a
terminal matters) and pins the behaviour that was wrong before.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PAPER_FSM = EXAMPLES / "paper_fsm.xml"
FSMBT = [sys.executable, "-m", "fsmbt.cli"]


def test_output_is_checked_before_any_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    existing = tmp_path / "mine.xml"
    existing.write_text("keep me", encoding="utf-8")

    def must_not_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("converted although the output is refused")

    monkeypatch.setattr(api, "convert_model", must_not_run)
    assert main(["convert", str(PAPER_FSM), "-o", str(existing)]) == 2
    err = capsys.readouterr().err
    assert "mine.xml" in err and "--force" in err and err.count("\n") == 1
    assert existing.read_text(encoding="utf-8") == "keep me"
    assert main(["convert", str(PAPER_FSM), "-o", str(tmp_path), "--force"]) == 2
    assert "is a folder" in capsys.readouterr().err


def test_convert_prints_each_step_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["convert", str(PAPER_FSM), "-o", str(tmp_path / "bt.xml")]) == 0
    out = capsys.readouterr().out
    time_line = next(line for line in out.splitlines() if line.startswith("time:"))
    for stage in ("read", "convert", "verify", "write"):
        assert f"{stage} " in time_line


def test_no_progress_display_when_stderr_is_not_a_terminal(tmp_path: Path) -> None:
    proc = subprocess.run(
        [*FSMBT, "convert", str(PAPER_FSM), "-o", str(tmp_path / "x.xml")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""  # no spinner, no escape codes in a pipe


def test_help_is_plain_and_lists_choices() -> None:
    proc = subprocess.run(
        [*FSMBT, "convert", "--help"],
        capture_output=True,
        text=True,
        timeout=60,
        env={"COLUMNS": "100", "PATH": "/usr/bin:/bin"},
    )
    assert proc.returncode == 0
    assert "<bool>" not in proc.stdout
    assert "<subtrees|flatten>" in proc.stdout
    assert "vllm" in proc.stdout  # the provider list is the one the endpoint error uses


def test_closed_pipe_exits_zero_without_a_message() -> None:
    proc = subprocess.run(
        f"{sys.executable} -m fsmbt.cli llm prompt {PAPER_FSM} | head -1",
        shell=True,
        capture_output=True,
        text=True,
        timeout=60,
        executable="/bin/bash",
    )
    assert proc.stdout.startswith("=== system ===")
    status = subprocess.run(
        f"set -o pipefail; {sys.executable} -m fsmbt.cli llm prompt {PAPER_FSM} | head -1 "
        ">/dev/null",
        shell=True,
        capture_output=True,
        text=True,
        timeout=60,
        executable="/bin/bash",
    )
    assert status.returncode == 0, status.stderr
    assert "Traceback" not in status.stderr and "Broken pipe" not in status.stderr


def test_generate_node_budget_is_an_option(tmp_path: Path) -> None:
    small, large = tmp_path / "small", tmp_path / "large"
    common = ["generate", "--kind", "bt", "--n", "1", "--depth", "40", "--breadth", "40"]
    assert main([*common, "-o", str(small)]) == 0
    assert main([*common, "-o", str(large), "--max-nodes", "4000"]) == 0

    def nodes(folder: Path) -> int:
        model = api.load(next(folder.iterdir())).model
        return sum(1 for _ in model.nodes())

    assert nodes(large) > 1000 > nodes(small)
    assert main([*common, "-o", str(small), "--max-nodes", "0"]) == 2


def test_convert_json_summary_has_verdict_and_timings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["convert", str(PAPER_FSM), "-o", str(tmp_path / "bt.xml"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["verdict"] == "EQUIVALENT" and data["written"] is True
    assert set(data["timings"]) == {"read", "convert", "verify", "load", "write"}
    assert data["loads"]["loaded"] is True


ROBOT_BT = EXAMPLES / "robot_bt.xml"


@pytest.mark.parametrize("source, convert_to", [(PAPER_FSM, "bt.xml"), (ROBOT_BT, "hfsm.scxml")])
def test_verify_verdict_does_not_depend_on_the_order(
    tmp_path: Path, source: Path, convert_to: str, capsys: pytest.CaptureFixture[str]
) -> None:
    converted = tmp_path / convert_to
    assert main(["convert", str(source), "-o", str(converted)]) == 0
    capsys.readouterr()
    assert main(["verify", str(source), str(converted), "--json"]) == 0
    given = json.loads(capsys.readouterr().out)
    assert main(["verify", str(converted), str(source), "--json"]) == 0
    swapped = json.loads(capsys.readouterr().out)
    assert given["equivalent"] is swapped["equivalent"] is True
    assert given["stats"]["swapped"] is False and swapped["stats"]["swapped"] is True
    assert given["stats"]["pairing"] == swapped["stats"]["pairing"]
    assert main(["verify", str(converted), str(source)]) == 0
    assert "was read as the source" in capsys.readouterr().out


def test_not_equivalent_in_both_orders(tmp_path: Path) -> None:
    from fsmbt.verify.mutations import mutants

    converted = api.convert_file(PAPER_FSM).result
    wrong = next(
        m.model
        for m in mutants(converted, seed=1)
        if not api.verify_models(api.load(PAPER_FSM).model, m.model).equivalent
    )
    path = tmp_path / "wrong.xml"
    api.write(wrong, path)
    assert main(["verify", str(PAPER_FSM), str(path)]) == 1
    assert main(["verify", str(path), str(PAPER_FSM)]) == 1


def test_a_pair_no_rule_compares_names_the_rules(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lebt = api.convert_file(PAPER_FSM, style="lebt").text
    # an LEBT with one foreign action leaf: neither a loop-execution BT nor a plain BT's FSM
    broken = lebt.replace("<LebtState", "<SomeRobotAction", 1)
    path = tmp_path / "mixed.xml"
    path.write_text(broken, encoding="utf-8")
    code = main(["verify", str(PAPER_FSM), str(path)])
    err = capsys.readouterr().err
    assert code == 2
    assert "pairing rule tried: FSM ~ loop-execution BT" in err
    assert "BT ~ FSM (leaf execution)" in err and err.count("\n") == 1


CUSTOM_TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <MyPipeline name="pipe">
      <Sequence>
        <IsReady/>
        <DoWork/>
      </Sequence>
    </MyPipeline>
  </BehaviorTree>
</root>
"""


def _models_file(path: Path, entries: str) -> Path:
    path.write_text(
        f'<root BTCPP_format="4"><TreeNodesModel>{entries}</TreeNodesModel></root>',
        encoding="utf-8",
    )
    return path


@pytest.mark.parametrize("command", ["validate", "info"])
def test_node_models_files_declare_custom_nodes(
    tmp_path: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    tree = tmp_path / "tree.xml"
    tree.write_text(CUSTOM_TREE, encoding="utf-8")
    controls = _models_file(tmp_path / "controls.xml", '<Control ID="MyPipeline"/>')
    leaves = _models_file(tmp_path / "leaves.xml", '<Condition ID="IsReady"/><Action ID="DoWork"/>')
    if command == "validate":
        assert main(["validate", str(tree)]) == 2
        assert "MyPipeline" in capsys.readouterr().err
    code = main(
        [command, str(tree), "--node-models", str(controls), "--node-models", str(leaves), "--json"]
    )
    out = json.loads(capsys.readouterr().out)
    if command == "validate":
        # the control is declared by the first file, the leaves by the second; what is left
        # is the one thing conversion refuses: a valid tree fsmbt cannot convert yet (a
        # warning, exit 0; --strict makes it an error)
        assert code == 0
        assert not [i for i in out["issues"] if i["severity"] == "error"]
        refusals = [
            i for i in out["issues"] if i["code"] in ("cannot-convert", "unknown-semantics")
        ]
        assert len(refusals) == 1 and refusals[0]["severity"] == "warning"
        assert "MyPipeline" in refusals[0]["message"]
        assert "no known semantics" in refusals[0]["message"]
        strict = [str(tree), "--node-models", str(controls), "--node-models", str(leaves)]
        assert main(["validate", "--strict", *strict]) == 2
        assert "MyPipeline" in capsys.readouterr().err
        messages = [issue["message"] for issue in out["issues"]]
        assert not any("not declared" in m for m in messages)
    else:
        assert code == 0
        assert any("MyPipeline" in b for b in out["conversion_blockers"])
        assert out["conditions"] == 1 or out.get("by_kind", {}).get("Condition") == 1
    assert main([command, str(tree), "--node-models", str(tmp_path / "missing.xml")]) == 2
    assert "missing.xml" in capsys.readouterr().err


def test_bt_to_mermaid_writes_exits_and_reads_back_equivalent(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "robot.mmd"
    assert main(["convert", str(ROBOT_BT), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert '%% fsmbt-exit: "SUCCESS"' in text and '%% fsmbt-exit: "FAILURE"' in text
    capsys.readouterr()
    assert main(["verify", str(ROBOT_BT), str(out)]) == 0
    # a directive must be followed by the transition it names
    broken = text.replace('%% fsmbt-exit: "SUCCESS"\n', '%% fsmbt-exit: "SUCCESS"\n    X : y\n', 1)
    bad = tmp_path / "bad.mmd"
    bad.write_text(broken, encoding="utf-8")
    assert main(["validate", str(bad)]) == 2
    assert "fsmbt-exit directive on line" in capsys.readouterr().err


def test_formats_lists_what_each_writer_cannot_hold(capsys: pytest.CaptureFixture[str]) -> None:
    from fsmbt.formats import formats

    assert main(["formats"]) == 0
    out = capsys.readouterr().out
    assert "cannot hold" in out
    limited = {f.name: f.cannot_hold for f in formats() if f.cannot_hold}
    assert "parallel states" in limited["mermaid"] and "composite" in limited["csv"]
