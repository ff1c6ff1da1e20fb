"""Run seeded episodes of a world with one set of agents, and compare two sets step by step.

A *side* is the models that drive a world's roles, each on an engine (``Side``). An episode is
run from ``seed``: ``world.reset(seed)``, then fixed steps until the world is done or
``max_steps``. In each step the roles act in the world's order: an event-driven role's sensor
events are posted, then its state's action runs; a leaf-driven role is ticked once. Episode ``i``
of a comparison uses seed ``seed + i`` on both sides, so both meet the same world and the same
random draws for as long as they behave the same; the first step whose record differs is the
divergence (``fsmbt.sim.world.first_divergence``).

Costs: O(steps x cost of a step) per episode; a comparison keeps two trajectories at a time plus
the first episode's (for the pictures).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.sim.agents import build_agent
from fsmbt.sim.world import EVENT_DRIVEN, Divergence, Trajectory, World, first_divergence

Model = FSM | BTDocument


@dataclass
class Side:
    """The models driving a world's roles and the engine each runs on.

    Attributes:
        label: the side's name in reports (``"robot_bt.xml"``, ``"hfsm"`` ...).
        models: role -> model.
        engines: role -> engine (``fsmbt`` when a role is missing).
    """

    label: str
    models: dict[str, Model]
    engines: dict[str, str] = field(default_factory=dict)

    def agents(self, world: World) -> dict[str, Any]:
        """Fresh agents for one episode (name tables checked)."""
        return {
            role: build_agent(
                model, world, role, self.engines.get(role, "fsmbt"), where=f"{self.label} ({role})"
            )
            for role, model in self.models.items()
        }


def _outcome_letter(outcome: str) -> str:
    return {"success": "S", "failure": "F", "running": "R"}.get(outcome, outcome)


def run_episode(world: World, side: Side, seed: int) -> Trajectory:
    """One seeded episode of ``side`` in ``world``.

    Args:
        world: the world (reset here).
        side: the models and engines.
        seed: the episode's seed.

    Returns:
        The trajectory (``ended`` is ``"done"`` or ``"step limit"``).
    """
    world.reset(seed)
    agents = side.agents(world)
    for role, agent in agents.items():
        if world.roles[role] == EVENT_DRIVEN:
            agent.start()
    while len(world.records) < world.max_steps and not world.done():
        behaviour: dict[str, str] = {}
        for role in world.roles:
            agent = agents.get(role)
            if agent is None or not world.active(role):
                continue
            if world.roles[role] == EVENT_DRIVEN:
                events = world.sensor_events(role)
                for event in events:
                    agent.post(event)
                world.run_action(role, agent.action)
                if agent.terminated:
                    world.agent_terminated(role)
                behaviour[role] = f"{'+'.join(events) or '-'} -> {agent.action}"
            else:
                leaves, result = agent.tick(lambda name, r=role: world.leaf(r, name))
                trail = " ".join(f"{label}:{_outcome_letter(o)}" for label, o in leaves)
                behaviour[role] = f"{trail} => {result}"
                world.root_result(role, result)
        world.end_step(behaviour)
    records = list(world.records)
    return Trajectory(seed, records, "done" if world.done() else "step limit")


@dataclass
class EpisodeResult:
    """One episode of a comparison."""

    seed: int
    steps: tuple[int, int]
    divergence: Divergence | None

    @property
    def identical(self) -> bool:
        return self.divergence is None


@dataclass
class Comparison:
    """Every episode of a comparison of two sides, plus the first episode's trajectories."""

    left: Side
    right: Side
    episodes: list[EpisodeResult]
    first: tuple[Trajectory, Trajectory] | None
    seconds: float

    @property
    def identical(self) -> int:
        return sum(1 for e in self.episodes if e.identical)

    @property
    def steps(self) -> int:
        return sum(e.steps[0] + e.steps[1] for e in self.episodes)

    @property
    def first_divergence(self) -> EpisodeResult | None:
        return next((e for e in self.episodes if not e.identical), None)

    @property
    def all_identical(self) -> bool:
        return self.identical == len(self.episodes)


def compare(
    make_world: Callable[[], World],
    left: Side,
    right: Side,
    *,
    episodes: int = 100,
    seed: int = 0,
    keep: int | None = None,
) -> Comparison:
    """Run both sides for ``episodes`` seeded episodes and compare them step by step.

    Args:
        make_world: builds a world (one per side, so they never share state).
        left: one side.
        right: the other.
        episodes: how many episodes.
        seed: the first episode's seed (episode ``i`` uses ``seed + i``).
        keep: which episode's trajectories to keep for pictures: the first divergent one, else
            episode 0, when ``None``.

    Returns:
        The ``Comparison``.
    """
    started = time.perf_counter()
    world_a, world_b = make_world(), make_world()
    results: list[EpisodeResult] = []
    kept: tuple[Trajectory, Trajectory] | None = None
    for index in range(episodes):
        a = run_episode(world_a, left, seed + index)
        b = run_episode(world_b, right, seed + index)
        divergence = first_divergence(a, b)
        results.append(EpisodeResult(seed + index, (len(a.records), len(b.records)), divergence))
        if keep is not None:
            if index == keep:
                kept = (a, b)
        elif kept is None or (divergence is not None and all(r.identical for r in results[:-1])):
            kept = (a, b)
    return Comparison(left, right, results, kept, time.perf_counter() - started)


def worlds() -> Mapping[str, Callable[[], World]]:
    """The worlds by name (``robot``, ``predator-prey``)."""
    from fsmbt.sim.predator_prey import PredatorPreyWorld
    from fsmbt.sim.robot import RobotWorld

    return {"robot": RobotWorld, "predator-prey": PredatorPreyWorld}
