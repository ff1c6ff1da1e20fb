"""NuSMV against the native checker on many generated FSM ~ FSM pairs (issue 27, item 2).

    .venv/bin/python benchmarks/bench_nusmv_agreement.py [--pairs 1000]
        [--sizes 5,10,20,50,100,300,1000] [--timeout 60] [--seed 27]
        [--style fsm|dispatch|bsd|chds]

Pairs: ``--pairs`` random FSMs (``fsmbt.generate.generator.random_fsm``, sizes cycling through
``--sizes``), each against its renamed copy (``bench_checker.renamed``: equivalent) or, every
other pair, a mutant of it (one transition retargeted: usually not equivalent). For each pair
both engines decide the five properties; the pair *agrees* when every verdict is the same.
``--style dispatch`` (docs/nusmv.md, "The dispatch form"): the result is the dispatch tree
(``convert(..., style="dispatch")``) of the random FSM, against the FSM itself (equivalent) or,
every other pair, against a mutant of the FSM (one transition retargeted); every fourth pair
puts the tree first (dispatch source, FSM result), so both orders are compared.
A NuSMV run past ``--timeout`` wall seconds is counted as *gave up* (the native verdict stands,
as with ``--engine both``), never as agreement. Prints one line per size (pairs, agree,
disagree, gave up, NuSMV CPU seconds total and largest) and the totals; exit 1 on any
disagreement. CPU seconds come from ``RUSAGE_CHILDREN`` (independent of the machine's load).

``--style bsd`` / ``--style chds`` (FSM ~ state-variable tree, ``fsmbt.verify.nusmv.encode_sv``):
the source FSM against its conversion with that baseline (equivalent) or, every other pair,
against the conversion of a one-transition mutant of it; ``--style fsm`` (default) is the FSM ~
FSM benchmark above. The sizes then default to 5,10,20,30, and copy and mutant alternate
per round of sizes as well, so every size gets both.
"""

from __future__ import annotations

import argparse
import copy
import random
import resource
import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import renamed  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert import convert  # noqa: E402
from fsmbt.generate.generator import random_fsm  # noqa: E402
from fsmbt.model.bt import BTDocument  # noqa: E402
from fsmbt.model.fsm import FSM  # noqa: E402
from fsmbt.verify import nusmv, verify  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError  # noqa: E402


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def pair(
    index: int, size: int, rng: random.Random, style: str = "fsm"
) -> tuple[FSM, FSM | BTDocument, str]:
    """The ``index``-th pair: a copy for even indices, a one-transition mutant for odd; with a
    baseline ``style`` the result is that baseline's conversion of the copy or mutant."""
    source = random_fsm(rng.randrange(10**9), n_states=size)
    if index % 2 == 0 or not source.transitions:
        return source, converted(renamed(source), style), "copy"
    mutant = copy.deepcopy(source)
    transition = mutant.transitions[rng.randrange(len(mutant.transitions))]
    others = [name for name in mutant.states if name != transition.target]
    transition.target = rng.choice(others)
    return source, converted(mutant, style), "mutant"


def converted(fsm: FSM, style: str) -> FSM | BTDocument:
    """``fsm`` itself (``fsm``) or its BSD/CHDS state-variable tree."""
    if style == "fsm":
        return fsm
    from fsmbt.convert.baselines.bsd import fsm_to_bsd
    from fsmbt.convert.baselines.chds import fsm_to_chds

    model = {"bsd": fsm_to_bsd, "chds": fsm_to_chds}[style](fsm).model
    assert isinstance(model, BTDocument)
    return model


def dispatch_pair(
    index: int, size: int, rng: random.Random
) -> tuple[FSM | BTDocument, FSM | BTDocument, str]:
    """The ``index``-th ``--style dispatch`` pair: the FSM's dispatch tree against the FSM
    (even indices) or a one-transition mutant of it (odd); the tree first every fourth."""
    source, other, kind = pair(index, size, rng)
    tree = convert(source, style="dispatch").model
    assert isinstance(tree, BTDocument)
    fsm = source if kind == "copy" else other
    assert isinstance(fsm, FSM)
    if index % 4 in (2, 3):
        return tree, fsm, kind
    return fsm, tree, kind


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=1000)
    parser.add_argument("--sizes", default=None)
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--seed", type=int, default=27)
    parser.add_argument("--style", choices=("fsm", "dispatch", "bsd", "chds"), default="fsm")
    args = parser.parse_args(argv)
    if args.sizes is None:
        args.sizes = "5,10,20,50,100,300,1000" if args.style == "fsm" else "5,10,20,30"
    limits.use(limits.current().with_changes(nusmv_max_seconds=args.timeout))
    sizes = [int(s) for s in args.sizes.split(",")]
    rng = random.Random(args.seed)
    counts: dict[int, Counter[str]] = {n: Counter() for n in sizes}
    cpu: dict[int, list[float]] = {n: [] for n in sizes}
    started = time.perf_counter()
    for index in range(args.pairs):
        size = sizes[index % len(sizes)]
        if args.style == "dispatch":  # its measured sequence (docs/nusmv.md, "The dispatch form")
            source, result, kind = dispatch_pair(index, size, rng)
        else:
            # FSM ~ FSM keeps its measured sequence; the baselines alternate copy/mutant per
            # round too, so an even number of sizes still mixes both kinds at every size
            slot = index if args.style == "fsm" else index + index // len(sizes)
            source, result, kind = pair(slot, size, rng, args.style)
        native = verify(source, result)
        before = child_cpu()
        try:
            report = nusmv.check(source, result)
        except NuSMVLimitError:
            counts[size]["gave up"] += 1
            continue
        finally:
            cpu[size].append(child_cpu() - before)
        same = report.verdicts() == native.verdicts()
        counts[size]["agree" if same else "disagree"] += 1
        counts[size][f"{kind} {'equivalent' if native.equivalent else 'failing'}"] += 1
        if not same:
            print(
                f"DISAGREE pair {index} ({size} states, {kind}): native {native.verdicts()} "
                f"NuSMV {report.verdicts()}",
                flush=True,
            )
    header = (
        f"{'states':>6} {'pairs':>6} {'agree':>6} {'disagree':>8} {'gave up':>7} "
        f"{'equiv.':>6} {'failing':>7} {'CPU s':>8} {'max s':>7}"
    )
    print(header)
    print("-" * len(header))
    total: Counter[str] = Counter()
    for n in sizes:
        c = counts[n]
        total.update(c)
        pairs = c["agree"] + c["disagree"] + c["gave up"]
        equivalent = c["copy equivalent"] + c["mutant equivalent"]
        failing = c["copy failing"] + c["mutant failing"]
        print(
            f"{n:>6} {pairs:>6} {c['agree']:>6} {c['disagree']:>8} {c['gave up']:>7} "
            f"{equivalent:>6} {failing:>7} {sum(cpu[n]):>8.1f} {max(cpu[n], default=0):>7.2f}"
        )
    print(
        f"total ({args.style}): {args.pairs} pairs, {total['agree']} agree, {total['disagree']} disagree, "
        f"{total['gave up']} gave up (NuSMV past {args.timeout:g} s; native verdict only); "
        f"{time.perf_counter() - started:.0f} s wall"
    )
    return 1 if total["disagree"] else 0


if __name__ == "__main__":
    sys.exit(main())
