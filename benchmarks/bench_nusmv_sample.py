"""The issue's sample in one run: NuSMV against the native checker (issue 27, "Done when").

    PYTHONPATH=src .venv/bin/python benchmarks/bench_nusmv_sample.py [--quick] [--seed 27]
        [--budget 60] [--small 1000] [--small-sizes 5,10,20,50,100] [--large 6]
        [--large-size 1000] [--dispatch 2] [--dispatch-size 1000] [--tree-size 1000]
        [--pernode-families memory,mixed,reactive-plain,decorated] [--tree-mutants 3]
        [--macro-families plain,reactive] [--structured 4] [--corpus]

One seeded sample of every kind of pair the issue names, each decided by both engines; the pairs
come from the existing benchmarks' generators (nothing generated twice):

- ``fsm``: ``--small`` FSM ~ FSM pairs of ``--small-sizes`` states (cycled), copies and
  one-transition mutants alternating (``bench_nusmv_agreement.pair``);
- ``fsm-large``: ``--large`` such pairs of ``--large-size`` states (copies and mutants);
- ``dispatch``: ``--dispatch`` FSM ~ dispatch-tree pairs of ``--dispatch-size`` states
  (``bench_nusmv_agreement.dispatch_pair``);
- ``pernode``: one tree of about ``--tree-size`` nodes per family of ``--pernode-families``
  (``bench_reactive.family_tree``, seed 1; ``decorated`` is the random family with decorators
  and Parallel) converted per node, and ``--tree-mutants`` one-transition mutants of its per-node
  sub-machine (``tests/support/pernode_mutants.mutate``), the native compositional walk's
  local checks decided by NuSMV (``verify.nusmv.pernode.check_plan``). A pair agrees when NuSMV
  gives every unit the native walk's verdict (and proves the unmutated tree); a mutant the
  native walk does not decompose has no local checks for NuSMV: *not asked* (not agreement);
- ``macro``: one tree of about ``--tree-size`` nodes per family of ``--macro-families``
  against its flattened HFSM (copy) and a one-transition mutant of it
  (``bench_nusmv_macro.mutant_of``), NuSMV's tree written by macro steps (``encode_macro``);
- ``structured``: ``--structured`` outcome-driven machines against their structured trees
  (``bench_nusmv_agreement.structured_pairs``; ``--corpus``: and the corpus files).

**The budget is per pair**: NuSMV's whole ``check`` of a pair (every run it makes) is done in a
forked child process (its own process group), killed at ``--budget`` wall seconds; a pair past
it, or with one NuSMV run past the same cap, is counted as *gave up* - never as agreement.
The native checker runs first in this process (its verdict is what NuSMV is compared with).
A pair NuSMV refuses by name (``UnsupportedError``, a per-node unit past its limit) is
*refused*. Each pair's row is printed (flushed) as soon as it is decided: kind, label, copy or
mutant, the native verdict, the outcome, NuSMV's CPU seconds (its children's user + system,
from ``RUSAGE_CHILDREN`` of the forked child) and the pair's wall seconds. Then one table per
kind and the total: pairs, agree, disagree, gave up, refused, not asked, the largest NuSMV CPU
seconds and pair wall seconds, and the pairs decided within the budget. The load average is
printed at the start and the end. Exit 1 on any disagreement or error.

``--quick``: a smoke sample (tens of small pairs, 100-node trees) for the test suite.
"""

from __future__ import annotations

import argparse
import os
import pickle
import random
import resource
import select
import signal
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from bench_nusmv_agreement import dispatch_pair, pair, structured_pairs  # noqa: E402
from bench_nusmv_macro import load, mutant_of  # noqa: E402
from bench_reactive import family_tree, leaves_for, node_count  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.model.errors import FsmbtError, UnsupportedError  # noqa: E402
from fsmbt.model.flatten import flatten  # noqa: E402
from fsmbt.verify import nusmv, verify  # noqa: E402
from fsmbt.verify.compositional import CheckPlan, NotDecomposable, decompose  # noqa: E402
from fsmbt.verify.nusmv.pernode import check_plan  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError  # noqa: E402
from support.pernode_mutants import mutate  # noqa: E402

KINDS = ("fsm", "fsm-large", "dispatch", "pernode", "macro", "structured")
#: Outcomes of one pair.
AGREE, DISAGREE, GAVE_UP, REFUSED, NOT_ASKED, ERROR = (
    "agree", "DISAGREE", "gave up", "refused", "not asked", "ERROR",
)  # fmt: skip
#: The per-node bench's caps for a mutant's native check (``bench_nusmv_pernode``).
NATIVE_BUDGET, MUTANT_STATES = 5.0, 1_000


@dataclass
class Pair:
    """One pair to decide: ``nusmv`` is run in the forked child and returns the outcome
    (``AGREE``/``DISAGREE``/``REFUSED``) and a short detail, comparing with ``native``."""

    kind: str
    label: str
    which: str  # copy or mutant
    native: str  # the native verdict, in words
    nusmv: Callable[[], tuple[str, str]]


@dataclass
class Row:
    pair: Pair
    outcome: str
    detail: str
    cpu: float  # NuSMV CPU seconds (the forked child's children)
    wall: float  # the pair's NuSMV check, wall seconds


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def within(budget: float, run: Callable[[], tuple[str, str]]) -> tuple[str, str, float, float]:
    """``run()`` in a forked child (its own process group, so NuSMV goes with it), killed at
    ``budget`` wall seconds: (outcome, detail, NuSMV CPU seconds, wall seconds). A NuSMV run
    past its own cap (``NuSMVLimitError``) or the budget is ``GAVE_UP``; ``UnsupportedError``
    is ``REFUSED``; any other exception is ``ERROR`` (named)."""
    read, write = os.pipe()
    begun = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        os.close(read)
        os.setpgid(0, 0)
        before = child_cpu()
        try:
            outcome, detail = run()
        except NuSMVLimitError as exc:
            outcome, detail = GAVE_UP, f"one run past the cap ({exc.resource})"
        except UnsupportedError as exc:
            outcome, detail = REFUSED, str(exc)[:80]
        except BaseException as exc:  # noqa: BLE001 - reported, never hidden
            outcome, detail = ERROR, f"{type(exc).__name__}: {exc}"[:200]
        with os.fdopen(write, "wb") as out:
            pickle.dump((outcome, detail, child_cpu() - before), out)
        os._exit(0)
    os.close(write)
    deadline = begun + budget
    data = b""
    with os.fdopen(read, "rb") as pipe:
        fd = pipe.fileno()
        while True:
            left = deadline - time.perf_counter()
            ready, _w, _x = select.select([fd], [], [], max(left, 0))
            if not ready:
                break
            chunk = os.read(fd, 65536)
            if not chunk:
                break
            data += chunk
    wall = time.perf_counter() - begun
    if not data or wall > budget:
        try:
            os.killpg(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        os.waitpid(pid, 0)
        return GAVE_UP, f"past the {budget:g} s budget", float("nan"), wall
    os.waitpid(pid, 0)
    outcome, detail, cpu = pickle.loads(data)
    return outcome, detail, cpu, wall


def verdicts_agree(native: dict[str, bool], found: dict[str, bool]) -> tuple[str, str]:
    if native == found:
        return AGREE, ""
    return DISAGREE, f"native {native} NuSMV {found}"


def fsm_pairs(args: argparse.Namespace, rng: random.Random) -> Iterator[Pair]:
    """The small and large FSM ~ FSM pairs, then the FSM ~ dispatch pairs."""
    sizes = [int(x) for x in args.small_sizes.split(",")]
    jobs = [("fsm", i, sizes[i % len(sizes)]) for i in range(args.small)]
    jobs += [("fsm-large", i, args.large_size) for i in range(args.large)]
    jobs += [("dispatch", i, args.dispatch_size) for i in range(args.dispatch)]
    for kind, index, size in jobs:
        if kind == "dispatch":
            source, result, which = dispatch_pair(index, size, rng)
        else:
            source, result, which = pair(index, size, rng)
        native = verify(source, result)

        def run(s=source, r=result, n=native.verdicts()):  # type: ignore[no-untyped-def]
            return verdicts_agree(n, nusmv.check(s, r).verdicts())

        yield Pair(kind, f"{size} states", which, _words(native.equivalent), run)


def _words(equivalent: bool) -> str:
    return "equivalent" if equivalent else "not equivalent"


def pernode_pairs(args: argparse.Namespace) -> Iterator[Pair]:
    """Per family one tree and ``--tree-mutants`` mutants, decided node by node."""
    for family in filter(None, args.pernode_families.split(",")):
        doc = family_tree(family, leaves_for(args.tree_size), 1)
        label = f"{family} {node_count(doc)} nodes"
        model = bt_to_hfsm(doc, pernode=True).model
        rng = random.Random(args.seed * 1000 + args.tree_size)
        candidates = [("copy", model)]
        for _ in range(args.tree_mutants):
            mutant = mutate(model, rng)
            if mutant is not None:
                candidates.append(("mutant", mutant))
        for which, result in candidates:
            plan = CheckPlan()
            capped = MUTANT_STATES if which == "mutant" else limits.current().conversion_max_states
            with limits.changed(conversion_max_states=capped):
                try:  # a mutant outside the per-node check falls back to its region whole
                    decompose(
                        doc, result, plan=plan, max_states=MUTANT_STATES, max_seconds=NATIVE_BUDGET
                    )
                except (NotDecomposable, FsmbtError):
                    pass
            units = [u for _region, region_units in plan.units for u in region_units]
            held = all(u.held for u in units)
            native = f"{_units(len(units))}, {'all hold' if held else 'one fails'}"
            if not units:
                yield Pair("pernode", label, which, "not decomposed", _not_asked)
                continue

            def run(p=plan, u=units, proof=which == "copy"):  # type: ignore[no-untyped-def]
                return _units_agree(p, u, proof)

            yield Pair("pernode", label, which, native, run)


def _not_asked() -> tuple[str, str]:
    return NOT_ASKED, "the native walk did not decompose it: no local check for NuSMV"


def _units_agree(plan: CheckPlan, units: list[Any], proof: bool) -> tuple[str, str]:
    """NuSMV's verdict on each of ``plan``'s units against the native walk's (and, for the
    unmutated tree, NuSMV's proof of the whole plan)."""
    found = check_plan(plan.units, plan.wholes)
    if found.local.refused or found.limits:
        return REFUSED, "; ".join(found.limits)[:80]
    if len(found.local.verdicts) != len(units):
        return DISAGREE, f"{len(found.local.verdicts)} verdicts for {len(units)} units"
    wrong = [v.node for u, v in zip(units, found.local.verdicts) if u.held != v.holds]
    if wrong:
        return DISAGREE, f"units {wrong[:3]}"
    if proof and not found.holds:
        return DISAGREE, "the unmutated tree not proven"
    return AGREE, f"{_units(len(units))}, NuSMV runs: {found.local.runs}"


def _units(count: int) -> str:
    return f"{count} unit{'' if count == 1 else 's'}"


def macro_pairs(args: argparse.Namespace, rng: random.Random) -> Iterator[Pair]:
    """Per family a tree against its flattened HFSM and a one-transition mutant of it."""
    for family in filter(None, args.macro_families.split(",")):
        doc = family_tree(family, leaves_for(args.tree_size), 1)
        label = f"{family} {node_count(doc)} nodes"
        flat = flatten(bt_to_hfsm(doc).model)
        for which, result in (("copy", flat), ("mutant", mutant_of(flat, rng))):
            native = verify(doc, result)

            def run(d=doc, r=result, n=native.verdicts()):  # type: ignore[no-untyped-def]
                report = nusmv.check(d, r, tree_encoding=nusmv.MACRO)
                return verdicts_agree(n, report.verdicts())

            yield Pair("macro", label, which, _words(native.equivalent), run)


def structured(args: argparse.Namespace, rng: random.Random) -> Iterator[Pair]:
    """Outcome-driven machines against their structured trees (and the corpus)."""
    options = argparse.Namespace(pairs=args.structured, corpus=args.corpus)
    for label, source, tree, which in structured_pairs(options, [5, 10, 20], rng):
        try:
            native = verify(source, tree, outcome_driven=True)
        except FsmbtError:
            continue  # a retargeted machine the outcome view refuses: not a pair

        def run(s=source, t=tree, n=native.verdicts()):  # type: ignore[no-untyped-def]
            return verdicts_agree(n, nusmv.check(s, t, outcome_driven=True).verdicts())

        yield Pair("structured", f"{label} states", which, _words(native.equivalent), run)


def sample(args: argparse.Namespace) -> Iterator[Pair]:
    rng = random.Random(args.seed)
    yield from fsm_pairs(args, rng)
    yield from pernode_pairs(args)
    yield from macro_pairs(args, rng)
    yield from structured(args, rng)


#: The table's columns: (title, width); the first left-aligned.
COLUMNS = (
    ("kind", 10), ("pairs", 6), ("agree", 6), ("disagree", 8), ("gave up", 7), ("refused", 7),
    ("not asked", 9), ("error", 5), ("max CPU s", 9), ("max wall s", 10),
    ("decided <= budget", 17),
)  # fmt: skip


def table(rows: list[Row], budget: float) -> int:
    """One line per kind and the total; the number of disagreements and errors."""
    header = " ".join(
        title.ljust(width) if i == 0 else title.rjust(width)
        for i, (title, width) in enumerate(COLUMNS)
    )
    print(f"{header}\n{'-' * len(header)}")
    groups = [(k, [r for r in rows if r.pair.kind == k]) for k in KINDS] + [("total", rows)]
    for kind, group in groups:
        if not group:
            continue
        c = Counter(r.outcome for r in group)
        cpus = [r.cpu for r in group if r.cpu == r.cpu]  # NaN: killed, no figure
        decided = sum(1 for r in group if r.outcome in (AGREE, DISAGREE) and r.wall <= budget)
        print(
            f"{kind:<10} {len(group):>6} {c[AGREE]:>6} {c[DISAGREE]:>8} {c[GAVE_UP]:>7} "
            f"{c[REFUSED]:>7} {c[NOT_ASKED]:>9} {c[ERROR]:>5} {max(cpus, default=0):>9.2f} "
            f"{max(r.wall for r in group):>10.2f} {decided:>17}"
        )
    bad = Counter(r.outcome for r in rows)
    return bad[DISAGREE] + bad[ERROR]


def arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a smoke sample")
    parser.add_argument("--seed", type=int, default=27)
    parser.add_argument("--budget", type=float, default=60.0, help="wall s per pair")
    parser.add_argument("--small", type=int, default=1000)
    parser.add_argument("--small-sizes", default="5,10,20,50,100")
    parser.add_argument("--large", type=int, default=6)
    parser.add_argument("--large-size", type=int, default=1000)
    parser.add_argument("--dispatch", type=int, default=2)
    parser.add_argument("--dispatch-size", type=int, default=1000)
    parser.add_argument("--tree-size", type=int, default=1000)
    parser.add_argument("--pernode-families", default="memory,mixed,reactive-plain,decorated")
    parser.add_argument("--tree-mutants", type=int, default=3)
    parser.add_argument("--macro-families", default="plain,reactive")
    parser.add_argument("--structured", type=int, default=4)
    parser.add_argument("--corpus", action="store_true")
    args = parser.parse_args(argv)
    if args.quick:  # tens of pairs of every kind, small: a smoke test
        args.small, args.small_sizes, args.large, args.large_size = 20, "5,10,20", 2, 50
        args.dispatch, args.dispatch_size, args.tree_size, args.tree_mutants = 2, 20, 60, 2
        args.structured = 2
    return args


def main(argv: list[str] | None = None) -> int:
    args = arguments(argv)
    # one NuSMV run may not pass the pair's budget either
    limits.use(limits.current().with_changes(nusmv_max_seconds=args.budget))
    started = time.perf_counter()
    print(f"# at start: {load()} (1, 5, 15 min) on {os.cpu_count()} cores", flush=True)
    print("# kind | label | pair | native | outcome | NuSMV CPU s | pair wall s | detail")
    rows: list[Row] = []
    for item in sample(args):
        outcome, detail, cpu, wall = within(args.budget, item.nusmv)
        row = Row(item, outcome, detail, cpu, wall)
        rows.append(row)
        print(
            f"{item.kind} | {item.label} | {item.which} | {item.native} | {outcome} | "
            f"{cpu:.2f} | {wall:.2f} | {detail}",
            flush=True,
        )
    bad = table(rows, args.budget)
    print(
        f"# {len(rows)} pairs in {time.perf_counter() - started:.0f} s wall; "
        f"budget {args.budget:g} s wall per pair; at end: {load()}",
        flush=True,
    )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
