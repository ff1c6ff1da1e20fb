"""The predator-prey game: one predator (an FSM, event-driven) and two prey (a BT each,
leaf-driven) on a 12 x 12 continuous field, all acting in the same steps.

The world (docs/simulation.md, "The predator-prey game"):

- the predator patrols the corners of an inner square (``WAYPOINTS``, the first one seeded) at
  ``PATROL_SPEED``; ``detect`` stands still; ``chase`` runs at ``CHASE_SPEED`` at the nearest
  visible prey (else its last seen place); ``capture`` lunges for ``CAPTURE_STEPS`` steps and
  then catches the prey still within ``REACH`` with probability ``CATCH_CHANCE`` (a draw from the
  seed); ``rest`` stands still.
- its sensors (range ``PREDATOR_RANGE``; a prey in a haven is invisible) raise, each step, in
  this order: ``all_caught``; ``caught`` / ``escaped`` (the lunge that ended last step);
  ``tired`` (``STAMINA`` chase steps in a row); ``rested`` (``REST_STEPS`` rest steps in a
  row); ``prey_seen`` or ``prey_lost``; ``in_reach``.
- a prey senses the predator within ``PREY_RANGE``; havens (``HAVENS``) hide it; food patches
  (``FOOD``) feed it: hunger grows by one per step, it is hungry from ``HUNGRY``; ``eat`` takes
  ``EAT_STEPS`` steps; moving to food and eating fail when the predator is near; ``flee`` and
  ``wander`` (a seeded direction) are one step each (SUCCESS); ``go_to_haven`` runs until the
  prey is in the haven.
- a caught prey leaves the game; the episode ends when both prey are caught, when the predator's
  model terminates, or at ``max_steps``.

Name tables: ``PREDATOR_NAMES`` (the FSM's state actions; ``examples/predator_fsm.scxml``) and
``PREY_NAMES`` (the BT's leaves; ``examples/prey_bt.xml``), each with the world's own names.

Costs: O(prey) per sensor reading, O(1) per leaf tick and action.
"""

from __future__ import annotations

import math
import random
from collections.abc import Mapping, Sequence

from fsmbt.sim.geometry import Point, clamp, distance, rounded, step_away, step_towards
from fsmbt.sim.world import EVENT_DRIVEN, LEAF_DRIVEN, StepRecord

SIZE = 12.0
WAYPOINTS: tuple[Point, ...] = ((3.0, 3.0), (9.0, 3.0), (9.0, 9.0), (3.0, 9.0))
HAVENS: tuple[Point, ...] = ((1.0, 11.0), (11.0, 1.0))
FOOD: tuple[Point, ...] = ((6.0, 10.5), (6.0, 1.5))
PATROL_SPEED = 0.4
CHASE_SPEED = 0.65
PREY_SPEED = 0.5
PREDATOR_RANGE = 4.0
PREY_RANGE = 3.0
REACH = 0.8
HAVEN_RADIUS = 0.5
CAPTURE_STEPS = 2
CATCH_CHANCE = 0.6
STAMINA = 12
REST_STEPS = 6
HUNGRY = 30
EAT_STEPS = 2

SUCCESS, FAILURE, RUNNING = "success", "failure", "running"
PREDATOR = "predator"
PREY_ROLES = ("prey0", "prey1")
EVENTS = (
    "all_caught",
    "caught",
    "escaped",
    "tired",
    "rested",
    "prey_seen",
    "prey_lost",
    "in_reach",
)

PREDATOR_ACTIONS = ("patrol", "detect", "chase", "capture", "rest")
PREDATOR_NAMES: dict[str, str] = {
    "Patrol": "patrol",
    "Detect": "detect",
    "Chase": "chase",
    "Capture": "capture",
    "GiveUp": "rest",
    "Sated": "rest",
    **{name: name for name in PREDATOR_ACTIONS},
}
PREY_CONDITIONS = ("predator_near", "in_haven", "haven_closer", "hungry", "at_food")
PREY_ACTIONS = ("go_to_haven", "flee", "move_to_food", "eat", "wander")
PREY_NAMES: dict[str, str] = {
    "PredatorNear": "predator_near",
    "InHaven": "in_haven",
    "HavenCloserThanPredator": "haven_closer",
    "Hungry": "hungry",
    "AtFood": "at_food",
    "GoToHaven": "go_to_haven",
    "Flee": "flee",
    "MoveToFood": "move_to_food",
    "Eat": "eat",
    "Wander": "wander",
    **{name: name for name in (*PREY_CONDITIONS, *PREY_ACTIONS)},
}


def _nearest(origin: Point, places: Sequence[Point]) -> Point:
    return min(places, key=lambda p: (distance(origin, p), p))


class _Prey:
    def __init__(self, position: Point) -> None:
        self.position = position
        self.hunger = 0
        self.caught = False
        self.running: tuple[str, int] | None = None


class PredatorPreyWorld:
    """The predator-prey game: role ``predator`` (event-driven), ``prey0``/``prey1`` (leaves)."""

    name = "predator-prey"
    roles: Mapping[str, str] = {PREDATOR: EVENT_DRIVEN, **dict.fromkeys(PREY_ROLES, LEAF_DRIVEN)}

    def __init__(self, max_steps: int = 300) -> None:
        self.max_steps = max_steps
        self.reset(0)

    def reset(self, seed: int) -> None:
        """A new game: the predator's first waypoint and the prey's places from ``seed``."""
        self.rng = random.Random(seed)
        self.waypoint = self.rng.randrange(len(WAYPOINTS))
        self.predator: Point = WAYPOINTS[self.waypoint]
        self.prey = {
            role: _Prey(
                (round(self.rng.uniform(1.0, 11.0), 3), round(self.rng.uniform(1.0, 11.0), 3))
            )
            for role in PREY_ROLES
        }
        for prey in self.prey.values():
            prey.hunger = self.rng.randrange(HUNGRY)
        self.last_seen: Point | None = None
        self.action_run: tuple[str, int] = ("", 0)  # predator: (action, steps in a row)
        self.pending: list[str] = []  # lunge results, raised at the next sensor reading
        self.terminated = False
        self.step_index = 0
        self.records: list[StepRecord] = []
        self._events: list[str] = []

    # -- the interface ------------------------------------------------------------------------
    size: float = SIZE
    movers: tuple[str, ...] = (PREDATOR, *PREY_ROLES)

    def landmarks(self) -> list[tuple[str, Point]]:
        """Fixed places, for pictures."""
        return [
            *((f"haven {i}", h) for i, h in enumerate(HAVENS)),
            *((f"food {i}", f) for i, f in enumerate(FOOD)),
        ]

    def known_names(self, role: str) -> Sequence[str]:
        return tuple(PREDATOR_NAMES) if role == PREDATOR else tuple(PREY_NAMES)

    def event_names(self, role: str) -> Sequence[str]:
        return EVENTS if role == PREDATOR else ()

    def active(self, role: str) -> bool:
        if role == PREDATOR:
            return not self.terminated
        return not self.prey[role].caught

    def done(self) -> bool:
        return self.terminated or all(p.caught for p in self.prey.values())

    def _visible(self) -> list[tuple[str, _Prey]]:
        return [
            (role, p)
            for role, p in self.prey.items()
            if not p.caught
            and not self._in_haven(p.position)
            and distance(self.predator, p.position) <= PREDATOR_RANGE
        ]

    def _target(self) -> tuple[str, _Prey] | None:
        visible = self._visible()
        if not visible:
            return None
        return min(visible, key=lambda rp: (distance(self.predator, rp[1].position), rp[0]))

    def sensor_events(self, role: str) -> list[str]:
        events: list[str] = []
        if all(p.caught for p in self.prey.values()):
            events.append("all_caught")
        events.extend(self.pending)
        self.pending = []
        action, count = self.action_run
        if action == "chase" and count >= STAMINA:
            events.append("tired")
        if action == "rest" and count >= REST_STEPS:
            events.append("rested")
        target = self._target()
        events.append("prey_seen" if target is not None else "prey_lost")
        if target is not None and distance(self.predator, target[1].position) <= REACH:
            events.append("in_reach")
        return events

    def run_action(self, role: str, name: str | None) -> None:
        behaviour = PREDATOR_NAMES[name] if name is not None else "rest"
        action, count = self.action_run
        self.action_run = (behaviour, count + 1 if behaviour == action else 1)
        target = self._target()
        if target is not None:
            self.last_seen = target[1].position
        if behaviour == "patrol":
            goal = WAYPOINTS[self.waypoint]
            self.predator = step_towards(self.predator, goal, PATROL_SPEED)
            if self.predator == goal:
                self.waypoint = (self.waypoint + 1) % len(WAYPOINTS)
        elif behaviour == "chase":
            chased = target[1].position if target is not None else self.last_seen
            if chased is not None:
                self.predator = step_towards(self.predator, chased, CHASE_SPEED)
        elif behaviour == "capture":
            if target is not None:
                self.predator = step_towards(self.predator, target[1].position, CHASE_SPEED)
            if self.action_run[1] % CAPTURE_STEPS == 0:
                self._resolve_lunge()

    def _resolve_lunge(self) -> None:
        target = self._target()
        if (
            target is not None
            and distance(self.predator, target[1].position) <= REACH
            and self.rng.random() < CATCH_CHANCE
        ):
            target[1].caught = True
            self.pending.append("caught")
            self._events.append(f"{target[0]}_caught")
        else:
            self.pending.append("escaped")
            self._events.append("lunge_missed")

    def agent_terminated(self, role: str) -> None:
        """The predator's model reached a final state: the game ends after this step."""
        self.terminated = True

    def root_result(self, role: str, result: str) -> None:
        """A prey's tree returned: it is ticked again next step (nothing to do)."""

    # -- prey leaves --------------------------------------------------------------------------
    def leaf(self, role: str, name: str) -> str:
        prey = self.prey[role]
        behaviour = PREY_NAMES[name]
        if behaviour in PREY_CONDITIONS:
            return SUCCESS if self._condition(prey, behaviour) else FAILURE
        steps = prey.running[1] if prey.running and prey.running[0] == behaviour else 0
        outcome = self._prey_action(prey, behaviour, steps)
        prey.running = (behaviour, steps + 1) if outcome == RUNNING else None
        return outcome

    def _in_haven(self, position: Point) -> bool:
        return any(distance(position, h) <= HAVEN_RADIUS for h in HAVENS)

    def _near(self, prey: _Prey) -> bool:
        return distance(prey.position, self.predator) <= PREY_RANGE

    def _condition(self, prey: _Prey, name: str) -> bool:
        if name == "predator_near":
            return self._near(prey)
        if name == "in_haven":
            return self._in_haven(prey.position)
        if name == "haven_closer":
            haven = _nearest(prey.position, HAVENS)
            return distance(prey.position, haven) < distance(prey.position, self.predator)
        if name == "hungry":
            return prey.hunger >= HUNGRY
        return distance(prey.position, _nearest(prey.position, FOOD)) <= 1e-9  # at_food

    def _prey_action(self, prey: _Prey, name: str, steps: int) -> str:
        if name == "go_to_haven":
            haven = _nearest(prey.position, HAVENS)
            prey.position = step_towards(prey.position, haven, PREY_SPEED)
            return SUCCESS if prey.position == haven else RUNNING
        if name == "flee":
            prey.position = step_away(prey.position, self.predator, PREY_SPEED, SIZE)
            return SUCCESS
        if name == "wander":
            angle = self.rng.uniform(0.0, 2.0 * math.pi)
            prey.position = clamp(
                (
                    prey.position[0] + PREY_SPEED * math.cos(angle),
                    prey.position[1] + PREY_SPEED * math.sin(angle),
                ),
                SIZE,
            )
            return SUCCESS
        if self._near(prey):
            return FAILURE  # move_to_food / eat: the predator is near
        if name == "move_to_food":
            food = _nearest(prey.position, FOOD)
            prey.position = step_towards(prey.position, food, PREY_SPEED)
            return SUCCESS if prey.position == food else RUNNING
        if not self._condition(prey, "at_food"):
            return FAILURE  # eat: only at a food patch
        if steps + 1 < EAT_STEPS:
            return RUNNING
        prey.hunger = 0
        self._events.append("ate")
        return SUCCESS

    def end_step(self, behaviour: Mapping[str, str]) -> StepRecord:
        for prey in self.prey.values():
            if not prey.caught:
                prey.hunger += 1
        record = StepRecord(
            step=self.step_index,
            positions=(
                ("predator", rounded(self.predator)),
                *((role, rounded(p.position)) for role, p in self.prey.items()),
            ),
            behaviour=tuple(sorted(behaviour.items())),
            events=tuple(self._events),
            state=tuple((f"{role}.hunger", str(p.hunger)) for role, p in self.prey.items())
            + tuple((f"{role}.caught", str(p.caught)) for role, p in self.prey.items()),
        )
        self.records.append(record)
        self.step_index += 1
        self._events = []
        return record
