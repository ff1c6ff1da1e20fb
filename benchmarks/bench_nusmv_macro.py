"""NuSMV on large trees by macro steps (``verify/nusmv/encode_macro.py``; issue 27 item 2).

    .venv/bin/python benchmarks/bench_nusmv_macro.py [--families plain,reactive,memory,mixed]
        [--sizes 100,300,1000] [--cap 60] [--micro-up-to 0] [--both]

For each family of ``bench_reactive.family_tree`` (seed 1, about ``size`` nodes) the tree is
converted by ``bt_to_hfsm`` (not timed) and checked against its HFSM (``copy``) and against a
one-transition mutant of the flattened HFSM (``mutant``, seeded). Each row prints the native
checker's verdict and seconds, NuSMV's seconds (the ``nusmv_seconds`` of ``nusmv.check``: the
NuSMV runs alone) and the whole ``nusmv.check`` wall seconds with the macro-step encoding,
whether its five verdicts equal the native checker's, and - up to ``--micro-up-to`` nodes - the
micro-step encoding's seconds; ``--both`` also times ``verify(doc, hfsm, engine="both")`` on
each copy (the engines side by side, as ``fsmbt verify --engine both`` runs them). A NuSMV run past ``--cap`` seconds prints ``gave up``; a pair
whose HFSM cannot be flattened (its data model expanded past the state limit) prints why.
The machine's load (``os.getloadavg``) is printed before and after: the figures are wall
seconds on a shared machine.
"""

from __future__ import annotations

import argparse
import copy
import os
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_reactive import family_tree, leaves_for, node_count  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.model.errors import InputError  # noqa: E402
from fsmbt.model.flatten import flatten  # noqa: E402
from fsmbt.model.fsm import FSM  # noqa: E402
from fsmbt.verify import nusmv, verify  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError  # noqa: E402


def load() -> str:
    return "load {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def mutant_of(flat: FSM, rng: random.Random) -> FSM:
    mutant = copy.deepcopy(flat)
    transition = mutant.transitions[rng.randrange(len(mutant.transitions))]
    transition.target = rng.choice([s for s in mutant.states if s != transition.target])
    return mutant


def row(doc, result: FSM, encoding: str) -> tuple[str, str]:  # type: ignore[no-untyped-def]
    """(NuSMV seconds and wall seconds, or why it stopped; the verdicts' text)."""
    started = time.perf_counter()
    try:
        report = nusmv.check(doc, result, tree_encoding=encoding)
    except NuSMVLimitError as error:
        return f"gave up ({time.perf_counter() - started:.1f} s: {error.resource})", ""
    wall = time.perf_counter() - started
    return f"{report.stats['nusmv_seconds']:.2f} s ({wall:.2f} s wall)", str(report.verdicts())


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--families", default="plain,reactive,memory,mixed")
    parser.add_argument("--sizes", default="100,300,1000")
    parser.add_argument("--cap", type=float, default=60.0)
    parser.add_argument("--micro-up-to", type=int, default=0)
    parser.add_argument("--both", action="store_true", help="also time verify(engine='both')")
    args = parser.parse_args(argv)
    limits.use(limits.current().with_changes(nusmv_max_seconds=args.cap))
    print(f"# before: {load()} on {os.cpu_count()} cores; NuSMV cap {args.cap:.0f} s per run")
    print("family | nodes | leaves | pair | native | NuSMV macro-step | agree | micro-step")
    rng = random.Random(27)
    largest: dict[str, int] = {}
    for family in args.families.split(","):
        for size in (int(x) for x in args.sizes.split(",")):
            doc = family_tree(family, leaves_for(size), 1)
            nodes = node_count(doc)
            leaves = sum(1 for n in _leaves(doc))
            hfsm = bt_to_hfsm(doc).model
            try:
                flat = flatten(hfsm)
            except InputError as error:
                print(f"{family} | {nodes} | {leaves} | - | HFSM not flattened: {error}")
                continue
            for pair, result in (("copy", flat), ("mutant", mutant_of(flat, rng))):
                started = time.perf_counter()
                native = verify(doc, result)
                native_s = time.perf_counter() - started
                verdict = "equivalent" if native.equivalent else "not equivalent"
                macro, verdicts = row(doc, result, nusmv.MACRO)
                agree = (
                    "-"
                    if not verdicts
                    else ("agree" if verdicts == str(native.verdicts()) else "DISAGREE")
                )
                micro = "-"
                if nodes <= args.micro_up_to:
                    micro = row(doc, result, nusmv.MICRO)[0]
                print(
                    f"{family} | {nodes} | {leaves} | {pair} | {verdict} {native_s:.2f} s | "
                    f"{macro} | {agree} | {micro}",
                    flush=True,
                )
                if args.both and pair == "copy":
                    started = time.perf_counter()
                    both = verify(doc, hfsm, engine="both")
                    print(
                        f"#   verify(doc, hfsm, engine='both'): equivalent={both.equivalent}, "
                        f"{time.perf_counter() - started:.2f} s, NuSMV tree encoding: "
                        f"{both.stats.get('nusmv', {}).get('nusmv_tree_encoding', '-')}",
                        flush=True,
                    )
                if agree == "agree":
                    largest[f"{family} {pair}"] = max(largest.get(f"{family} {pair}", 0), nodes)
    for key, nodes in largest.items():
        print(f"# largest decided within the cap: {key}: {nodes} nodes")
    print(f"# after: {load()}")
    return 0


def _leaves(doc):  # type: ignore[no-untyped-def]
    stack = [doc.main.root]
    while stack:
        node = stack.pop()
        if not node.children:
            yield node
        stack.extend(node.children)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
