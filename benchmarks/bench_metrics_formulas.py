"""Measured graphical element counts of converted models vs the paper's formulas.

FSM -> BT: >= 100 generated FSMs per size class (2-10, 11-20, 21-30 states), converted with
rules (LEBT, formula 7M-1), bsd (8M+1) and chds (ours: 6T+6M+1); M = reachable states of the
source, T = its transitions that can fire. BT -> FSM: >= 100 generated BTs converted with rules
and chds (hierarchical, formula 4M+2k+1, M = leaves, k = sub-FSMs) and bsd (flat, k = 0).
Counting rules: docs/metrics.md. Usage: python benchmarks/bench_metrics_formulas.py [--n 100]
"""

from __future__ import annotations

import argparse
import time

from fsmbt.convert.engines import converter_for
from fsmbt.generate.generator import random_bt, random_fsm
from fsmbt.metrics import elements
from fsmbt.metrics.formulas import FORMULA_TEXT, Comparison, bsd, chds, hfsm, lebt

SIZE_CLASSES = ((2, 10), (11, 20), (21, 30))
SCENARIOS = ("basic", "robot", "game")


def fsm_rows(n: int) -> list[Comparison]:
    rows = []
    for low, high in SIZE_CLASSES:
        measured: dict[str, list[int]] = {"rules": [], "bsd": [], "chds": []}
        predicted: dict[str, list[int]] = {"rules": [], "bsd": [], "chds": []}
        for i in range(n):
            fsm = random_fsm(
                seed=f"formula-{low}-{i}",
                min_states=low,
                max_states=high,
                scenario=SCENARIOS[i % 3],
            )
            for engine in measured:
                result = converter_for(engine, fsm)(fsm)
                measured[engine].append(elements(result.model).graphical)
                m = result.stats["states"]
                if engine == "rules":
                    predicted[engine].append(lebt(m))
                elif engine == "bsd":
                    predicted[engine].append(bsd(m))
                else:
                    predicted[engine].append(chds(m, result.stats["switches"]))
        for engine, formula in (("rules", "lebt"), ("bsd", "bsd"), ("chds", "chds")):
            rows.append(
                Comparison.of(
                    f"FSM->BT {engine:5} M={low}-{high}",
                    FORMULA_TEXT[formula],
                    measured[engine],
                    predicted[engine],
                )
            )
    return rows


def bt_rows(n: int) -> list[Comparison]:
    measured: dict[str, list[int]] = {"rules": [], "bsd": [], "chds": []}
    predicted: dict[str, list[int]] = {"rules": [], "bsd": [], "chds": []}
    for i in range(n):
        bt = random_bt(seed=f"formula-bt-{i}", scenario=SCENARIOS[i % 3])
        leaves = sum(1 for _t, node in bt.nodes() if node.is_leaf)
        for engine in measured:
            e = elements(converter_for(engine, bt)(bt).model)
            measured[engine].append(e.graphical)
            predicted[engine].append(hfsm(leaves, e.sub_fsms))
    return [
        Comparison.of(
            f"BT->FSM {engine:5} (k={'0' if engine == 'bsd' else 'sub-FSMs'})",
            FORMULA_TEXT["hfsm"],
            measured[engine],
            predicted[engine],
        )
        for engine in measured
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100, help="models per size class")
    args = parser.parse_args()
    began = time.perf_counter()
    rows = fsm_rows(args.n) + bt_rows(args.n)
    header = (
        f"{'set':34} {'formula':8} {'n':>4} {'meas.mean':>9} {'min':>5} {'max':>5} "
        f"{'pred.mean':>9} {'dev.mean':>8} {'dev.min':>8} {'dev.max':>8} {'exact':>6}"
    )
    print(header)
    print("-" * len(header))
    for r in rows:
        print(
            f"{r.label:34} {r.formula:8} {r.n:>4} {r.measured_mean:>9.1f} {r.measured_min:>5} "
            f"{r.measured_max:>5} {r.predicted_mean:>9.1f} {r.deviation_mean:>+8.1%} "
            f"{r.deviation_min:>+8.1%} {r.deviation_max:>+8.1%} {r.exact_share:>6.0%}"
        )
    print(f"({time.perf_counter() - began:.1f} s; deviation = (measured - formula) / formula)")


if __name__ == "__main__":
    main()
