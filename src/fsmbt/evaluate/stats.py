"""The statistics of the report: Wilson score intervals and a least-squares slope with its error.

Wilson (not the normal approximation): it stays inside [0, 1] and keeps its coverage at 0 % and
100 %, which is where converters that are correct by construction sit. z = 1.96 (95 %).
The slope fit is ordinary least squares ``y = a x + b``; the error is the standard error of
``a`` (residual variance / sum of squared x deviations). Cost: O(n).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

Z95 = 1.959963984540054


def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of ``successes`` out of ``n`` (``(0, 1)`` for ``n = 0``).

    Args:
        successes: the count of successes.
        n: the number of trials.
        z: the normal quantile (1.96 for 95 %).

    Returns:
        ``(low, high)`` as shares.
    """
    if n == 0:
        return 0.0, 1.0
    p = successes / n
    denominator = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denominator
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denominator
    return max(0.0, centre - half), min(1.0, centre + half)


def fit_slope(x: Sequence[float], y: Sequence[float]) -> tuple[float, float, float]:
    """Least-squares ``y = a x + b``.

    Args:
        x: the predictor (e.g. M).
        y: the measured values.

    Returns:
        ``(a, standard error of a, b)``; the error is ``nan`` with fewer than 3 points or
        constant ``x``.
    """
    n = len(x)
    if n == 0:
        return math.nan, math.nan, math.nan
    mx = sum(x) / n
    my = sum(y) / n
    sxx = sum((xi - mx) ** 2 for xi in x)
    if sxx == 0:
        return math.nan, math.nan, my
    a = sum((xi - mx) * (yi - my) for xi, yi in zip(x, y)) / sxx
    b = my - a * mx
    if n < 3:
        return a, math.nan, b
    residual = sum((yi - (a * xi + b)) ** 2 for xi, yi in zip(x, y)) / (n - 2)
    return a, math.sqrt(residual / sxx), b
