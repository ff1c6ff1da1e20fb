"""Small 2-D helpers shared by the worlds (plain floats; no numpy on the step path)."""

from __future__ import annotations

import math

Point = tuple[float, float]


def distance(a: Point, b: Point) -> float:
    """Euclidean distance."""
    return math.hypot(a[0] - b[0], a[1] - b[1])


def step_towards(origin: Point, target: Point, speed: float) -> Point:
    """``origin`` moved by at most ``speed`` towards ``target`` (lands on it when closer)."""
    gap = distance(origin, target)
    if gap <= speed:
        return target
    ratio = speed / gap
    return (
        origin[0] + (target[0] - origin[0]) * ratio,
        origin[1] + (target[1] - origin[1]) * ratio,
    )


def step_away(origin: Point, threat: Point, speed: float, size: float) -> Point:
    """``origin`` moved by ``speed`` directly away from ``threat``, kept inside [0, size]^2."""
    dx, dy = origin[0] - threat[0], origin[1] - threat[1]
    norm = math.hypot(dx, dy) or 1.0
    return clamp((origin[0] + dx / norm * speed, origin[1] + dy / norm * speed), size)


def clamp(point: Point, size: float) -> Point:
    """``point`` kept inside the square [0, size]^2."""
    return (min(max(point[0], 0.0), size), min(max(point[1], 0.0), size))


def rounded(point: Point) -> Point:
    """Rounded to 1e-6, so that records compare and print the same on every platform."""
    return (round(point[0], 6), round(point[1], 6))
