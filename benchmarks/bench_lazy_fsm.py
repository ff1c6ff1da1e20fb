"""The lazy result runner's cost per input (``verify/lazy_fsm.py``; docs/verification.md §3,
"The lazy result runner"): seeded random outcome walks on converted bench trees, timed per step.

    .venv/bin/python benchmarks/bench_lazy_fsm.py [--size 150] [--whole-size 40] [--walks 200]
        [--steps 1000]

For the families ``mixed`` and ``memory``: ``bench_reactive.family_tree(family, size, 300)``
converted per node and ``family_tree(family, whole_size, 300)`` converted whole (a larger one
passes the converter's state limit; a conversion refused is said so); on each,
``walks`` walks of at most ``steps`` outcomes from ``random.Random(1)``: the steps taken and
the microseconds per step (the start included).
"""

from __future__ import annotations

import argparse
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402
from fsmbt.semantics.machine import FINAL, LEAF_OUTCOMES  # noqa: E402
from fsmbt.verify.lazy_fsm import LazyDataMachine, Unsupported  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=150, help="family_tree size")
    parser.add_argument("--whole-size", type=int, default=40, help="the same, written whole")
    parser.add_argument("--walks", type=int, default=200)
    parser.add_argument("--steps", type=int, default=1000, help="most outcomes per walk")
    args = parser.parse_args(argv)
    print(f"{'tree':<28} {'conversion':<10} {'steps':>8} {'us/step':>8}")
    for family in ("mixed", "memory"):
        for pernode in (True, False):
            size = args.size if pernode else args.whole_size
            doc = family_tree(family, size, 300)
            where = f"{family} {size} (seed 300)"
            written = "per node" if pernode else "whole"
            try:
                machine = LazyDataMachine(bt_to_hfsm(doc, pernode=pernode).model)
            except (FsmbtError, Unsupported) as exc:
                print(f"{where:<28} {written:<10} not run: {type(exc).__name__}")
                continue
            rng = random.Random(1)
            steps = 0
            started = time.perf_counter()
            for _walk in range(args.walks):
                state, _out = machine.start()
                for _step in range(args.steps):
                    if machine.status(state) == FINAL:
                        break
                    state, _out = machine.step(state, rng.choice(LEAF_OUTCOMES))
                    steps += 1
            seconds = time.perf_counter() - started
            per = seconds / max(steps + args.walks, 1) * 1e6
            print(f"{where:<28} {written:<10} {steps:>8} {per:>8.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
