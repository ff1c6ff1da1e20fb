"""NuSMV against the native checker on many generated FSM ~ FSM pairs (issue 27, item 2).

    .venv/bin/python benchmarks/bench_nusmv_agreement.py [--pairs 1000]
        [--sizes 5,10,20,50,100,300,1000] [--timeout 60] [--seed 27]
        [--style fsm|dispatch|bsd|chds|structured] [--corpus]

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
disagree, gave up, NuSMV CPU seconds total and largest, and the largest wall seconds of one
pair's ``check``, all its NuSMV runs, on the loaded machine) and the totals; exit 1 on any
disagreement. CPU seconds come from ``RUSAGE_CHILDREN`` (independent of the machine's load).

``--style structured`` (the outcome pairing, docs/nusmv.md "The outcome pairing (structured
trees)"): a seeded outcome-driven machine (``fsmbt.generate.outcome_machines.random_outcome_fsm``,
20% containers) against its structured tree (even pairs) or the same tree against the machine
with one transition retargeted inside its region (odd pairs); ``--corpus`` adds every SMACH,
FlexBE and YASMIN file of the corpus (``$FSMBT_CORPUS``, else ``../shared/corpus``) that the
structured style converts, against its tree and with one transition retargeted. A pair NuSMV
refuses by name (a Concurrence read in rounds, a livelock) is counted as *refused* (the native
verdict stands, as with ``--engine both``). Sizes default to 5,10,20,50.

``--style bsd`` / ``--style chds`` (FSM ~ state-variable tree, ``fsmbt.verify.nusmv.encode_sv``):
the source FSM against its conversion with that baseline (equivalent) or, every other pair,
against the conversion of a one-transition mutant of it; ``--style fsm`` (default) is the FSM ~
FSM benchmark above. The sizes then default to 5,10,20,30, and copy and mutant alternate
per round of sizes as well, so every size gets both.
"""

from __future__ import annotations

import argparse
import copy
import os
import random
import resource
import sys
import time
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import renamed  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert import convert  # noqa: E402
from fsmbt.generate.generator import random_fsm  # noqa: E402
from fsmbt.model.bt import BTDocument  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402
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


def retargeted(fsm: FSM, rng: random.Random) -> FSM:
    """``fsm`` with one transition (of any region) retargeted to another state of its region."""
    mutant = copy.deepcopy(fsm)
    regions = [m for _p, m, _s in mutant.walk() if m.transitions] or [mutant]
    regions += [r for _p, _m, s in mutant.walk() for r in s.regions if r.transitions]
    region = rng.choice([r for r in regions if r.transitions])
    transition = region.transitions[rng.randrange(len(region.transitions))]
    others = [name for name in region.states if name != transition.target]
    transition.target = rng.choice(others)
    return mutant


def structured_pairs(
    args: argparse.Namespace, sizes: list[int], rng: random.Random
) -> Iterator[tuple[str, FSM, BTDocument, str]]:
    """(size label, machine, structured tree, kind) for ``--style structured``."""
    from fsmbt.convert.structured import fsm_to_structured
    from fsmbt.generate.outcome_machines import random_outcome_fsm

    for index in range(args.pairs):
        size = sizes[index % len(sizes)]
        source = random_outcome_fsm(rng.randrange(10**9), states=size, containers=0.2)
        tree = fsm_to_structured(source).model
        if (index + index // len(sizes)) % 2 == 0:
            yield str(size), source, tree, "copy"
        else:
            yield str(size), retargeted(source, rng), tree, "mutant"
    if not args.corpus:
        return
    from fsmbt import api
    from fsmbt.model.errors import FsmbtError

    root = Path(os.environ.get("FSMBT_CORPUS", REPO / ".." / "shared" / "corpus")) / "fsm"
    files = sorted(
        [*root.glob("smach_tutorials/*.py"), *root.glob("smach_tests/*.py"),
         *root.glob("flexbe_turtlesim_demo/*_sm.py"), *root.glob("yasmin/*.xml")]
    )  # fmt: skip
    for path in files:
        try:
            fsm = api.load(path).model
            assert isinstance(fsm, FSM)
            tree = fsm_to_structured(fsm).model
        except (FsmbtError, AssertionError):
            continue  # not an outcome-driven machine the structured style converts
        yield "corpus", fsm, tree, "copy"
        yield "corpus", retargeted(fsm, rng), tree, "mutant"


def structured_main(args: argparse.Namespace, sizes: list[int], rng: random.Random) -> int:
    """``--style structured``: one line per size (and the corpus): pairs, agree, disagree,
    gave up, refused, equivalent / failing by the native verdict, NuSMV CPU seconds."""
    from fsmbt.model.errors import UnsupportedError

    labels = [str(n) for n in sizes] + (["corpus"] if args.corpus else [])
    counts: dict[str, Counter[str]] = {n: Counter() for n in labels}
    cpu: dict[str, list[float]] = {n: [] for n in labels}
    started = time.perf_counter()
    for label, source, tree, kind in structured_pairs(args, sizes, rng):
        try:
            native = verify(source, tree, outcome_driven=True)
        except FsmbtError:
            counts[label]["not read"] += 1  # a retargeted machine the outcome view refuses
            continue
        except KeyError as exc:  # a native checker's bug, counted and shown, not hidden
            counts[label]["native crashed"] += 1
            print(f"NATIVE CRASHED ({label}, {kind}): KeyError {exc}", flush=True)
            continue
        before = child_cpu()
        try:
            report = nusmv.check(source, tree, outcome_driven=True)
        except NuSMVLimitError:
            counts[label]["gave up"] += 1
            nodes = sum(1 for _ in tree.nodes())
            print(f"GAVE UP ({label}, {kind}): tree '{tree.main.id}', {nodes} nodes", flush=True)
            continue
        except UnsupportedError as exc:
            counts[label]["refused"] += 1
            counts[label][f"refused: {str(exc).split(' cover ')[-1][:40]}"] += 1
            continue
        finally:
            cpu[label].append(child_cpu() - before)
        same = report.verdicts() == native.verdicts()
        counts[label]["agree" if same else "disagree"] += 1
        counts[label]["equivalent" if native.equivalent else "failing"] += 1
        if not same:
            print(f"DISAGREE ({label}, {kind}): native {native.verdicts()} NuSMV "
                  f"{report.verdicts()}", flush=True)  # fmt: skip
    header = (
        f"{'states':>6} {'pairs':>6} {'agree':>6} {'disagree':>8} {'gave up':>7} "
        f"{'refused':>7} {'equiv.':>6} {'failing':>7} {'CPU s':>8} {'max s':>7}"
    )
    print(header)
    print("-" * len(header))
    total: Counter[str] = Counter()
    for n in labels:
        c = counts[n]
        total.update(c)
        pairs = c["agree"] + c["disagree"] + c["gave up"] + c["refused"]
        print(
            f"{n:>6} {pairs:>6} {c['agree']:>6} {c['disagree']:>8} {c['gave up']:>7} "
            f"{c['refused']:>7} {c['equivalent']:>6} {c['failing']:>7} {sum(cpu[n]):>8.1f} "
            f"{max(cpu[n], default=0):>7.2f}"
        )
    reasons = {k: v for k, v in total.items() if k.startswith("refused: ")}
    print(
        f"total (structured): {total['agree']} agree, {total['disagree']} disagree, "
        f"{total['gave up']} gave up (NuSMV past {args.timeout:g} s), {total['refused']} refused "
        f"{reasons}, {total['not read']} mutants not outcome-driven (skipped), "
        f"{total['native crashed']} on which the native checker crashed (skipped); "
        f"{time.perf_counter() - started:.0f} s wall"
    )
    return 1 if total["disagree"] else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=1000)
    parser.add_argument("--sizes", default=None)
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--seed", type=int, default=27)
    parser.add_argument(
        "--style", choices=("fsm", "dispatch", "bsd", "chds", "structured"), default="fsm"
    )
    parser.add_argument("--corpus", action="store_true", help="structured: add the corpus")
    args = parser.parse_args(argv)
    if args.sizes is None:
        defaults = {"fsm": "5,10,20,50,100,300,1000", "structured": "5,10,20,50"}
        args.sizes = defaults.get(args.style, "5,10,20,30")
    limits.use(limits.current().with_changes(nusmv_max_seconds=args.timeout))
    sizes = [int(s) for s in args.sizes.split(",")]
    rng = random.Random(args.seed)
    if args.style == "structured":
        return structured_main(args, sizes, rng)
    counts: dict[int, Counter[str]] = {n: Counter() for n in sizes}
    cpu: dict[int, list[float]] = {n: [] for n in sizes}
    wall: dict[int, list[float]] = {n: [] for n in sizes}  # every NuSMV run of a pair, wall s
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
        before, begun = child_cpu(), time.perf_counter()
        try:
            report = nusmv.check(source, result)
        except NuSMVLimitError:
            counts[size]["gave up"] += 1
            continue
        finally:
            cpu[size].append(child_cpu() - before)
            wall[size].append(time.perf_counter() - begun)
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
        f"{'equiv.':>6} {'failing':>7} {'CPU s':>8} {'max s':>7} {'wall s':>7}"
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
            f"{equivalent:>6} {failing:>7} {sum(cpu[n]):>8.1f} {max(cpu[n], default=0):>7.2f} "
            f"{max(wall[n], default=0):>7.2f}"
        )
    print(
        f"total ({args.style}): {args.pairs} pairs, {total['agree']} agree, {total['disagree']} disagree, "
        f"{total['gave up']} gave up (NuSMV past {args.timeout:g} s; native verdict only); "
        f"{time.perf_counter() - started:.0f} s wall"
    )
    return 1 if total["disagree"] else 0


if __name__ == "__main__":
    sys.exit(main())
