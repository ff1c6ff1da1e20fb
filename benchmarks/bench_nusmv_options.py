"""NuSMV options and the implied-reachability run, measured (issue 27, item 2). Prints a table.

    .venv/bin/python benchmarks/bench_nusmv_options.py [--sizes 10,20,30,50] [--timeout 60]

Pairs: ``bench_checker.chain_fsm(n, n)`` against its renamed copy (equivalent), and the same
with one transition retargeted (``mutant``: not equivalent), FSM ~ FSM by macro steps. Columns
(NuSMV wall seconds, ``-`` past ``--timeout``):

- ``before``: every spec in one run, ``-mono`` and fsmbt's variable order (``check(...,
  implied_reachability=False)``);
- ``-coi``, ``-dynamic``: the same model with NuSMV's cone of influence / dynamic reordering;
- ``after``: ``check``'s default: the four specs without reachability first, reachability
  reported as implied when they hold (docs/nusmv.md), the whole model again when one fails.

``agree`` compares ``after``'s five verdicts with the native checker's.
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import chain_fsm, renamed  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.verify import nusmv, verify  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError, run_nusmv  # noqa: E402


def _timed(run, *args, **kwargs) -> str:  # type: ignore[no-untyped-def]
    started = time.perf_counter()
    try:
        run(*args, **kwargs)
    except NuSMVLimitError:
        return "-"
    return f"{time.perf_counter() - started:.2f}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20,30,50")
    parser.add_argument("--timeout", type=float, default=60.0)
    args = parser.parse_args(argv)
    limits.use(limits.current().with_changes(nusmv_max_seconds=args.timeout))
    header = (
        f"{'pair':<10} {'states':>6} {'before':>8} {'-coi':>8} {'-dynamic':>8} {'after':>8}  agree"
    )
    print(header)
    print("-" * len(header))
    for n in [int(x) for x in args.sizes.split(",")]:
        source = chain_fsm(n, n)
        same = renamed(chain_fsm(n, n))
        mutant = copy.deepcopy(source)
        mutant.transitions[0].target = mutant.transitions[-1].target
        for label, result in (("copy", same), ("mutant", mutant)):
            text, names, context = nusmv.build_model(source, result)
            order = context[-1]
            cells = [
                _timed(nusmv.check, source, result, implied_reachability=False),
                _timed(run_nusmv, text, len(names), order=order, options=["-coi"]),
                _timed(run_nusmv, text, len(names), order=order, options=["-dynamic"]),
            ]
            agree = "-"
            started = time.perf_counter()
            try:
                after = nusmv.check(source, result)
                cells.append(f"{time.perf_counter() - started:.2f}")
                native = verify(source, result)
                agree = "yes" if after.verdicts() == native.verdicts() else "NO"
            except NuSMVLimitError:
                cells.append("-")
            print(
                f"{label:<10} {n:>6} " + " ".join(f"{c:>8}" for c in cells) + f"  {agree}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
