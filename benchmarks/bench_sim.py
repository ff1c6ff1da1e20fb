"""How fast the simulations run: episodes, steps and steps per second, per model and engine.

    .venv/bin/python benchmarks/bench_sim.py [--episodes 50] [--seed 0]

One row per (world, side, engine): ``episodes`` seeded episodes of that side alone
(``fsmbt.sim.run.run_episode``), wall time and process CPU time (stable on a shared machine),
steps, steps per second of CPU. A step is one world step: every role acts once (the robot's tree
ticked; the predator's events posted and its action run, both prey ticked). Then one mutant's
divergence report (the prey BT with its root's first two children swapped, against the prey
HFSM), as ``fsmbt simulate`` prints it.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from fsmbt import api
from fsmbt.sim.agents import engines_for
from fsmbt.sim.predator_prey import PredatorPreyWorld
from fsmbt.sim.robot import RobotWorld
from fsmbt.sim.run import Side, compare, run_episode
from fsmbt.sim.scxml_engine import available
from fsmbt.verify.mutations import mutants

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load(name: str):  # type: ignore[no-untyped-def]
    return api.load(EXAMPLES / name).model


def side(label: str, models: dict, engine: str) -> Side:  # type: ignore[type-arg]
    return Side(label, models, dict.fromkeys(models, engine))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    robot_bt = load("robot_bt.xml")
    robot_hfsm = api.convert_model(robot_bt).model
    robot_bsd = api.convert_model(robot_hfsm, "bsd").model
    robot_chds = api.convert_model(robot_hfsm, "chds").model
    predator = load("predator_fsm.scxml")
    predator_lebt = api.convert_model(predator, style="lebt").model
    prey = load("prey_bt.xml")
    prey_hfsm = api.convert_model(prey).model

    def game(pred, prey_model):  # type: ignore[no-untyped-def]
        return {"predator": pred, "prey0": prey_model, "prey1": prey_model}

    psm = ["python-statemachine"] if available() else []
    rows = [
        ("robot", RobotWorld, "robot BT", {"robot": robot_bt}, ["fsmbt", "btcpp", "py_trees"]),
        ("robot", RobotWorld, "robot HFSM", {"robot": robot_hfsm}, ["fsmbt", *psm]),
        ("robot", RobotWorld, "HFSM -> BSD BT", {"robot": robot_bsd}, ["fsmbt"]),
        ("robot", RobotWorld, "HFSM -> CHDS BT", {"robot": robot_chds}, ["fsmbt"]),
        (
            "predator-prey",
            PredatorPreyWorld,
            "predator FSM + prey BT",
            game(predator, prey),
            ["fsmbt"],
        ),
        (
            "predator-prey",
            PredatorPreyWorld,
            "predator LEBT + prey BT",
            game(predator_lebt, prey),
            ["fsmbt", "btcpp", "py_trees"],
        ),
        (
            "predator-prey",
            PredatorPreyWorld,
            "predator FSM + prey HFSM",
            game(predator, prey_hfsm),
            ["fsmbt", *psm],
        ),
    ]
    if not psm:
        print("note: python-statemachine does not import: its rows are skipped")
    print(
        f"{'world':<14} {'side':<26} {'engine':<20} {'episodes':>8} {'steps':>7} "
        f"{'wall s':>7} {'cpu s':>7} {'steps/s (cpu)':>13}"
    )
    for world_name, make, label, models, engines in rows:
        for engine in engines:
            # each role on the engine when its model runs there, else on fsmbt's runner
            engine_of = {
                role: engine if engine in engines_for(model) else "fsmbt"
                for role, model in models.items()
            }
            s = Side(label, models, engine_of)
            world = make()
            wall, cpu = time.perf_counter(), time.process_time()
            steps = 0
            for index in range(args.episodes):
                steps += len(run_episode(world, s, args.seed + index).records)
            wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
            print(
                f"{world_name:<14} {label:<26} {engine:<20} {args.episodes:>8} {steps:>7} "
                f"{wall:>7.2f} {cpu:>7.2f} {steps / cpu:>13.0f}"
            )

    bad = next(
        m.model
        for m in mutants(prey, per_operator=None)
        if m.operator == "swap_children" and m.description == "children 0 and 1 of PreyRoot swapped"
    )
    c = compare(
        PredatorPreyWorld,
        side("prey mutant", game(predator, bad), "fsmbt"),
        side("prey HFSM", game(predator, prey_hfsm), "fsmbt"),
        episodes=args.episodes,
        seed=args.seed,
    )
    first = c.first_divergence
    print(
        f"\nmutant 'children 0 and 1 of PreyRoot swapped' vs the prey HFSM: "
        f"{len(c.episodes) - c.identical} of {len(c.episodes)} episodes diverge"
    )
    if first is not None and first.divergence is not None:
        print(
            f"first divergence, episode seed {first.seed}, "
            + first.divergence.describe("prey mutant", "prey HFSM")
        )


if __name__ == "__main__":
    main()
