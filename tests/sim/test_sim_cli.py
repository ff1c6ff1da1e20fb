"""``fsmbt simulate``: the table, the pictures, the exit codes, bad input."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image

from fsmbt import api
from fsmbt.cli import main
from support.sim_helpers import EXAMPLES, example, mutant


class Result:
    def __init__(self, code: int, output: str) -> None:
        self.exit_code = code
        self.output = output


@pytest.fixture
def simulate(capsys):
    def run(*args: object) -> Result:
        code = main(["simulate", *map(str, args)])
        captured = capsys.readouterr()
        return Result(code, captured.out + captured.err)

    return run


def test_robot_with_pictures(simulate, tmp_path: Path):
    out = tmp_path / "pics"
    result = simulate(
        "robot",
        EXAMPLES / "robot_bt.xml",
        "-n",
        "5",
        "--engine",
        "fsmbt",
        "--engine",
        "py_trees",
        "-o",
        out,
    )
    assert result.exit_code == 0, result.output
    assert "fsmbt / fsmbt" in result.output and "py_trees / fsmbt" in result.output
    assert "IDENTICAL: 10 of 10 episodes identical" in result.output
    gif = Image.open(out / "simulation.gif")
    assert gif.format == "GIF" and gif.n_frames > 10
    png = Image.open(out / "trajectories.png")
    assert png.format == "PNG" and png.size[0] > 300
    # the pictures are not replaced without --force, and nothing runs then
    again = simulate("robot", EXAMPLES / "robot_bt.xml", "-n", "1", "-o", out)
    assert again.exit_code == 2 and "exists" in again.output


def test_predator_against_its_lebt_file(simulate, tmp_path: Path):
    lebt = tmp_path / "predator_bt.xml"
    api.write(api.convert_model(example("predator_fsm.scxml"), style="lebt").model, lebt, "btcpp")
    result = simulate(
        "predator-prey",
        EXAMPLES / "predator_fsm.scxml",
        "--against",
        lebt,
        "-n",
        "3",
        "--engine",
        "fsmbt",
        "--engine",
        "btcpp",
    )
    assert result.exit_code == 0, result.output
    assert "role predator" in result.output and "fsmbt / btcpp" in result.output


def test_mutant_diverges_exit_1_and_names_the_step(simulate, tmp_path: Path):
    bad = mutant(example("prey_bt.xml"), "swap_children", "children 0 and 1 of PreyRoot swapped")
    path = tmp_path / "prey_mutant.xml"
    api.write(bad, path, "btcpp")
    hfsm = tmp_path / "prey_hfsm.scxml"
    api.write(api.convert_model(example("prey_bt.xml")).model, hfsm, "scxml")
    result = simulate(
        "predator-prey",
        path,
        "--against",
        hfsm,
        "-n",
        "10",
        "--engine",
        "fsmbt",
        "-o",
        tmp_path / "pics",
    )
    assert result.exit_code == 1, result.output
    assert "DIVERGENT" in result.output
    assert "first divergence (fsmbt), episode seed" in result.output
    assert ", step " in result.output and "prey_mutant.xml: behaviour [" in result.output
    assert (tmp_path / "pics" / "simulation.gif").exists()


def test_skipped_engine_is_not_counted(simulate):
    # BT on BehaviorTree.CPP against its HFSM on fsmbt's runner: a real row
    real = simulate("robot", EXAMPLES / "robot_bt.xml", "-n", "1", "--engine", "btcpp")
    assert real.exit_code == 0 and "btcpp / fsmbt" in real.output
    # two plain BTs: python-statemachine runs neither; the row is skipped, nothing ran: exit 1
    skipped = simulate(
        "robot",
        EXAMPLES / "robot_bt.xml",
        "-n",
        "1",
        "--engine",
        "python-statemachine",
        "--against",
        EXAMPLES / "robot_bt.xml",
    )
    assert skipped.exit_code == 1
    assert "skipped python-statemachine: neither model runs on it" in skipped.output
    assert "NOT RUN" in skipped.output and "IDENTICAL:" not in skipped.output


@pytest.mark.parametrize(
    "args, message",
    [
        (["moon", EXAMPLES / "robot_bt.xml"], "unknown world"),
        (["robot", EXAMPLES / "game_npc_bt.xml"], "not known to the robot world"),
        (["predator-prey", EXAMPLES / "robot_bt.xml"], "neither the predator nor the prey"),
        (["robot", EXAMPLES / "robot_bt.xml", "--engine", "gazebo"], "unknown engine"),
        (["robot", EXAMPLES / "no_such_file.xml"], "no_such_file"),
    ],
)
def test_bad_input_exit_2(simulate, args, message):
    result = simulate(*args, "-n", "1")
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output


def test_missing_statemachine_is_a_note_never_identical():
    from fsmbt.sim.simulate import simulate as run_simulation

    bt = example("robot_bt.xml")
    result = run_simulation(
        "robot",
        bt,
        api.convert_model(bt).model,
        engines=["python-statemachine"],
        episodes=1,
        statemachine_available=lambda: False,
    )
    assert [row.comparison for row in result.rows] == [None]
    assert "does not import" in result.rows[0].note
    assert not result.all_identical
