"""The world interface every simulation implements, and the trajectory it records.

Rules (docs/simulation.md, "The world interface"):

- A world has *roles* (``robot``; ``predator``, ``prey0``, ``prey1``): each role is driven by
  one agent. A role is either *leaf-driven* (a BT leaf ticks a condition or an action of the
  world by name; a BT->FSM conversion is run by leaf execution, so its state is the leaf being
  ticked) or *event-driven* (the world's sensors raise FSM events; the FSM state's action runs
  in the world once per step).
- Names: every role has a documented name table, model leaf/action name -> world behaviour;
  a model naming anything outside it is refused when the agent is built (``InputError``).
- Time advances in fixed steps; ``reset(seed)`` makes an episode reproducible: every random
  draw (start positions, pick failures, wandering) comes from one ``random.Random(seed)``.
- After each step the world appends a ``StepRecord``: positions, each role's behaviour this step
  (the leaves ticked with their outcomes, or the events and the action run) and world events.

Two trajectories are compared record by record (``first_divergence``); the first differing
record is the divergence. Cost: O(steps) per comparison.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

LEAF_DRIVEN = "leaf"
EVENT_DRIVEN = "event"


@dataclass(frozen=True)
class StepRecord:
    """What happened in one step.

    Attributes:
        step: the step's number (0 = the first step).
        positions: role or object name -> (x, y), rounded to 1e-6 (printing, comparing).
        behaviour: role -> what its agent did this step (e.g. ``"MovetoCube2:running"``).
        events: world events of the step (``"picked"``, ``"prey_seen"`` ...), in order.
        state: other world values worth showing (battery, cube in hand ...), as text.
    """

    step: int
    positions: tuple[tuple[str, tuple[float, float]], ...]
    behaviour: tuple[tuple[str, str], ...]
    events: tuple[str, ...]
    state: tuple[tuple[str, str], ...] = ()

    def describe(self) -> str:
        """One line: behaviour, events, positions, state."""
        beh = "; ".join(f"{role}: {what}" for role, what in self.behaviour)
        pos = ", ".join(f"{name}=({x:.2f},{y:.2f})" for name, (x, y) in self.positions)
        extra = ", ".join(f"{k}={v}" for k, v in self.state)
        events = ",".join(self.events) or "-"
        return f"behaviour [{beh}] events [{events}] at {pos}" + (f" [{extra}]" if extra else "")


@dataclass
class Trajectory:
    """An episode's records and how it ended (``"done"`` or ``"step limit"``)."""

    seed: int
    records: list[StepRecord] = field(default_factory=list)
    ended: str = ""


@dataclass(frozen=True)
class Divergence:
    """The first step where two trajectories differ, with both sides' records."""

    step: int
    left: StepRecord | None
    right: StepRecord | None

    def describe(self, left_name: str = "model", right_name: str = "other") -> str:
        """A short report: the step, then each side's behaviour and world state."""

        def side(record: StepRecord | None) -> str:
            return record.describe() if record is not None else "(episode already ended)"

        return (
            f"step {self.step}:\n  {left_name}: {side(self.left)}\n"
            f"  {right_name}: {side(self.right)}"
        )


def first_divergence(left: Trajectory, right: Trajectory) -> Divergence | None:
    """The first record that differs (a missing record counts), or ``None`` when identical.

    Args:
        left: one trajectory.
        right: the other, run from the same seed.

    Returns:
        The divergence, or ``None``.
    """
    for index in range(max(len(left.records), len(right.records))):
        a = left.records[index] if index < len(left.records) else None
        b = right.records[index] if index < len(right.records) else None
        if a != b:
            return Divergence(index, a, b)
    return None


class World(Protocol):
    """What the simulation runner needs from a world."""

    name: str
    roles: Mapping[str, str]  # role -> LEAF_DRIVEN / EVENT_DRIVEN
    max_steps: int
    records: list[StepRecord]  # this episode's records so far
    size: float  # the field is the square [0, size]^2 (pictures)
    movers: tuple[str, ...]  # what moves, as named in StepRecord.positions (pictures)

    def landmarks(self) -> list[tuple[str, tuple[float, float]]]:
        """Fixed places (charger, havens ...), for pictures."""
        ...

    def root_result(self, role: str, result: str) -> None:
        """A leaf-driven role's tree returned ``result`` (``SUCCESS``/``FAILURE``/``RUNNING``)."""
        ...

    def agent_terminated(self, role: str) -> None:
        """An event-driven role's model reached a final state."""
        ...

    def reset(self, seed: int) -> None:
        """Start a new episode from ``seed``."""
        ...

    def known_names(self, role: str) -> Sequence[str]:
        """The leaf / action names a model of ``role`` may use (its name table's keys)."""
        ...

    def event_names(self, role: str) -> Sequence[str]:
        """The events the sensors may raise for an event-driven ``role``."""
        ...

    def leaf(self, role: str, name: str) -> str:
        """Tick the leaf ``name`` for ``role``; ``"success"``/``"failure"``/``"running"``."""
        ...

    def sensor_events(self, role: str) -> list[str]:
        """The events the sensors raise for an event-driven ``role`` this step, in order."""
        ...

    def run_action(self, role: str, name: str | None) -> None:
        """Run the FSM state's action ``name`` (``None``: no action) for this step."""
        ...

    def active(self, role: str) -> bool:
        """Whether ``role`` still acts (a captured prey, a finished robot does not)."""
        ...

    def end_step(self, behaviour: Mapping[str, str]) -> StepRecord:
        """Close the step: physics (battery, capture), append and return its record."""
        ...

    def done(self) -> bool:
        """Whether the episode is over (mission complete, every prey captured ...)."""
        ...


def check_names(world: World, role: str, names: Sequence[str], where: str) -> None:
    """Refuse names outside the role's name table (docs/simulation.md "Name tables").

    Args:
        world: the world.
        role: the role the model plays.
        names: the leaf / action names the model uses.
        where: the model's name, for the message.

    Raises:
        InputError: naming every unknown name and the known ones.
    """
    from fsmbt.model.errors import InputError

    known = set(world.known_names(role))
    unknown = sorted({n for n in names if n not in known})
    if unknown:
        raise InputError(
            f"{where}: {', '.join(unknown)} not known to the {world.name} world's {role} "
            f"(known: {', '.join(sorted(known))}; docs/simulation.md, 'Name tables')"
        )
