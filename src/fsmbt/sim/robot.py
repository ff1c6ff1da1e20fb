"""The robot grasping world: a mobile manipulator delivers a cube, keeps its battery charged and
docks at the inspection point (the world of the paper's robot BT, ``examples/robot_bt.xml``).

The world (a 10 x 10 m floor; docs/simulation.md, "The robot grasping world"):

- places: the charger (1, 1), the delivery station (9, 1), the inspection dock (5, 9); cube 2 at a
  seeded place in [2, 8] x [3, 7]; the robot starts at a seeded place with a seeded charge in
  [20, 100] %.
- the battery drains ``MOVE_DRAIN`` per step of motion and ``IDLE_DRAIN`` per step; it is low
  below ``LOW_BATTERY``; at the charger it gains ``CHARGE_RATE`` per step.
- actions take several steps (RUNNING, then SUCCESS or FAILURE): a move goes ``SPEED`` per step
  and fails when the battery is empty; ``pick`` takes ``PICK_STEPS`` steps next to the cube and
  then fails with probability ``PICK_FAILURE`` (a draw from the episode's seed); ``place`` takes
  ``PLACE_STEPS`` at the delivery station with the cube in hand; ``recharge`` drives to the
  charger (on reserve power: it never fails) and charges to full; ``dock`` drives to the dock
  and takes ``DOCK_STEPS`` to latch.
- an action ticked again while it is the one running continues; any other tick starts it anew.

Name table (``NAMES``): the paper's leaf names onto the world's behaviours. ``BatteryBelow`` is
the first child of ``Fallback(BatteryBelow, Recharge)``: the recharge runs only when that leaf
fails, so the leaf succeeds when the charge is *not* below the threshold ("the drain is below
budget"). The world's own names (``battery_ok``, ``move_to_cube`` ...) are accepted too.

Costs: O(1) per leaf tick and per step.
"""

from __future__ import annotations

import random
from collections.abc import Mapping, Sequence

from fsmbt.sim.geometry import Point, distance, rounded, step_towards
from fsmbt.sim.world import LEAF_DRIVEN, StepRecord

SIZE = 10.0
CHARGER: Point = (1.0, 1.0)
DELIVERY: Point = (9.0, 1.0)
DOCK: Point = (5.0, 9.0)
SPEED = 0.5
MOVE_DRAIN = 1.5
IDLE_DRAIN = 0.1
LOW_BATTERY = 30.0
CHARGE_RATE = 20.0
PICK_STEPS = 2
PICK_FAILURE = 0.3
PLACE_STEPS = 2
DOCK_STEPS = 2
REACH = 1e-9  # "at" a place: on it (moves land exactly on their target)

SUCCESS, FAILURE, RUNNING = "success", "failure", "running"

#: The world's behaviours: conditions and actions.
CONDITIONS = (
    "battery_ok",
    "battery_low",
    "cube_delivered",
    "cube_in_hand",
    "at_cube",
    "at_delivery",
    "at_inspection",
)
ACTIONS = ("recharge", "move_to_cube", "pick", "move_to_delivery", "place", "dock")
#: Model leaf name -> world behaviour (the paper's robot BT, then the world's own names).
NAMES: dict[str, str] = {
    "BatteryBelow": "battery_ok",
    "Cube2inDelivery": "cube_delivered",
    "CubeinHand": "cube_in_hand",
    "RobotatCube2": "at_cube",
    "RobotatDelivery": "at_delivery",
    "RobotAtInspection": "at_inspection",
    "Recharge": "recharge",
    "MovetoCube2": "move_to_cube",
    "Pickcube2": "pick",
    "MovetoDelivery": "move_to_delivery",
    "PlaceCube2": "place",
    "Dock": "dock",
    **{name: name for name in (*CONDITIONS, *ACTIONS)},
}
ROLE = "robot"


class RobotWorld:
    """The robot grasping world (one role, ``robot``, leaf-driven)."""

    name = "robot"
    roles: Mapping[str, str] = {ROLE: LEAF_DRIVEN}

    def __init__(self, max_steps: int = 400) -> None:
        self.max_steps = max_steps
        self.reset(0)

    def reset(self, seed: int) -> None:
        """A new episode: robot, cube and charge placed from ``seed``."""
        self.rng = random.Random(seed)
        self.robot: Point = (
            round(self.rng.uniform(0.5, 9.5), 3),
            round(self.rng.uniform(0.5, 9.5), 3),
        )
        self.cube: Point = (
            round(self.rng.uniform(2.0, 8.0), 3),
            round(self.rng.uniform(3.0, 7.0), 3),
        )
        self.battery = float(self.rng.randint(20, 100))
        self.in_hand = False
        self.delivered = False
        self.docked = False
        self.finished = False
        self.step_index = 0
        self.records: list[StepRecord] = []
        self._running: tuple[str, int] | None = None  # (behaviour, steps done)
        self._events: list[str] = []
        self._latched = 0

    # -- the interface ------------------------------------------------------------------------
    size: float = SIZE
    movers: tuple[str, ...] = ("robot", "cube")

    def landmarks(self) -> list[tuple[str, Point]]:
        """Fixed places, for pictures."""
        return [("charger", CHARGER), ("delivery", DELIVERY), ("inspection dock", DOCK)]

    def known_names(self, role: str) -> Sequence[str]:
        return tuple(NAMES)

    def event_names(self, role: str) -> Sequence[str]:
        return ()

    def sensor_events(self, role: str) -> list[str]:
        return []

    def run_action(self, role: str, name: str | None) -> None:
        raise NotImplementedError("the robot is leaf-driven")

    def active(self, role: str) -> bool:
        return not self.finished

    def leaf(self, role: str, name: str) -> str:
        behaviour = NAMES[name]
        if behaviour in CONDITIONS:
            return SUCCESS if self._condition(behaviour) else FAILURE
        steps = self._running[1] if self._running and self._running[0] == behaviour else 0
        outcome = getattr(self, f"_{behaviour}")(steps)
        self._running = (behaviour, steps + 1) if outcome == RUNNING else None
        return outcome

    def agent_terminated(self, role: str) -> None:
        """Not used: the robot is leaf-driven (its end is its root's SUCCESS)."""

    def root_result(self, role: str, result: str) -> None:
        """The robot's tree returned ``result``: SUCCESS ends the mission; FAILURE is retried
        from the root on the next step."""
        if result == "SUCCESS":
            self.finished = True
            self._events.append("mission_complete")
        elif result == "FAILURE":
            self._events.append("mission_failed")

    def end_step(self, behaviour: Mapping[str, str]) -> StepRecord:
        self.battery = max(0.0, self.battery - IDLE_DRAIN)
        record = StepRecord(
            step=self.step_index,
            positions=(("robot", rounded(self.robot)), ("cube", rounded(self.cube))),
            behaviour=tuple(sorted(behaviour.items())),
            events=tuple(self._events),
            state=(
                ("battery", f"{self.battery:.1f}"),
                ("in_hand", str(self.in_hand)),
                ("delivered", str(self.delivered)),
            ),
        )
        self.records.append(record)
        self.step_index += 1
        self._events = []
        return record

    def done(self) -> bool:
        return self.finished

    # -- conditions ---------------------------------------------------------------------------
    def _condition(self, name: str) -> bool:
        if name == "battery_ok":
            return self.battery >= LOW_BATTERY
        if name == "battery_low":
            return self.battery < LOW_BATTERY
        if name == "cube_delivered":
            return self.delivered
        if name == "cube_in_hand":
            return self.in_hand
        if name == "at_cube":
            return distance(self.robot, self.cube) <= REACH
        if name == "at_delivery":
            return distance(self.robot, DELIVERY) <= REACH
        return distance(self.robot, DOCK) <= REACH  # at_inspection

    # -- actions (argument: steps already done in this run of the action) ---------------------
    def _move(self, target: Point, *, reserve: bool = False) -> str:
        if distance(self.robot, target) <= REACH:
            return SUCCESS
        if self.battery <= 0.0 and not reserve:
            self._events.append("battery_empty")
            return FAILURE
        self.robot = step_towards(self.robot, target, SPEED)
        if self.in_hand:
            self.cube = self.robot
        self.battery = max(0.0, self.battery - MOVE_DRAIN)
        return RUNNING

    def _move_to_cube(self, steps: int) -> str:
        return self._move(self.cube)

    def _move_to_delivery(self, steps: int) -> str:
        return self._move(DELIVERY)

    def _recharge(self, steps: int) -> str:
        if self._move(CHARGER, reserve=True) == RUNNING:
            return RUNNING
        self.battery = min(100.0, self.battery + CHARGE_RATE)
        if self.battery >= 100.0:
            self._events.append("charged")
            return SUCCESS
        return RUNNING

    def _pick(self, steps: int) -> str:
        if self.in_hand or distance(self.robot, self.cube) > REACH:
            return FAILURE
        if steps + 1 < PICK_STEPS:
            return RUNNING
        if self.rng.random() < PICK_FAILURE:
            self._events.append("pick_failed")
            return FAILURE
        self.in_hand = True
        self._events.append("picked")
        return SUCCESS

    def _place(self, steps: int) -> str:
        if not self.in_hand or distance(self.robot, DELIVERY) > REACH:
            return FAILURE
        if steps + 1 < PLACE_STEPS:
            return RUNNING
        self.in_hand = False
        self.delivered = True
        self._events.append("delivered")
        return SUCCESS

    def _dock(self, steps: int) -> str:
        if steps == 0:
            self._latched = 0
        moved = self._move(DOCK)
        if moved != SUCCESS:
            return moved
        self._latched += 1
        if self._latched < DOCK_STEPS:
            return RUNNING
        self.docked = True
        self._events.append("docked")
        return SUCCESS
