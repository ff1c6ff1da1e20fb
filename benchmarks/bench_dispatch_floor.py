"""What one ticked node costs in BehaviorTree.CPP 4.8.2: the floor under any dispatch tree made of
built-in nodes (issue 23 item 6).

    PYTHONPATH=src python benchmarks/bench_dispatch_floor.py [--levels 0,1,3,6,9] [--steps 10000]

Trees ticked by the driver's ``--dispatch`` mode (``post(e)``: write ``{event}``, tick the root
once with ``tickExactlyOnce``), every step the event ``go``, timed in C++ (``--bench``: CPU ns
per step, only the ``post()`` calls):

- ``bare``: ``KeepRunningUntilFailure(AlwaysSuccess)`` - the blackboard write, the tick and two
  nodes: what a step costs before any dispatch;
- ``k Switch``: ``k`` nested ``Switch2`` on ``{event}`` whose first case matches (one
  comparison per level, the cheapest a ``Switch`` can be) above the bare tree;
- ``k x 2 Inverter``: ``2k`` nested ``Inverter`` above it (a node that reads no port).

The per-level columns are (step - bare step) / k. A dispatch over ``n`` states ticks at least
``ceil(log7 n)`` index ``Switch`` nodes, one event ``Switch`` and the user's leaf; the last lines
print a lower bound (the bare step and those Switches at their cheapest, the leaf not counted)
beside 50 x the plain transition table's cost (measured here too, the
driver's ``--table`` over a 2-state LEBT - a hash look-up per step).
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.model.fsm import FSM
from fsmbt.runtime.cpp import DriverSession, find_driver, status

BARE = "<KeepRunningUntilFailure><AlwaysSuccess/></KeepRunningUntilFailure>"


def tree(inner: str) -> str:
    return (
        '<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">'
        f"{inner}</BehaviorTree></root>"
    )


def switches(k: int) -> str:
    inner = BARE
    for _ in range(k):
        inner = (
            '<Switch2 variable="{event}" case_1="go" case_2="zz">'
            f"{inner}<AlwaysFailure/><AlwaysFailure/></Switch2>"
        )
    return tree(inner)


def inverters(k: int) -> str:
    inner = BARE
    for _ in range(2 * k):
        inner = f"<Inverter>{inner}</Inverter>"
    return tree(inner)


def ns_per_step(path: Path, text: str, steps: int, repeat: int, **mode: bool) -> float:
    path.write_text(text, encoding="utf-8")
    session = DriverSession(path, driver=find_driver(), timeout=600, **mode)
    return float(session.bench([["go"] * steps], repeat)["cpu_ns_per_step"])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", default="0,1,3,6,9")
    parser.add_argument("--steps", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    if find_driver() is None:
        print(f"C++ driver not built ({status().problem}); run scripts/build_btcpp.sh")
        return 2
    levels = [int(k) for k in args.levels.split(",") if k]
    with tempfile.TemporaryDirectory() as name:
        tmp = Path(name)
        bare = ns_per_step(tmp / "bare.xml", tree(BARE), args.steps, args.repeat, dispatch=True)
        header = (
            f"{'levels':>6} {'k Switch ns':>12} {'per Switch':>11} "
            f"{'k x 2 Inverter ns':>18} {'per Inverter':>13}"
        )
        print(f"\nbare step (blackboard write, tick, 2 nodes): {bare:,.1f} ns of CPU\n")
        print(header)
        print("-" * len(header))
        per_switch: list[float] = []
        for k in levels:
            sw = ns_per_step(tmp / "sw.xml", switches(k), args.steps, args.repeat, dispatch=True)
            inv = ns_per_step(tmp / "inv.xml", inverters(k), args.steps, args.repeat, dispatch=True)
            ps = (sw - bare) / k if k else float("nan")
            pi = (inv - bare) / (2 * k) if k else float("nan")
            if k:
                per_switch.append(ps)
            print(f"{k:>6} {sw:>12,.1f} {ps:>11,.1f} {inv:>18,.1f} {pi:>13,.1f}")
        fsm = FSM("two")
        fsm.add_state("A")
        fsm.add_state("B")
        fsm.initial = "A"
        fsm.add_transition("A", "go", "B")
        fsm.add_transition("B", "go", "A")
        lebt = dumps(convert(fsm, style="lebt").model, "btcpp")
        table = ns_per_step(tmp / "table.xml", lebt, args.steps, args.repeat, table=True)
        switch = sum(per_switch) / len(per_switch) if per_switch else float("nan")
        print(f"\nplain transition table: {table:,.1f} ns/step; 50 x table: {50 * table:,.1f} ns")
        print(f"mean cost of a best-case Switch level: {switch:,.1f} ns")
        print(f"{'states':>6} {'index levels':>12} {'lower bound ns':>15} {'bound / table':>14}")
        for n in (100, 1_000, 10_000):
            index = max(1, math.ceil(math.log(n, 7)))
            # bare step + index Switches + the event Switch, each at its cheapest (first case);
            # the user's leaf and the transition's nodes are not counted: a lower bound
            bound = bare + (index + 1) * switch
            print(f"{n:>6} {index:>12} {bound:>15,.1f} {bound / table:>13,.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
