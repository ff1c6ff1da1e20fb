"""The predator-prey game: the predator FSM against its LEBT, the prey BT against its HFSM
(100 seeded episodes each), on fsmbt's runners and on the real engines; mutants diverge."""

from __future__ import annotations

import collections
from importlib import resources

import pytest

from fsmbt import api
from fsmbt.model.errors import InputError
from fsmbt.sim.predator_prey import PredatorPreyWorld
from fsmbt.sim.run import compare, run_episode
from fsmbt.sim.simulate import role_of
from support.sim_helpers import EXAMPLES, assert_first_divergence_is_real, example, mutant, side

EPISODES = 100


@pytest.fixture(scope="module")
def predator():
    return example("predator_fsm.scxml")


@pytest.fixture(scope="module")
def prey():
    return example("prey_bt.xml")


def game(predator, prey0, prey1=None):
    return {"predator": predator, "prey0": prey0, "prey1": prey1 if prey1 is not None else prey0}


def test_shipped_companions_are_the_examples():
    for name in ("predator_fsm.scxml", "prey_bt.xml"):
        shipped = resources.files("fsmbt.sim").joinpath("models", name).read_text()
        assert shipped == (EXAMPLES / name).read_text()


def test_game_is_exercised(predator, prey):
    counts: collections.Counter[str] = collections.Counter()
    for seed in range(EPISODES):
        for record in run_episode(
            PredatorPreyWorld(), side("g", game(predator, prey)), seed
        ).records:
            counts.update(record.events)
            for role, what in record.behaviour:
                counts.update(
                    f"{role}:{token.split(':')[0]}"
                    for token in what.replace(" -> ", " ").replace("+", " ").split()
                    if token != "=>"
                )
    for key in (
        "predator:Patrol",
        "predator:Detect",
        "predator:Chase",
        "predator:Capture",
        "predator:GiveUp",
        "predator:tired",
        "predator:rested",
        "predator:escaped",
        "prey0:GoToHaven",
        "prey0:Flee",
        "prey0:Eat",
        "prey0:Wander",
        "ate",
        "lunge_missed",
        "prey0_caught",
        "prey1_caught",
    ):
        assert counts[key] > 0, key


def test_predator_fsm_vs_its_lebt_identical(predator, prey):
    lebt = api.convert_model(predator, style="lebt").model
    c = compare(
        PredatorPreyWorld,
        side("fsm", game(predator, prey)),
        side("lebt", game(lebt, prey)),
        episodes=EPISODES,
    )
    assert c.all_identical, c.first_divergence


def test_prey_bt_vs_its_hfsm_identical(predator, prey):
    hfsm = api.convert_model(prey).model
    c = compare(
        PredatorPreyWorld,
        side("bt", game(predator, prey)),
        side("hfsm", game(predator, hfsm)),
        episodes=EPISODES,
    )
    assert c.all_identical, c.first_divergence


@pytest.mark.parametrize("engine", ["btcpp", "py_trees"])
def test_real_engines(predator, prey, engine):
    lebt = api.convert_model(predator, style="lebt").model
    hfsm = api.convert_model(prey).model
    # the LEBT predator and the prey BT on the engine, against FSM predator and HFSM prey
    c = compare(
        PredatorPreyWorld,
        side(engine, game(lebt, prey), engine),
        side("fsmbt", game(predator, hfsm)),
        episodes=20,
    )
    assert c.all_identical, c.first_divergence


def test_python_statemachine(predator, prey):
    pytest.importorskip("statemachine")
    hfsm = api.convert_model(prey).model
    c = compare(
        PredatorPreyWorld,
        side("fsmbt", game(predator, prey)),
        side("psm", game(predator, hfsm), "python-statemachine"),
        episodes=10,
    )
    assert c.all_identical, c.first_divergence


def test_predator_retargeted_transition_diverges(predator, prey):
    lebt = api.convert_model(predator, style="lebt").model
    bad = mutant(predator, "retarget_transition", "Detect -prey_seen-> Chase now goes to Patrol")
    assert not api.verify_models(bad, lebt).equivalent
    c = compare(
        PredatorPreyWorld,
        side("mutant", game(bad, prey)),
        side("lebt", game(lebt, prey)),
        episodes=EPISODES,
    )
    assert not c.all_identical
    assert_first_divergence_is_real("predator-prey", c)


def test_lebt_moved_guard_pair_diverges(predator, prey):
    lebt = api.convert_model(predator, style="lebt").model
    bad = mutant(lebt, "retarget_transition", "pair Detect/prey_seen moved from Enter_Chase")
    assert not api.verify_models(predator, bad).equivalent
    c = compare(
        PredatorPreyWorld,
        side("fsm", game(predator, prey)),
        side("mutant", game(bad, prey)),
        episodes=EPISODES,
    )
    assert not c.all_identical
    assert_first_divergence_is_real("predator-prey", c)


def test_prey_swapped_children_diverges(predator, prey):
    hfsm = api.convert_model(prey).model
    bad = mutant(prey, "swap_children", "children 0 and 1 of PreyRoot swapped")
    assert not api.verify_models(bad, hfsm).equivalent
    c = compare(
        PredatorPreyWorld,
        side("mutant", game(predator, bad)),
        side("hfsm", game(predator, hfsm)),
        episodes=EPISODES,
    )
    assert not c.all_identical
    step = assert_first_divergence_is_real("predator-prey", c)
    assert f"step {step}:" in c.first_divergence.divergence.describe()


def test_prey_hfsm_retargeted_transition_diverges(predator, prey):
    hfsm = api.convert_model(prey).model
    bad = mutant(hfsm, "retarget_transition", "Wander -success-> SUCCESS now goes to FAILURE")
    assert not api.verify_models(prey, bad).equivalent
    c = compare(
        PredatorPreyWorld,
        side("bt", game(predator, prey)),
        side("mutant", game(predator, bad)),
        episodes=EPISODES,
    )
    assert not c.all_identical
    assert_first_divergence_is_real("predator-prey", c)


def test_roles_are_inferred_from_names(predator, prey):
    assert role_of("predator-prey", predator) == "predator"
    assert role_of("predator-prey", prey) == "prey"
    assert role_of("predator-prey", api.convert_model(prey).model) == "prey"
    with pytest.raises(InputError, match="neither the predator nor the prey"):
        role_of("predator-prey", example("robot_bt.xml"))
    with pytest.raises(InputError, match="unknown world"):
        role_of("moon", prey)


def test_plain_bt_cannot_play_the_event_driven_predator(prey):
    from fsmbt.sim.agents import build_agent

    with pytest.raises(InputError, match="event-driven"):
        build_agent(example("prey_bt.xml"), PredatorPreyWorld(), "predator", where="x")
