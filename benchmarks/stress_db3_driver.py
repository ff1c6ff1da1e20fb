"""Stress the C++ driver's SQLite log: how often does a ``--db3`` recording hang under load?

    PYTHONPATH=src python benchmarks/stress_db3_driver.py [--runs 2000] [--busy 6] [--driver PATH]

Why: BehaviorTree.CPP 4.8.2's ``SqliteLogger`` destructor can lose its writer's wakeup and wait
for ever (docs/conform.md, "Recording a run in C++"); the driver no longer runs that destructor.
A hang needs the writer preempted in a window of a few instructions, so it shows only under
load and only in a fraction of runs: this script records the same tree ``--runs`` times
(one mutant of examples/robot_bt.xml, the tree of the CI failure, 30 scripted ticks, seeds 0
and 1 alternating) beside ``--busy`` busy-looping processes, and counts the recordings past
``--timeout`` seconds. ``--driver`` runs another build of the driver (e.g. a copy of the one
before the fix) on the same arguments.

Costs: one driver process per run (about 0.1-1 s each under load).
"""

from __future__ import annotations

import argparse
import multiprocessing
import subprocess
import tempfile
import time
from pathlib import Path

from fsmbt import api
from fsmbt.runtime.cpp import require_driver
from fsmbt.runtime.cpp.scripted import leaf_types
from fsmbt.verify.mutations import mutants

ROBOT = Path(__file__).resolve().parents[1] / "examples" / "robot_bt.xml"


def _busy() -> None:
    """Spin until terminated: one core's worth of load."""
    while True:
        pass


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=2000)
    parser.add_argument("--busy", type=int, default=6, help="busy-looping processes beside")
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds before a hang")
    parser.add_argument("--driver", type=Path, default=None)
    args = parser.parse_args()
    driver = args.driver or require_driver()
    model = api.load(ROBOT).model
    mutant = list(mutants(model, seed=5, per_operator=1))[1]
    conditions, actions = leaf_types(mutant.model)
    loops = [multiprocessing.Process(target=_busy, daemon=True) for _ in range(args.busy)]
    for loop in loops:
        loop.start()
    hangs, start = 0, time.perf_counter()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            tree = api.write(mutant.model, Path(tmp) / "m1.xml")
            db3 = Path(tmp) / "run.db3"
            for run in range(1, args.runs + 1):
                db3.unlink(missing_ok=True)
                command = [str(driver), str(tree), "--scripted", str(run % 2), "--ticks", "30"]
                command += ["--conditions", ",".join(conditions)]
                command += ["--actions", ",".join(actions), "--db3", str(db3)]
                try:
                    subprocess.run(command, capture_output=True, timeout=args.timeout, check=True)
                except subprocess.TimeoutExpired:
                    hangs += 1
                if run % 100 == 0:
                    print(f"{run} runs, {hangs} hangs", flush=True)
    finally:
        for loop in loops:
            loop.terminate()
    elapsed = time.perf_counter() - start
    print(
        f"driver {driver}: {hangs} hangs in {args.runs} runs beside {args.busy} busy loops "
        f"(timeout {args.timeout:g} s), {elapsed:.0f} s"
    )


if __name__ == "__main__":
    main()
