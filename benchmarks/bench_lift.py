"""Lifted counterexamples (``verify/lift.py``; issue 27, "the counterexample on a mutant stays
the shortest"): how often a one-transition mutant is refuted by a lifted counterexample, and
whether it is as short as the whole product's shortest. Prints two tables.

    .venv/bin/python benchmarks/bench_lift.py [--small 60] [--whole 150] [--large 6]
        [--bound 4000] [--large-bound 200000] [--limit 60]

``small``: the sample ``tests/verify/test_ver_lift.py`` uses (``seeded_trees(N, seed=4)``, two
mutants each of the first per-node sub-machine, ``random.Random(5)``): per whole-product
verdict (``None``: past ``--bound`` states) the method of the compositional verdict
(``per node, lifted``, ``compositional, lifted``, or ``none``: the whole product decides),
and for each lifted one whether its length equals the whole product's shortest counterexample
(native breadth-first search); the last line counts the lifted counterexamples the lift's own
bounded search (``verify/shortest.py``) proved shortest. ``whole``: the same over results written
whole (not per node: every region is checked whole),
``support.whole_mutants.seeded_whole_mutants(N, seed=8)`` - the compositional test's random trees,
two one-transition mutants each of a random machine, regions included. ``large``: six mutants
each of ``bench_reactive``
``family_tree("mixed", 150, seed)`` for seeds 300.. (about 400 nodes, ``random.Random(27)``):
the same, the whole product (the result run lazily, as the lift replays it) bounded by
``--large-bound`` states and ``--limit`` seconds per mutant (``unknown`` past either).
"""

from __future__ import annotations

import argparse
import random
import sys
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "tests"))
from bench_reactive import family_tree  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.model.bt import BTDocument  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402
from fsmbt.model.fsm import FSM  # noqa: E402
from fsmbt.verify.compositional import (  # noqa: E402
    NotDecomposable,
    compositional_report,
    decompose,
    per_node_lower_bound,
)
from fsmbt.verify.lazy_fsm import Unsupported  # noqa: E402
from fsmbt.verify.lift import lift_machines  # noqa: E402
from fsmbt.verify.native import check  # noqa: E402
from fsmbt.verify.pairing import machines_for  # noqa: E402
from fsmbt.verify.report import LIFTED, Report  # noqa: E402
from support.pernode_mutants import mutate, seeded_mutants  # noqa: E402
from support.whole_mutants import seeded_whole_mutants  # noqa: E402


def shortest(
    doc: BTDocument, model: FSM, bound: int, seconds: float, lazy: bool = False
) -> int | None:
    """The whole product's shortest counterexample (inputs), -1 when equivalent, ``None`` past
    ``bound`` states or ``seconds``. ``lazy``: the result run by ``lazy_fsm.LazyDataMachine``
    (the lift's machines, ``lift.lift_machines``: the same steps as the expanded machine,
    without expanding the data first)."""
    try:
        with limits.changed(conversion_max_states=bound):
            if lazy:
                source, result = lift_machines(doc, model)
            else:
                source, result, _mode = machines_for(doc, model)
            report = check(source, result, max_states=bound, max_seconds=seconds)
    except (FsmbtError, Unsupported):
        return None
    if report.equivalent:
        return -1
    return min(
        len(p.counterexample) - 1
        for p in report.properties.values()
        if not p.holds and p.counterexample
    )


def lower_bound_of(doc: BTDocument, mutant: FSM, bound: int) -> int | None:
    """The lower bound on any counterexample's length (``verify/lower_bound.py``) when the
    per-node check failed and its conditions hold, else ``None`` (computed for every lifted
    verdict, whether or not the bounded search already proved it shortest)."""
    try:
        with limits.changed(conversion_max_states=bound):
            found = decompose(doc, mutant, max_states=bound)
    except (NotDecomposable, FsmbtError):
        return None
    if found.per_node_failure is None:
        return None
    lower = per_node_lower_bound(doc, mutant, *found.per_node_failure)
    return None if lower is None else lower.bound


def lifted_length(report: Report) -> int:
    return min(len(p.counterexample) - 1 for p in report.properties.values() if p.counterexample)


def tally(
    pairs: list[tuple[BTDocument, FSM]],
    bound: int,
    whole_bound: int,
    seconds: float,
    lazy: bool = False,
) -> None:
    """One table: per whole-product verdict, the compositional method and the lengths."""
    rows: Counter[tuple[str, str, str]] = Counter()
    spent = 0.0
    proven = 0  # lifted verdicts whose bounded search proved them shortest (verify/shortest.py)
    by_bound = 0  # ... whose lower bound (verify/lower_bound.py) meets their length
    bounded = 0  # lifted per-node verdicts the lower bound applies to
    above = 0  # a bound above the whole product's shortest (unsound: must stay 0)
    bound_seconds = 0.0
    for doc, mutant in pairs:
        started = time.perf_counter()
        with limits.changed(conversion_max_states=bound):
            report, _why = compositional_report(doc, mutant, max_states=bound)
        spent += time.perf_counter() - started
        best = shortest(doc, mutant, whole_bound, seconds, lazy)
        verdict = "unknown" if best is None else ("equivalent" if best == -1 else "differ")
        method = report.method if report is not None else "none"
        length = ""
        if report is not None and report.method in LIFTED:
            mine = lifted_length(report)
            proven += bool(report.stats.get("shortest"))
            started = time.perf_counter()
            lower = lower_bound_of(doc, mutant, bound)
            bound_seconds += time.perf_counter() - started
            if lower is not None:
                bounded += 1
                by_bound += lower == mine
                above += best is not None and best >= 0 and lower > best
            if best is None:
                length = "whole product undecided"
            elif best == -1:
                length = "WRONG: the whole product proves it"
            else:
                length = "= shortest" if mine == best else f"> shortest ({mine} vs {best})"
        rows[(verdict, method, length)] += 1
    print(f"{'whole product':<14} {'compositional verdict':<26} {'length':<30} {'mutants':>7}")
    print("-" * 80)
    for (verdict, method, length), count in sorted(rows.items()):
        print(f"{verdict:<14} {method:<26} {length:<30} {count:>7}")
    differ = sum(n for (v, _m, _l), n in rows.items() if v == "differ")
    lifted = sum(n for (v, m, _l), n in rows.items() if v == "differ" and m in LIFTED)
    equal = sum(n for (_v, _m, length), n in rows.items() if length == "= shortest")
    every = sum(n for (_v, m, _l), n in rows.items() if m in LIFTED)
    print(
        f"lifted {lifted} of {differ} mutants the whole product refutes; {equal} of them as "
        f"short as its shortest; compositional check + lift {spent:.1f} s in all\n"
        f"proven shortest by the lift's own bounded search: {proven} of the {every} lifted "
        "counterexamples\n"
        f"lower bound (verify/lower_bound.py) computed for {bounded} of them, equal to the "
        f"lifted length for {by_bound} (proven shortest by the bound alone), above the whole "
        f"product's shortest for {above} (must be 0); {bound_seconds:.1f} s in all\n",
        flush=True,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", type=int, default=60, help="seeded small trees")
    parser.add_argument("--whole", type=int, default=150, help="trees converted whole")
    parser.add_argument("--large", type=int, default=6, help="400-node mixed trees")
    parser.add_argument("--bound", type=int, default=4000, help="states, small pairs")
    parser.add_argument("--large-bound", type=int, default=200_000, help="states, large pairs")
    parser.add_argument("--limit", type=float, default=60.0, help="seconds per whole product")
    args = parser.parse_args(argv)
    small = [
        (doc, mutant)
        for doc, _model, mutants in seeded_mutants(args.small, seed=4, rng_seed=5)
        for mutant in mutants
    ]
    print(f"small seeded trees ({len(small)} mutants, whole product <= {args.bound} states)")
    tally(small, args.bound, args.bound, args.limit)
    whole = [
        (doc, mutant)
        for doc, _model, mutants in seeded_whole_mutants(args.whole, seed=8)
        for mutant in mutants
    ]
    print(
        f"seeded trees written whole ({len(whole)} mutants, whole product <= {args.bound} states)"
    )
    tally(whole, args.bound, args.bound, args.limit)
    rng = random.Random(27)
    large = []
    for seed in range(300, 300 + args.large):
        doc = family_tree("mixed", 150, seed)
        model = bt_to_hfsm(doc, pernode=True).model
        for _ in range(6):
            mutant = mutate(model, rng)
            assert mutant is not None
            large.append((doc, mutant))
    print(
        f"mixed trees of about 400 nodes ({len(large)} mutants, whole product on the lazy "
        f"result <= {args.large_bound} states and {args.limit:.0f} s)"
    )
    tally(large, args.bound, args.large_bound, args.limit, lazy=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
