"""Issue 13, points 6 (state limit), 7 (collapsed warnings), 8 (large pictures), 9 (words) and
10 (LEBT ports checked against the structure), through the real CLI (``fsmbt.cli.main``).

Each test pins what a new user met before: a limit they could not see or raise, a screen of
identical warnings, an unreadable picture, jargon, a wrong port that verified silently.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsmbt.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

#: A plain sequence around a reactive region: the region is explored (docs/conversion.md).
REACTIVE_BT = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="top">
      <Action ID="Start"/>
      <ReactiveSequence name="patrol">
        <Condition ID="BatteryOK"/>
        <Parallel success_count="2" failure_count="1">
          <Action ID="MoveA"/>
          <Action ID="MoveB"/>
        </Parallel>
      </ReactiveSequence>
    </Sequence>
  </BehaviorTree>
</root>
"""


@pytest.fixture
def reactive_bt(tmp_path: Path) -> Path:
    path = tmp_path / "patrol.xml"
    path.write_text(REACTIVE_BT, encoding="utf-8")
    return path


# -- 6: a state limit the user can see and raise ---------------------------------------------
def test_no_verify_exploration_names_the_subtree_and_the_flag(
    reactive_bt: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "patrol.scxml"
    assert (
        main(
            [
                "convert",
                str(reactive_bt),
                "--no-verify",
                "--max-states",
                "3",
                "--no-progress",
                "-o",
                str(out),
            ]
        )
        == 2
    )
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    # tree id, node labels from the root down, the line of the exploding node, the flag
    assert "patrol.xml:5:" in err
    assert "tree 'Main', Sequence 'top' > ReactiveSequence 'patrol'" in err
    assert "more than 3 states" in err and "--max-states" in err
    assert "@" not in err and not out.exists()


def test_raising_the_limit_converts_and_verifies(
    reactive_bt: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "patrol.scxml"
    assert (
        main(["convert", str(reactive_bt), "--max-states", "5000", "--no-progress", "-o", str(out)])
        == 0
    )
    assert "EQUIVALENT" in capsys.readouterr().out and out.exists()


def test_verify_state_limit_is_an_option(
    reactive_bt: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "patrol.scxml"
    assert main(["convert", str(reactive_bt), "--no-progress", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["verify", str(reactive_bt), str(out), "--max-states", "4", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "more than 4 reachable states" in err and "--max-states" in err
    assert "pairing rule" not in err  # a size limit is not a pairing problem
    assert (
        main(["verify", str(reactive_bt), str(out), "--max-states", "100000", "--no-progress"]) == 0
    )


def test_max_states_must_be_positive(reactive_bt: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["convert", str(reactive_bt), "--max-states", "0", "--no-progress"]) == 2
    assert "--max-states" in capsys.readouterr().err


# -- 7: one line per undeclared node type, with a count --------------------------------------
UNDECLARED_BT = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Spin name="a"/>
      <Spin name="b"/>
      <Spin name="c"/>
      <Wait/>
    </Sequence>
  </BehaviorTree>
</root>
"""


@pytest.fixture
def undeclared_bt(tmp_path: Path) -> Path:
    path = tmp_path / "nav.xml"
    path.write_text(UNDECLARED_BT, encoding="utf-8")
    return path


def test_validate_collapses_repeated_not_declared_warnings(
    undeclared_bt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["validate", "--json", "--no-profiles", str(undeclared_bt)]) == 0
    issues = json.loads(capsys.readouterr().out)["issues"]
    # one warning for every undeclared type, worded as convert words it, at the first one
    undeclared = [i for i in issues if i["code"] == "undeclared-leaf"]
    assert len(undeclared) == 1 and undeclared[0]["line"] == 4
    assert "Spin x3" in undeclared[0]["message"] and "Wait" in undeclared[0]["message"]
    assert "Wait x" not in undeclared[0]["message"]
    assert not [i for i in issues if "'Spin'" in i["message"] or "'Wait'" in i["message"]]


@pytest.mark.parametrize(
    "command",
    [["info", "--no-profiles"], ["convert", "--no-progress", "--no-verify", "--no-profiles"]],
)
def test_info_and_convert_name_each_undeclared_type_once(
    command: list[str], undeclared_bt: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    extra = ["-o", str(tmp_path / "out.scxml")] if command[0] == "convert" else []
    assert main([*command, str(undeclared_bt), *extra]) == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if "undeclared" in line]
    assert len(lines) == 1
    assert "2 undeclared leaf types (4 nodes)" in lines[0] and "Spin x3, Wait" in lines[0]
    assert "--node-models" in lines[0]


# -- 10: the LEBT leaves' redundant ports are checked against the structure ------------------
@pytest.fixture
def paper_lebt(tmp_path: Path) -> Path:
    out = tmp_path / "paper_bt.xml"
    assert (
        main(
            [
                "convert",
                str(EXAMPLES / "paper_fsm.xml"),
                "--style",
                "lebt",
                "--no-progress",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    return out


def _edited(path: Path, old: str, new: str) -> Path:
    text = path.read_text(encoding="utf-8")
    assert text.count(old) == 1
    edited = path.with_name("edited_" + path.name)
    edited.write_text(text.replace(old, new), encoding="utf-8")
    return edited


def _line_of(path: Path, needle: str) -> int:
    lines = path.read_text(encoding="utf-8").splitlines()
    return next(n for n, line in enumerate(lines, 1) if needle in line)


def test_honest_lebt_has_no_port_issue(
    paper_lebt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    capsys.readouterr()
    assert main(["validate", str(paper_lebt)]) == 0
    assert main(["verify", str(EXAMPLES / "paper_fsm.xml"), str(paper_lebt), "--no-progress"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_wrong_guard_target_is_an_error_in_validate_and_a_warning_in_verify(
    paper_lebt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = _edited(paper_lebt, 'name="Enter_B" target="B"', 'name="Enter_B" target="C"')
    capsys.readouterr()
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    line = _line_of(bad, 'name="Enter_B"')
    assert f"{bad}:{line}:" in err and "LebtGuard 'Enter_B'" in err
    assert "target='C'" in err and "'B'" in err
    # the checkers read the pairs, not the target: the verdict stands, the user is told
    assert main(["verify", str(EXAMPLES / "paper_fsm.xml"), str(bad), "--no-progress"]) == 0
    captured = capsys.readouterr()
    assert "EQUIVALENT" in captured.out
    assert "warning:" in captured.err and "target='C'" in captured.err


def test_exit_without_guard_and_pair_without_exit_are_named(
    paper_lebt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = _edited(paper_lebt, 'exits="eventBC;eventBD"', 'exits="eventBC;eventBX"')
    capsys.readouterr()
    assert main(["validate", "--json", str(bad)]) == 2
    messages = [i["message"] for i in json.loads(capsys.readouterr().out)["issues"]]
    assert any("'B/eventBD'" in m and "never fires" in m for m in messages)
    assert any("'eventBX'" in m and "no LebtGuard" in m for m in messages)


# -- 9: words a robotics engineer can read ---------------------------------------------------
def test_convert_summary_says_what_was_built(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        main(
            [
                "convert",
                str(EXAMPLES / "robot_bt.xml"),
                "--no-progress",
                "-o",
                str(tmp_path / "robot.scxml"),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    summary = next(line for line in out.splitlines() if line.startswith("converted"))
    assert "k=" not in summary and "units=" not in summary
    assert "12 leaves became a state machine with 2 sub-state-machines" in summary
    assert "3 conversion units" in summary
    # the checker's counts say what they count
    assert "configurations (an FSM's states plus its start" in out


def test_convert_json_keeps_its_keys(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        main(
            [
                "convert",
                str(EXAMPLES / "robot_bt.xml"),
                "--no-progress",
                "--json",
                "-o",
                str(tmp_path / "robot.scxml"),
            ]
        )
        == 0
    )
    stats = json.loads(capsys.readouterr().out)["stats"]
    assert {"k", "units", "explored_regions", "leaves"} <= set(stats)


def test_leaf_execution_counterexample_in_the_users_words(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("COLUMNS", "250")  # rich tables do not wrap the words compared here
    hfsm = tmp_path / "robot.scxml"
    assert main(["convert", str(EXAMPLES / "robot_bt.xml"), "--no-progress", "-o", str(hfsm)]) == 0
    wrong = tmp_path / "wrong.scxml"
    wrong.write_text(
        hfsm.read_text(encoding="utf-8").replace("MovetoCube2", "MovetoCubeX"), encoding="utf-8"
    )
    capsys.readouterr()
    assert main(["verify", str(EXAMPLES / "robot_bt.xml"), str(wrong), "--no-progress"]) == 1
    out = " ".join(capsys.readouterr().out.split())  # the table wraps; compare the words
    assert "NOT EQUIVALENT" in out
    assert "input 'failure'" not in out and "when the previous leaf returned FAILURE" in out
    assert "@" not in out  # no MovetoCube2@1/1/0/1/0/1
    assert "never reached with matching behaviour: MovetoCube2" in out
    assert "4 leaf outcomes" in out and "FAILURE" in out


def test_one_step_counterexample_is_singular(
    paper_lebt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = _edited(paper_lebt, 'state="A" action="A"', 'state="A" action="Z"')
    capsys.readouterr()
    assert main(["verify", str(EXAMPLES / "paper_fsm.xml"), str(bad), "--no-progress"]) == 1
    out = " ".join(capsys.readouterr().out.split())
    assert "shortest counterexample (1 input)" in out and "(1 inputs)" not in out


def test_prose_text_points_to_llm_extract(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    prose = tmp_path / "mission.txt"
    prose.write_text("The robot moves to the cube, picks it up and docks.\n", encoding="utf-8")
    assert main(["convert", str(prose), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "mission.txt:1:" in err and "fsmbt llm extract" in err and "--engine llm" in err


# -- 8: large pictures -----------------------------------------------------------------------
def _many_trees(count: int, leaves: int) -> str:
    """``count`` trees of ``leaves`` actions each, the main tree written last."""
    trees = []
    for t in range(count):
        body = "".join(f'<Action ID="Do{t}_{k}"/>' for k in range(leaves))
        trees.append(f'<BehaviorTree ID="T{t}"><Sequence>{body}</Sequence></BehaviorTree>')
    return (
        f'<root BTCPP_format="4" main_tree_to_execute="T{count - 1}">' + "".join(trees) + "</root>"
    )


def _png_size(path: Path) -> tuple[int, int]:
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def test_multi_tree_picture_puts_the_main_tree_first_and_stacks_the_rest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "trees.xml"
    source.write_text(_many_trees(24, 6), encoding="utf-8")
    dot = tmp_path / "trees.dot"
    assert main(["render", str(source), "-o", str(dot)]) == 0
    text = dot.read_text(encoding="utf-8")
    first_cluster_label = text[text.index("subgraph cluster_") :].split("label=", 1)[1]
    assert first_cluster_label.startswith('"T23 (main)"')
    assert text.count("style=invis") >= 2  # rows hang under each other
    png = tmp_path / "trees.png"
    assert main(["render", str(source), "-o", str(png)]) == 0
    width, height = _png_size(png)
    assert width < 4 * height, (width, height)  # not a strip


def test_a_capped_picture_says_what_it_left_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "many.xml"
    source.write_text(_many_trees(40, 20), encoding="utf-8")  # 40 x 21 = 840 nodes
    assert main(["render", str(source), "-o", str(tmp_path / "many.dot")]) == 0
    err = capsys.readouterr().err
    assert "picture capped to fit 4096 x 4096 pixels" in err and "of 40 trees" in err
    assert "left out: " in err and "--tree ID" in err
    one = tmp_path / "one.dot"
    assert main(["render", str(source), "-o", str(one), "--tree", "T5"]) == 0
    text = one.read_text(encoding="utf-8")
    assert "Do5_0" in text and "Do6_0" not in text
    assert main(["render", str(source), "-o", str(tmp_path / "x.dot"), "--tree", "Nope"]) == 2
    assert "no tree 'Nope'" in capsys.readouterr().err


def test_hfsm_one_level_at_a_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    door = EXAMPLES / "door_hfsm.scxml"
    top = tmp_path / "top.dot"
    assert main(["render", str(door), "-o", str(top), "--level", "0"]) == 0
    text = top.read_text(encoding="utf-8")
    assert "states inside" in text and "cluster" not in text and "Closing" not in text
    inner = tmp_path / "operating.dot"
    assert main(["render", str(door), "-o", str(inner), "--composite", "Operating"]) == 0
    text = inner.read_text(encoding="utf-8")
    assert "Closing" in text and "Emergency" not in text
    full = tmp_path / "full.dot"
    assert main(["render", str(door), "-o", str(full)]) == 0
    assert "subgraph cluster_" in full.read_text(encoding="utf-8")  # clusters, as documented
    capsys.readouterr()
    assert main(["render", str(door), "-o", str(tmp_path / "x.dot"), "--composite", "Nope"]) == 2
    assert "composite states: Operating" in capsys.readouterr().err


def test_big_hfsm_is_drawn_to_the_level_that_fits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    big = tmp_path / "big_hfsm.scxml"
    inner = "".join(
        f'<state id="c{k}"><transition event="e" target="c{(k + 1) % 70}"/></state>'
        for k in range(70)
    )
    big.write_text(
        '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" '
        'initial="Busy"><state id="Busy" initial="c0">'
        + inner
        + '<transition event="stop" target="Done"/></state><final id="Done"/></scxml>',
        encoding="utf-8",
    )
    out = tmp_path / "big.dot"
    assert main(["render", str(big), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "picture capped" in err and "--composite NAME" in err and "Busy" in err
    text = out.read_text(encoding="utf-8")
    assert "70 states inside" in text and "c17" not in text


@pytest.mark.parametrize("engine", ["bsd", "chds"])
def test_baseline_summaries_claim_only_what_they_built(
    engine: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        main(
            [
                "convert",
                str(EXAMPLES / "paper_fsm.xml"),
                "--engine",
                engine,
                "--no-progress",
                "--no-verify",
                "-o",
                str(tmp_path / "bt.xml"),
            ]
        )
        == 0
    )
    summary = next(
        line for line in capsys.readouterr().out.splitlines() if line.startswith("converted")
    )
    assert "10 FSM states became a BT of" in summary
    assert "loop-execution" not in summary and "?" not in summary.split("):", 1)[1]
