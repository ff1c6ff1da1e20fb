"""NuSMV node by node on the bench_reactive families (issue 27 item 2; docs/nusmv.md, "Trees node
by node"). Prints one table row per tree, then the agreement count.

    .venv/bin/python benchmarks/bench_nusmv_pernode.py [--sizes 100,1000] [--trees 2] [--first-seed 1]
        [--mutants 10] [--families memory,mixed,reactive-plain,decorated] [--batch 2]
        [--cap 600] [--sweep 1,2,4,8]

Per family and size, ``--trees`` random trees (``bench_reactive.family_tree``, seeds from ``--first-seed``) are
converted by ``bt_to_hfsm(pernode=True)`` (regions written per node) and checked:

- ``native s``: the native compositional check (``compositional.decompose``; no lift), which
  also decides which local checks exist (the plan); a region it checks whole (a mutant the
  per-node check refuses) gets ``NATIVE_BUDGET`` seconds and ``MUTANT_STATES`` states;
- ``units``: distinct local checks NuSMV decided, ``runs``: NuSMV runs (``--batch`` units each,
  ``-coi``), ``NuSMV s``: NuSMV's wall seconds summed, ``enc s``: encoding seconds, and
  ``whole``: the parts checked whole by the whole encoders (the skeleton);
- ``agree``: whether NuSMV's verdict on every unit is the native walk's;
- then ``--mutants`` one-transition mutants of the tree's per-node sub-machine
  (``tests/support/pernode_mutants.mutate``), each decided the same way; NuSMV's verdicts are
  shared across the tree and its mutants by SMV text (``check_units``' cache: a unit whose
  module text was already decided is not run again; its count is ``cached``), so a mutant
  costs the units it changes. ``mut`` columns: pairs, pairs where every unit agreed, pairs
  NuSMV refused (a unit past ``encode_local.FRAGMENT_LIMIT``), pairs outside the per-node
  check (the native compositional check did not decompose the mutant), NuSMV seconds summed.

Each tree is capped at ``--cap`` seconds (SIGALRM; the row says ``stopped``). A disagreement
prints the unit and both verdicts. ``--sweep`` times the unmutated tree's units at several
batch sizes (one file per batch, with ``-coi``; and without it on the first ``4 x batch`` units
for batches up to 8, each run capped at 30 s) and prints the seconds per distinct unit.
"""

from __future__ import annotations

import argparse
import os
import random
import signal
import sys
import time
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from bench_reactive import family_tree, leaves_for, node_count  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402
from fsmbt.verify.compositional import CheckPlan, NotDecomposable, decompose  # noqa: E402
from fsmbt.verify.nusmv.pernode import PlanResult, Verdicts, check_plan, check_units  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError  # noqa: E402
from support.pernode_mutants import mutate  # noqa: E402

#: Seconds the native check of a region checked whole may take (a mutant outside the per-node
#: check), and the data expansion's cap for a mutant (``conversion_max_states``): the bench only
#: counts pairs decided node by node, and a 1 000-node region expanded to 20 000 states
#: takes ~20 s before it stops.
NATIVE_BUDGET = 5.0
MUTANT_STATES = 1_000


class _Stop(Exception):
    pass


def _alarm(_signum, _frame):  # type: ignore[no-untyped-def]
    raise _Stop


def _decide(doc, model, batch: int, cache: Verdicts) -> tuple[CheckPlan, PlanResult | None, float]:  # type: ignore[no-untyped-def]
    """The native plan, NuSMV's verdicts on it (``None``: nothing per node) and the native
    seconds."""
    plan = CheckPlan()
    started = time.perf_counter()
    try:  # a mutant outside the per-node check falls back to its region whole: capped
        decompose(doc, model, plan=plan, max_states=MUTANT_STATES, max_seconds=NATIVE_BUDGET)
    except (NotDecomposable, FsmbtError):  # outside the scope, or a part past a limit
        pass
    native = time.perf_counter() - started
    if not plan.units:
        return plan, None, native
    return plan, check_plan(plan.units, plan.wholes, batch=batch, cache=cache), native


def _agrees(plan: CheckPlan, found: PlanResult) -> bool:
    units = [u for _region, region_units in plan.units for u in region_units]
    verdicts = found.local.verdicts
    if len(units) != len(verdicts):
        return False
    same = True
    for unit, verdict in zip(units, verdicts):
        if unit.held != verdict.holds:
            same = False
            print(f"  DISAGREE {verdict.node}: native {unit.held}, NuSMV {verdict.holds}")
    return same


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default="100,1000")
    parser.add_argument("--trees", type=int, default=2)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--mutants", type=int, default=10)
    parser.add_argument("--families", default="memory,mixed,reactive-plain,decorated")
    parser.add_argument("--batch", type=int, default=2)
    parser.add_argument("--cap", type=int, default=600)
    parser.add_argument("--sweep", default="")
    args = parser.parse_args()
    signal.signal(signal.SIGALRM, _alarm)
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} (1, 5 min); batch {args.batch}")
    header = (
        "family", "nodes", "native s", "units", "runs", "NuSMV s", "enc s", "whole", "agree",
        "mut", "mut agree", "mut refused", "mut outside", "mut NuSMV s", "cached",
    )  # fmt: skip
    print(" | ".join(header))
    total: Counter[str] = Counter()
    for size in [int(x) for x in args.sizes.split(",")]:
        for family in args.families.split(","):
            for seed in range(args.first_seed, args.first_seed + args.trees):
                signal.alarm(args.cap)
                try:
                    row = _tree(family, size, seed, args, total)
                except _Stop:
                    row = [family, str(size), f"stopped after {args.cap} s"]
                finally:
                    signal.alarm(0)
                print(" | ".join(row), flush=True)
    print(
        f"pairs decided node by node by both engines: {total['pairs']}; NuSMV agreed on every "
        f"unit: {total['agree']} (of them with 1 000 nodes or more: {total['agree_large']}); "
        f"disagreed: {total['pairs'] - total['agree'] - total['refused']}; NuSMV refused a "
        f"unit: {total['refused']}; outside the per-node check: {total['outside']}"
    )
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} (1, 5 min)")
    return 0 if total["pairs"] == total["agree"] + total["refused"] else 1


def _tree(family: str, size: int, seed: int, args: argparse.Namespace, total: Counter[str]):  # type: ignore[no-untyped-def]
    doc = family_tree(family, leaves_for(size), seed)
    nodes = node_count(doc)
    model = bt_to_hfsm(doc, pernode=True).model
    cache: Verdicts = {}
    plan, found, native = _decide(doc, model, args.batch, cache)
    if found is None:
        return [family, str(nodes), f"{native:.2f}", "not per node"]
    agree = _agrees(plan, found) and not found.limits and found.holds
    _count(total, found, agree, nodes)
    row = [
        family,
        str(nodes),
        f"{native:.2f}",
        str(len(found.local.verdicts)),
        str(found.local.runs),
        f"{found.local.nusmv_seconds:.2f}",
        f"{found.local.encode_seconds:.2f}",
        ",".join(f"{name}: {'eq' if eq else 'NOT eq'}" for name, eq in found.wholes) or "-",
        "yes" if agree else "NO",
    ]
    if args.sweep:
        _sweep(plan, [int(x) for x in args.sweep.split(",")])
    rng = random.Random(seed * 1000 + size)
    mut: Counter[str] = Counter()
    seconds = 0.0
    cached = 0
    for _ in range(args.mutants):
        mutant = mutate(model, rng)
        if mutant is None:
            break
        with limits.changed(conversion_max_states=MUTANT_STATES):
            mplan, mfound, _native = _decide(doc, mutant, args.batch, cache)
        mut["pairs"] += 1
        if mfound is None:
            mut["outside"] += 1
            total["outside"] += 1
            continue
        seconds += mfound.local.nusmv_seconds
        cached += mfound.local.cached
        same = _agrees(mplan, mfound) and not mfound.limits
        if mfound.limits:
            mut["refused"] += 1
        elif same:
            mut["agree"] += 1
        _count(total, mfound, same, nodes)
    row += [
        str(mut["pairs"]),
        str(mut["agree"]),
        str(mut["refused"]),
        str(mut["outside"]),
        f"{seconds:.2f}",
        str(cached),
    ]
    return row


def _count(total: Counter[str], found: PlanResult, agree: bool, nodes: int) -> None:
    total["pairs"] += 1
    if found.limits:
        total["refused"] += 1
    elif agree:
        total["agree"] += 1
        total["agree_large"] += nodes >= 1000


def _sweep(plan: CheckPlan, sizes: list[int]) -> None:
    """The unmutated tree's units at each batch size, with ``-coi`` and, up to 8 units per
    file, without it (capped by the runner's time limit)."""
    units = [u for _region, region_units in plan.units for u in region_units]
    for batch in sizes:
        for coi in (True, False) if batch <= 8 else (True,):
            try:
                chosen = units if coi else units[: max(batch * 4, 8)]
                found = check_units(chosen, batch=batch, coi=coi, timeout=None if coi else 30)
            except NuSMVLimitError as exc:
                print(f"  sweep: batch {batch}, coi {coi}: {exc}", flush=True)
                continue
            run = len(found.verdicts) - found.cached  # distinct module texts, each run once
            per_unit = found.nusmv_seconds / max(run, 1)
            print(
                f"  sweep: batch {batch}, {'-coi' if coi else 'no -coi'}: {len(found.verdicts)} "
                f"units ({run} distinct texts), {found.runs} runs, {found.nusmv_seconds:.2f} "
                f"NuSMV s, {per_unit * 1000:.1f} ms per distinct unit "
                f"(load {os.getloadavg()[0]:.2f})",
                flush=True,
            )


if __name__ == "__main__":
    sys.exit(main())
