"""Names for generated models: the paper's three scenarios (basic symbols, robot grasping, game AI).

A vocabulary gives state names, event names and BT leaf names (actions and conditions). When a
model needs more names than a list holds, names repeat with a number (``Patrol2``), so every
generated name is unique where it must be and readable everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass

SCENARIOS = ("basic", "robot", "game")


@dataclass(frozen=True)
class Vocabulary:
    """Word lists of one scenario. ``events`` is empty for ``basic`` (events are ``eventXY``)."""

    scenario: str
    states: tuple[str, ...]
    events: tuple[str, ...]
    actions: tuple[str, ...]
    conditions: tuple[str, ...]


def letters(index: int) -> str:
    """Spreadsheet-style symbols: 0 -> A, 25 -> Z, 26 -> AA, 27 -> AB ..."""
    out = ""
    index += 1
    while index:
        index, rem = divmod(index - 1, 26)
        out = chr(ord("A") + rem) + out
    return out


_ROBOT = Vocabulary(
    "robot",
    states=(
        "Idle",
        "Navigate",
        "Detect",
        "Approach",
        "Grasp",
        "Lift",
        "Transport",
        "Place",
        "Release",
        "Recharge",
        "Dock",
        "Inspect",
        "Scan",
        "Localize",
        "Align",
        "Retreat",
        "Wait",
        "Calibrate",
        "Search",
        "Pick",
        "Deliver",
        "Verify",
        "Report",
        "ReturnHome",
        "Explore",
        "Undock",
        "OpenGripper",
        "CloseGripper",
        "Regrasp",
        "Recover",
    ),
    events=(
        "arrived",
        "detected",
        "lost",
        "grasped",
        "slipped",
        "placed",
        "battery_low",
        "charged",
        "timeout",
        "done",
        "failed",
        "retry",
        "obstacle",
        "cleared",
        "reset",
        "aligned",
        "released",
    ),
    actions=(
        "Navigate",
        "Detect",
        "Approach",
        "Grasp",
        "Lift",
        "Place",
        "Release",
        "Recharge",
        "Dock",
        "Inspect",
        "Scan",
        "MoveToCube",
        "PickCube",
        "MoveToDelivery",
        "PlaceCube",
        "OpenGripper",
        "CloseGripper",
        "Localize",
        "Align",
        "Retreat",
    ),
    conditions=(
        "BatteryLow",
        "ObjectDetected",
        "AtGoal",
        "ObjectInHand",
        "AtDelivery",
        "PathClear",
        "Docked",
        "Calibrated",
        "AtCube",
        "CubeInDelivery",
        "GripperOpen",
        "Localized",
        "AtInspection",
        "Aligned",
    ),
)

_GAME = Vocabulary(
    "game",
    states=(
        "Idle",
        "Patrol",
        "Chase",
        "Attack",
        "Flee",
        "Forage",
        "Hide",
        "Search",
        "Guard",
        "Heal",
        "Reload",
        "Ambush",
        "Wander",
        "Eat",
        "Sleep",
        "Rest",
        "Investigate",
        "Alert",
        "Retreat",
        "Regroup",
        "Defend",
        "Follow",
        "Evade",
        "Taunt",
        "Dodge",
        "Block",
        "Loot",
        "Return",
        "Scout",
        "Hunt",
    ),
    events=(
        "enemy_seen",
        "enemy_lost",
        "in_range",
        "out_of_range",
        "low_health",
        "healed",
        "hungry",
        "fed",
        "noise",
        "timeout",
        "cornered",
        "safe",
        "ally_called",
        "ammo_empty",
        "reloaded",
        "dawn",
        "dusk",
    ),
    actions=(
        "Patrol",
        "Chase",
        "Attack",
        "Flee",
        "Forage",
        "Hide",
        "Search",
        "Heal",
        "Reload",
        "Ambush",
        "Wander",
        "Eat",
        "Roost",
        "Investigate",
        "Retreat",
        "Defend",
        "Follow",
        "Evade",
        "Loot",
        "Scout",
    ),
    conditions=(
        "EnemyVisible",
        "InRange",
        "HealthLow",
        "Hungry",
        "AmmoEmpty",
        "HeardNoise",
        "IsSafe",
        "AllyNearby",
        "IsNight",
        "HasFood",
        "Cornered",
        "TargetDead",
    ),
)


def vocabulary(scenario: str) -> Vocabulary:
    """The vocabulary of ``scenario`` (``basic``, ``robot`` or ``game``)."""
    if scenario == "basic":
        symbols = tuple(letters(i) for i in range(26))
        return Vocabulary(
            "basic",
            states=symbols,
            events=(),
            actions=symbols,
            conditions=tuple(f"Is{s}" for s in symbols),
        )
    if scenario == "robot":
        return _ROBOT
    if scenario == "game":
        return _GAME
    raise ValueError(f"unknown scenario {scenario!r} (known: {', '.join(SCENARIOS)})")


def numbered(words: tuple[str, ...], index: int, *, basic: bool = False) -> str:
    """The ``index``-th name of a list, cycling with a number suffix (``Patrol2``).

    ``basic`` lists continue with spreadsheet symbols (``AA``) instead of numbers.
    """
    if basic:
        return letters(index)
    word = words[index % len(words)]
    lap = index // len(words)
    return word if lap == 0 else f"{word}{lap + 1}"
