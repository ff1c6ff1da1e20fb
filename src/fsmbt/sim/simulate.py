"""``fsmbt simulate``'s work, as a library call: which roles a model plays, the companion
models of the other roles, one comparison per engine.

Rules (docs/simulation.md, "fsmbt simulate"):

- The role: the robot world has one (``robot``). In the predator-prey game a model plays the
  predator when every name it uses is in the predator's name table, the prey (both prey) when
  every name is in the prey's; ``role`` overrides this. A model fitting neither is refused
  with the names that do not fit.
- The other roles are played by the shipped models (``fsmbt/sim/models/predator_fsm.scxml`` and
  ``prey_bt.xml``, the same files as ``examples/``), on fsmbt's runners, on both sides.
- One row per engine: each side's model runs on the engine when it can (``engines_for``), else
  on fsmbt's runner; the row names what each side ran on. A row where neither side can use the
  engine is not run, and neither is python-statemachine when it does not import: a note says so
  and the row is never counted as identical.

Costs: ``episodes`` x 2 episodes per row (``fsmbt.sim.run.compare``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from importlib import resources

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.execution import engines_for
from fsmbt.sim.agents import ENGINES, model_names
from fsmbt.sim.run import Comparison, Side, compare, worlds
from fsmbt.sim.world import World

Model = FSM | BTDocument
#: The companion models of the predator-prey game, by role family.
COMPANIONS = {"predator": "predator_fsm.scxml", "prey": "prey_bt.xml"}


@dataclass
class Row:
    """One engine's comparison (``comparison`` is ``None`` when the row was skipped)."""

    engine: str
    left_engine: str
    right_engine: str
    comparison: Comparison | None
    note: str = ""


@dataclass
class Simulation:
    """All rows of one ``simulate`` call."""

    world: str
    role: str
    rows: list[Row] = field(default_factory=list)

    @property
    def ran(self) -> list[Row]:
        return [row for row in self.rows if row.comparison is not None]

    @property
    def all_identical(self) -> bool:
        """True when at least one row ran and every row that ran is identical."""
        return bool(self.ran) and all(
            r.comparison is not None and r.comparison.all_identical for r in self.ran
        )


def companion(family: str) -> Model:
    """The shipped model of a predator-prey role family (``predator`` or ``prey``)."""
    from fsmbt.api import load_text

    name = COMPANIONS[family]
    text = resources.files("fsmbt.sim").joinpath("models", name).read_text(encoding="utf-8")
    return load_text(text, filename=name).model


def role_of(world_name: str, model: Model, role: str | None = None) -> str:
    """The role family a model plays: ``robot``, ``predator`` or ``prey``.

    Raises:
        InputError: an unknown world or role, or a model fitting no role (its unknown names).
    """
    families = {"robot": ("robot",), "predator-prey": ("predator", "prey")}
    if world_name not in families:
        raise InputError(f"unknown world '{world_name}' (worlds: {', '.join(families)})")
    if role is not None:
        if role not in families[world_name]:
            raise InputError(
                f"the {world_name} world has no role '{role}' "
                f"(roles: {', '.join(families[world_name])})"
            )
        return role
    if world_name == "robot":
        return "robot"
    from fsmbt.sim.predator_prey import PREDATOR_NAMES, PREY_NAMES

    names = set(model_names(model))
    if not names:
        raise InputError("the model asks the world for nothing (no leaf, no state action)")
    if names <= set(PREDATOR_NAMES):
        return "predator"
    if names <= set(PREY_NAMES):
        return "prey"
    unknown = sorted(names - set(PREDATOR_NAMES) - set(PREY_NAMES)) or sorted(names)
    raise InputError(
        f"the model fits neither the predator nor the prey of the predator-prey "
        f"world: {', '.join(unknown)} (docs/simulation.md, 'Name tables')"
    )


def _roles(world: World, family: str) -> list[str]:
    return [r for r in world.roles if r == family or (family == "prey" and r.startswith("prey"))]


def simulate(
    world_name: str,
    model: Model,
    other: Model,
    *,
    engines: Sequence[str] = ENGINES,
    episodes: int = 100,
    seed: int = 0,
    role: str | None = None,
    names: tuple[str, str] = ("model", "other"),
    max_steps: int | None = None,
    statemachine_available: Callable[[], bool] | None = None,
    keep: int | None = None,
) -> Simulation:
    """Compare ``model`` and ``other`` in a world, one row per engine.

    Args:
        world_name: ``robot`` or ``predator-prey``.
        model: the model.
        other: the model to compare it with (e.g. its conversion).
        engines: the engines to run (``fsmbt``, ``btcpp``, ``py_trees``,
            ``python-statemachine``).
        episodes: episodes per row.
        seed: the first episode's seed.
        role: the role family (inferred when ``None``).
        names: the two sides' labels.
        max_steps: the step limit of an episode (the world's default when ``None``).
        statemachine_available: tells whether python-statemachine imports (tests pass one).
        keep: the episode whose trajectories are kept for pictures (``compare``'s ``keep``).

    Returns:
        The ``Simulation``.

    Raises:
        InputError: an unknown world, role or engine; names outside the role's table.
    """
    from fsmbt.sim.scxml_engine import available

    makers = worlds()
    family = role_of(world_name, model, role)
    role_of(world_name, other, family)  # same checks for the other model
    base = makers[world_name]

    def make_world() -> World:
        return base() if max_steps is None else base(max_steps=max_steps)  # type: ignore[call-arg]

    probe = make_world()
    played = _roles(probe, family)
    companions: dict[str, Model] = {}
    for r in probe.roles:
        if r not in played:
            companions[r] = companion("predator" if r == "predator" else "prey")
    result = Simulation(world_name, family)
    has_statemachine = (statemachine_available or available)()
    for engine in engines:
        if engine not in ENGINES:
            raise InputError(f"unknown engine '{engine}' (engines: {', '.join(ENGINES)})")
        left_engine = engine if engine in engines_for(model) else "fsmbt"
        right_engine = engine if engine in engines_for(other) else "fsmbt"
        if engine != "fsmbt" and left_engine == right_engine == "fsmbt":
            result.rows.append(
                Row(
                    engine,
                    left_engine,
                    right_engine,
                    None,
                    f"skipped {engine}: neither model runs on it",
                )
            )
            continue
        if engine == "python-statemachine" and not has_statemachine:
            result.rows.append(
                Row(
                    engine,
                    left_engine,
                    right_engine,
                    None,
                    "skipped python-statemachine: the statemachine package does "
                    "not import (pip install python-statemachine==3.2.2)",
                )
            )
            continue
        left = Side(
            names[0],
            {**companions, **dict.fromkeys(played, model)},
            dict.fromkeys(played, left_engine),
        )
        right = Side(
            names[1],
            {**companions, **dict.fromkeys(played, other)},
            dict.fromkeys(played, right_engine),
        )
        comparison = compare(make_world, left, right, episodes=episodes, seed=seed, keep=keep)
        result.rows.append(Row(engine, left_engine, right_engine, comparison))
    return result
