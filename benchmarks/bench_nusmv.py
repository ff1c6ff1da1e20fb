"""NuSMV vs the native checker on the same pairs: seconds each, the ratio, growth with size.

Pairs: random FSMs of n states converted to LEBTs (macro steps), and random BTs of n leaves
converted to FSMs (leaf execution). Each size runs ``--repeat`` pairs; the table prints the
median seconds. Run: ``.venv/bin/python benchmarks/bench_nusmv.py [--sizes 2,3,4,6] [--repeat 3]``.
NuSMV runs are capped by ``--timeout`` seconds (shown as ">T").
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.generate.generator import random_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.verify import verify
from fsmbt.verify.nusmv import check
from fsmbt.verify.nusmv.runner import NuSMVError


def random_bt(rng: random.Random, leaves: int) -> BTDocument:
    names = iter(range(10_000))

    def build(budget: int) -> BTNode:
        if budget <= 1:
            i = next(names)
            return BTNode("L", NodeKind.CONDITION if rng.random() < 0.4 else NodeKind.ACTION,
                          name=f"l{i}")
        parts = min(budget, rng.randint(2, 3))
        sizes = [budget // parts] * parts
        sizes[0] += budget - sum(sizes)
        kind = rng.choice(("Sequence", "Fallback", "ReactiveSequence", "ReactiveFallback"))
        return BTNode(kind, NodeKind.CONTROL, children=[build(s) for s in sizes])

    return BTDocument.single(build(leaves))


def timed(fn) -> tuple[float, object]:
    started = time.perf_counter()
    value = fn()
    return time.perf_counter() - started, value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", default="2,3,4,6,8")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--timeout", type=float, default=120.0)
    args = parser.parse_args()
    sizes = [int(x) for x in args.sizes.split(",")]
    rng = random.Random(2024)
    print(f"{'pair':<12}{'size':>5}{'native s':>11}{'NuSMV s':>10}{'ratio':>9}{'agree':>7}")
    for family in ("fsm->lebt", "bt->fsm"):
        for n in sizes:
            native_t, smv_t, agree, timeouts = [], [], 0, 0
            for _ in range(args.repeat):
                if family == "fsm->lebt":
                    source = random_fsm(rng.randrange(10**9), n_states=n)
                    result = fsm_to_lebt(source).model
                else:
                    source = random_bt(rng, n)
                    result = bt_to_hfsm(source).model
                t_native, native = timed(lambda: verify(source, result))
                try:
                    t_smv, smv = timed(lambda: check(source, result, timeout=args.timeout))
                except NuSMVError:
                    timeouts += 1
                    continue
                native_t.append(t_native)
                smv_t.append(t_smv)
                agree += native.verdicts() == smv.verdicts()
            if not smv_t:
                print(f"{family:<12}{n:>5}{'-':>11}{'>' + str(int(args.timeout)):>10}"
                      f"{'-':>9}{'-':>7}")
                continue
            a, b = statistics.median(native_t), statistics.median(smv_t)
            note = f" ({timeouts} timed out)" if timeouts else ""
            print(f"{family:<12}{n:>5}{a:>11.4f}{b:>10.2f}{b / a:>9.0f}"
                  f"{f'{agree}/{len(smv_t)}':>7}{note}", flush=True)


if __name__ == "__main__":
    main()
