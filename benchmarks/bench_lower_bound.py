"""The lower bound on any counterexample's length (``verify/lower_bound.py``; issue 27, "the
counterexample on a mutant stays the shortest"): how tight and how often it applies, on the
samples ``tests/verify/test_ver_lower_bound.py`` asserts on. Prints three lines.

    PYTHONPATH=src .venv/bin/python benchmarks/bench_lower_bound.py [--trees 60]

1. ``P`` against the interpreter: on ``seeded_trees(trees, seed=31)``, every node the
   interpreter's breadth-first search (at most 9 leaves) sees ticking: how often the bound on the
   leaves before its first tick equals the fewest the search needed (never above: the test);
2. and 3. the seeded one-transition mutants of the per-node samples
   (``seeded_mutants(60, seed=4, rng_seed=5)`` and ``seeded_mutants(120, seed=41, rng_seed=42,
   per_tree=3)``): how many the bound applies to, how many the whole product decides (<= 4 000
   states), how often the bound equals its shortest counterexample, how often it is above it
   (unsound: must be 0), and the seconds the bounds took.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from fsmbt.verify.lower_bound import TickCosts  # noqa: E402
from support.lower_bound_samples import bounded_pairs, first_ticks  # noqa: E402
from support.pernode_mutants import whole_shortest  # noqa: E402
from support.pernode_trees import seeded_trees  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trees", type=int, default=60, help="trees for the interpreter check")
    args = parser.parse_args(argv)
    checked = tight = above = 0
    for doc in seeded_trees(args.trees, seed=31):
        tree, seen, _root_first = first_ticks(doc)
        costs = TickCosts(tree)
        for nid, depth in seen.items():
            before = costs.before(nid)
            checked += 1
            tight += before == depth
            above += before is None or before > depth
    print(
        f"P against the interpreter: {checked} nodes seen ticking, bound = fewest leaves for "
        f"{tight}, above it for {above} (must be 0)"
    )
    for trees, seed, rng_seed, per_tree in ((60, 4, 5, 2), (120, 41, 42, 3)):
        bounded = decided = equal = wrong = 0
        spent = 0.0
        started = time.perf_counter()
        for doc, mutant, bound in bounded_pairs(trees, seed, rng_seed, per_tree):
            spent += time.perf_counter() - started
            bounded += 1
            best = whole_shortest(doc, mutant)
            if best is not None and best >= 0:
                decided += 1
                equal += bound.bound == best
                wrong += bound.bound > best
            started = time.perf_counter()
        print(
            f"seeded_mutants({trees}, seed={seed}, rng_seed={rng_seed}, per_tree={per_tree}): "
            f"bound applies to {bounded}; the whole product refutes {decided} of them; bound = "
            f"its shortest for {equal}, above it for {wrong} (must be 0); compositional check "
            f"and bound {spent:.1f} s in all",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
