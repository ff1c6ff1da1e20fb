"""The robot grasping world: the paper's robot BT against its HFSM, against the BSD/CHDS
baselines' BTs of that HFSM, on every engine; mutants diverge; names are checked at load time."""

from __future__ import annotations

import collections

import pytest

from fsmbt import api
from fsmbt.model.errors import InputError
from fsmbt.sim.agents import build_agent
from fsmbt.sim.robot import NAMES, RobotWorld
from fsmbt.sim.run import compare, run_episode
from support.sim_helpers import assert_first_divergence_is_real, example, mutant, side

EPISODES = 100


@pytest.fixture(scope="module")
def bt():
    return example("robot_bt.xml")


@pytest.fixture(scope="module")
def hfsm(bt):
    return api.convert_model(bt).model


def test_world_is_exercised_and_deterministic(bt):
    counts: collections.Counter[str] = collections.Counter()
    ended: collections.Counter[str] = collections.Counter()
    for seed in range(EPISODES):
        trajectory = run_episode(RobotWorld(), side("bt", {"robot": bt}), seed)
        ended[trajectory.ended] += 1
        for record in trajectory.records:
            counts.update(record.events)
    # every part of the world happens somewhere in 100 episodes: picks fail by chance, the
    # battery is recharged, missions fail and are retried, cubes are delivered, robots dock
    for event in (
        "picked",
        "pick_failed",
        "charged",
        "mission_failed",
        "delivered",
        "docked",
        "mission_complete",
    ):
        assert counts[event] > 0, event
    assert ended["done"] == counts["mission_complete"] > EPISODES // 2
    again = run_episode(RobotWorld(), side("bt", {"robot": bt}), 7)
    assert again.records == run_episode(RobotWorld(), side("bt", {"robot": bt}), 7).records
    assert again.records != run_episode(RobotWorld(), side("bt", {"robot": bt}), 8).records


def test_bt_vs_its_hfsm_identical(bt, hfsm):
    c = compare(
        RobotWorld, side("bt", {"robot": bt}), side("hfsm", {"robot": hfsm}), episodes=EPISODES
    )
    assert c.all_identical, c.first_divergence
    assert len(c.episodes) == EPISODES and c.steps > 20 * EPISODES


@pytest.mark.parametrize("baseline", ["bsd", "chds"])
def test_bt_vs_baseline_bt_of_its_hfsm_identical(bt, hfsm, baseline):
    rebuilt = api.convert_model(hfsm, baseline).model  # BT -> HFSM (rules) -> BT (baseline)
    c = compare(
        RobotWorld, side("bt", {"robot": bt}), side(baseline, {"robot": rebuilt}), episodes=EPISODES
    )
    assert c.all_identical, c.first_divergence


@pytest.mark.parametrize("engine", ["btcpp", "py_trees"])
def test_bt_on_real_engines_vs_hfsm(bt, hfsm, engine):
    c = compare(
        RobotWorld, side(engine, {"robot": bt}, engine), side("hfsm", {"robot": hfsm}), episodes=30
    )
    assert c.all_identical, c.first_divergence


@pytest.mark.parametrize("engine", ["btcpp", "py_trees"])
def test_lebt_of_hfsm_on_real_engines(bt, hfsm, engine):
    lebt = api.convert_model(
        hfsm, style="lebt"
    ).model  # HFSM -> BT (rules): an LEBT in leaf execution
    c = compare(
        RobotWorld, side("bt", {"robot": bt}), side(engine, {"robot": lebt}, engine), episodes=20
    )
    assert c.all_identical, c.first_divergence


def test_hfsm_on_python_statemachine(bt, hfsm):
    pytest.importorskip("statemachine")
    c = compare(
        RobotWorld,
        side("bt", {"robot": bt}),
        side("psm", {"robot": hfsm}, "python-statemachine"),
        episodes=20,
    )
    assert c.all_identical, c.first_divergence


def test_swapped_children_mutant_diverges(bt, hfsm):
    bad = mutant(bt, "swap_children", "children 0 and 1 of Sequence swapped")
    assert not api.verify_models(bad, hfsm).equivalent  # the checker agrees it changed
    c = compare(
        RobotWorld, side("mutant", {"robot": bad}), side("hfsm", {"robot": hfsm}), episodes=EPISODES
    )
    assert not c.all_identical
    step = assert_first_divergence_is_real("robot", c)
    report = c.first_divergence.divergence.describe("mutant", "hfsm")
    assert report.startswith(f"step {step}:") and "mutant: behaviour [robot:" in report


def test_retargeted_transition_mutant_diverges(bt, hfsm):
    bad = mutant(hfsm, "retarget_transition", "Dock -success-> SUCCESS now goes to Dock")
    assert not api.verify_models(bt, bad).equivalent
    c = compare(
        RobotWorld, side("bt", {"robot": bt}), side("mutant", {"robot": bad}), episodes=EPISODES
    )
    assert not c.all_identical
    assert_first_divergence_is_real("robot", c)


def test_unknown_leaf_names_refused_at_load():
    doc = example("game_npc_bt.xml")
    with pytest.raises(InputError) as err:
        build_agent(doc, RobotWorld(), "robot")
    assert "CanSeeEnemy" in str(err.value) and "robot world" in str(err.value)


def test_name_table_covers_the_papers_tree(bt):
    from fsmbt.sim.agents import model_names

    assert set(model_names(bt)) <= set(NAMES)
    assert len(model_names(bt)) == 12
