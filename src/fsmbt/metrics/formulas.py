"""The paper's size formulas and the exact counts of our constructions, to compare measured
element counts with (docs/metrics.md explains which hold where).

Paper: LEBT ≈ 7M − 1 (M FSM states); HFSM = 4M + 2k + 1 (M BT leaves, k sub-FSMs);
BSD = 8M + 1 (M FSM states). Ours, exact by construction (see docs/baselines.md):
CHDS-BT = 6T + 6M + 1 (T transitions) and a start subtree of 6 more elements for BSD / CHDS
when the FSM has an initial event (a start pseudo-state).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from statistics import mean


def lebt(m: int) -> int:
    return 7 * m - 1


def hfsm(m: int, k: int) -> int:
    return 4 * m + 2 * k + 1


def bsd(m: int) -> int:
    return 8 * m + 1


def chds(m: int, t: int) -> int:
    return 6 * t + 6 * m + 1


FORMULAS: dict[str, Callable[..., int]] = {"lebt": lebt, "hfsm": hfsm, "bsd": bsd, "chds": chds}
FORMULA_TEXT = {"lebt": "7M-1", "hfsm": "4M+2k+1", "bsd": "8M+1", "chds": "6T+6M+1"}


@dataclass
class Comparison:
    """Measured vs predicted over a set: mean/min/max of both and of the relative deviation
    ``(measured - predicted) / predicted``."""

    label: str
    formula: str
    n: int
    measured_mean: float
    measured_min: int
    measured_max: int
    predicted_mean: float
    deviation_mean: float
    deviation_min: float
    deviation_max: float
    exact_share: float  # share of models where measured == predicted

    @classmethod
    def of(
        cls, label: str, formula: str, measured: Sequence[int], predicted: Sequence[int]
    ) -> Comparison:
        if not measured or len(measured) != len(predicted):
            raise ValueError("need as many predictions as measurements (at least one)")
        deviations = [(m - p) / p if p else 0.0 for m, p in zip(measured, predicted)]
        return cls(
            label,
            formula,
            len(measured),
            mean(measured),
            min(measured),
            max(measured),
            mean(predicted),
            mean(deviations),
            min(deviations),
            max(deviations),
            sum(m == p for m, p in zip(measured, predicted)) / len(measured),
        )
