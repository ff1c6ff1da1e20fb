"""At least 1 000 generated models, both directions, every scenario and the extended node set:
each conversion must be proven equivalent by the checker (100% is the only acceptable figure)."""

from __future__ import annotations

import pytest

from fsmbt.convert import convert
from fsmbt.generate import random_bt, random_fsm
from support.conv_helpers import check

SCENARIOS = ("basic", "robot", "game")
FSM_SMALL, FSM_LARGE, BT_PAPER, BT_EXTENDED = 300, 100, 350, 250
TOTAL = FSM_SMALL + FSM_LARGE + BT_PAPER + BT_EXTENDED


def _failures(models) -> tuple[int, list[str]]:
    failures, count = [], 0
    for label, model in models:
        result = convert(model)
        report = check(model, result.model)
        count += 1
        if not report.equivalent:
            failing = [n for n, p in report.properties.items() if not p.holds]
            failures.append(f"{label}: {failing}")
    return count, failures


def test_total_is_at_least_one_thousand() -> None:
    assert TOTAL >= 1000


@pytest.mark.parametrize("size", ["small", "large"])
def test_generated_fsms_convert_equivalently(size: str) -> None:
    if size == "small":
        seeds, low, high = range(FSM_SMALL), 2, 12
    else:
        seeds, low, high = range(10_000, 10_000 + FSM_LARGE), 13, 30
    models = (
        (f"fsm seed {s}", random_fsm(s, scenario=SCENARIOS[s % 3], min_states=low, max_states=high))
        for s in seeds
    )
    count, failures = _failures(models)
    assert count == len(seeds) and failures == []


@pytest.mark.parametrize("extended", [False, True])
def test_generated_bts_convert_equivalently(extended: bool) -> None:
    n, budget = (BT_EXTENDED, 20) if extended else (BT_PAPER, 60)
    models = (
        (
            f"bt seed {s} extended={extended}",
            random_bt(s, scenario=SCENARIOS[s % 3], extended=extended, max_nodes=budget),
        )
        for s in range(n)
    )
    count, failures = _failures(models)
    assert count == n and failures == []
