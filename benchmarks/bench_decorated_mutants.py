"""How many random one-transition mutants of large ``decorated`` trees ``verify`` decides
(issue 27; docs/verification.md §7, the tenth round). Prints one line per verdict kind.

    .venv/bin/python benchmarks/bench_decorated_mutants.py [--sizes 1000] [--trees 2]
        [--mutants 20] [--limit 20] [--seed 1]

The family is ``bench_reactive.py``'s ``decorated`` (mixed controls, a fifth of the leaves
under a decorator, a tenth of the controls Parallel), converted per node; each mutant is
``tests/support/pernode_mutants.mutate`` (one transition of the first per-node sub-machine
retargeted, its guard dropped, or one assignment dropped or changed), drawn from
``random.Random(seed)``. Each is given to ``verify`` with ``--limit`` seconds (SIGALRM):
the verdict, its method, and the rules past the plain check that decided it (``_kind``: dead
code set aside - nodes the tree never ticks skipped per node, or a region never ticked -,
transitions no local check follows, stages that never go on; random runs for a refutation). ``undecided`` counts the
mutants past the limit or stopped by a state limit. Why: the single mutant row of
``bench_reactive.py --pernode`` showed one pair; this counts a sample, so a change to what
the checker decides shows as numbers, before and after.
"""

from __future__ import annotations

import argparse
import random
import signal
import sys
import time
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))

from bench_reactive import family_tree, leaves_for  # noqa: E402

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402
from fsmbt.verify import verify  # noqa: E402
from support.pernode_mutants import mutate  # noqa: E402


class _Timeout(Exception):
    pass


def _alarm(_signum, _frame):  # type: ignore[no-untyped-def]
    raise _Timeout


def _kind(report) -> str:  # type: ignore[no-untyped-def]
    """The verdict, its method and the rules past the plain check that decided it: for a
    proof, dead code set aside, transitions no local check follows, stages that never go on;
    for a refutation, random runs."""
    if not report.equivalent:
        walked = any("random runs" in a for a in report.abstractions)
        return f"NOT EQUIVALENT ({report.method}{', random runs' if walked else ''})"
    rules = []
    if report.stats.get("regions_never_ticked") or report.stats.get("per_node_unticked"):
        rules.append("dead code set aside")
    if report.stats.get("per_node_unfired"):
        rules.append("unfired")
    if report.stats.get("never_go_on"):
        rules.append("stages")
    return f"EQUIVALENT ({', '.join([report.method, *rules])})"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1000")
    parser.add_argument("--trees", type=int, default=2)
    parser.add_argument("--mutants", type=int, default=20)
    parser.add_argument("--limit", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    signal.signal(signal.SIGALRM, _alarm)
    rng = random.Random(args.seed)
    tally: Counter[str] = Counter()
    seconds: dict[str, list[float]] = {}
    for size in (int(s) for s in args.sizes.split(",")):
        for tree in range(args.trees):
            doc = family_tree("decorated", leaves_for(size), size + tree)
            model = bt_to_hfsm(doc).model
            for _ in range(args.mutants):
                mutant = mutate(model, rng)
                if mutant is None:
                    continue
                started = time.perf_counter()
                signal.alarm(args.limit)
                try:
                    kind = _kind(verify(doc, mutant))
                except _Timeout:
                    kind = "undecided (past the limit)"
                except FsmbtError as exc:
                    kind = f"undecided ({type(exc).__name__})"
                finally:
                    signal.alarm(0)
                tally[kind] += 1
                seconds.setdefault(kind, []).append(time.perf_counter() - started)
    total = sum(tally.values())
    print(f"{'verdict':<80} {'mutants':>7} {'max s':>7}")
    print("-" * 96)
    for kind, count in tally.most_common():
        print(f"{kind:<80} {count:>7} {max(seconds[kind]):>7.2f}")
    undecided = sum(c for k, c in tally.items() if k.startswith("undecided"))
    print(f"total: {total} mutants, {total - undecided} decided, {undecided} undecided")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
