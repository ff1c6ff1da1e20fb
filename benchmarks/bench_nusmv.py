"""NuSMV vs the native checker on the same pairs: seconds each, the ratio, growth with size.

Pairs: random FSMs of n states converted to LEBTs (macro steps), random BTs of n leaves
converted to FSMs (leaf execution), and every model in examples/ converted by the rules engine
(the paper's A-J FSM -> LEBT, the robot BT -> HFSM, ...). Each generated size runs ``--repeat``
pairs and each example ``--repeat`` times; the tables print median wall seconds. The growth line
fits ``t ~ size^b`` by least squares on log-log and reports ``2^b``, the time factor per size
doubling. Prints figures only; nothing is asserted.

Run: ``.venv/bin/python benchmarks/bench_nusmv.py [--sizes 2,4,8] [--repeat 3] [--no-examples]``.
NuSMV runs are capped by ``--timeout`` seconds (shown as ">T").
"""

from __future__ import annotations

import argparse
import math
import random
import statistics
import time
from pathlib import Path

from fsmbt import api
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.engines import converter_for
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.generate.generator import random_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError, UnsupportedError
from fsmbt.verify import verify
from fsmbt.verify.nusmv import check
from fsmbt.verify.nusmv.runner import NuSMVError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
HEADER = f"{'pair':<26}{'size':>5}{'native s':>11}{'NuSMV s':>10}{'ratio':>9}{'agree':>7}"


def random_bt(rng: random.Random, leaves: int) -> BTDocument:
    names = iter(range(10_000))

    def build(budget: int) -> BTNode:
        if budget <= 1:
            i = next(names)
            return BTNode(
                "L", NodeKind.CONDITION if rng.random() < 0.4 else NodeKind.ACTION, name=f"l{i}"
            )
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


def measure(pairs, timeout: float) -> tuple[list[float], list[float], int, int, str]:
    """Native and NuSMV seconds over ``pairs`` (``(source, result)``), agreements, timeouts,
    and the reason when NuSMV's encoding rejects the pair."""
    native_t, smv_t, agree, timeouts = [], [], 0, 0
    for source, result in pairs:
        t_native, native = timed(lambda source=source, result=result: verify(source, result))
        try:
            t_smv, smv = timed(
                lambda source=source, result=result: check(source, result, timeout=timeout)
            )
        except UnsupportedError as exc:
            return native_t, smv_t, agree, timeouts, str(exc).split("unsupported: ")[-1][:60]
        except NuSMVError:
            timeouts += 1
            continue
        native_t.append(t_native)
        smv_t.append(t_smv)
        agree += native.verdicts() == smv.verdicts()
    return native_t, smv_t, agree, timeouts, ""


def row(label: str, size: int, measured, timeout: float) -> tuple[float, float] | None:
    """Print one table line; the medians when NuSMV answered."""
    native_t, smv_t, agree, timeouts, unsupported = measured
    if unsupported:
        print(f"{label:<26}{size:>5}   NuSMV: unsupported ({unsupported})")
        return None
    if not smv_t:
        print(f"{label:<26}{size:>5}{'-':>11}{'>' + str(int(timeout)):>10}{'-':>9}{'-':>7}")
        return None
    a, b = statistics.median(native_t), statistics.median(smv_t)
    note = f" ({timeouts} timed out)" if timeouts else ""
    print(
        f"{label:<26}{size:>5}{a:>11.4f}{b:>10.2f}{b / max(a, 1e-6):>9.0f}"
        f"{f'{agree}/{len(smv_t)}':>7}{note}",
        flush=True,
    )
    return a, b


def per_doubling(points: list[tuple[int, float]]) -> float | None:
    """``2^b`` for the least-squares fit of ``log t = a + b log size``."""
    points = [(s, t) for s, t in points if s > 0 and t > 0]
    if len({s for s, _ in points}) < 2:
        return None
    xs, ys = [math.log2(s) for s, _ in points], [math.log2(t) for _, t in points]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    return 2**slope


def warm_up() -> None:
    """One untimed native check per pairing, so imports and caches do not count as the first
    size's time (they made the growth line meaningless)."""
    fsm = random_fsm(0, n_states=2)
    verify(fsm, fsm_to_lebt(fsm).model)
    doc = random_bt(random.Random(0), 2)
    verify(doc, bt_to_hfsm(doc).model)


def generated(sizes: list[int], repeat: int, timeout: float) -> None:
    warm_up()
    rng = random.Random(2024)
    print(HEADER)
    for family in ("fsm->lebt", "bt->fsm"):
        native_points, smv_points = [], []
        for n in sizes:
            pairs = []
            for _ in range(repeat):
                if family == "fsm->lebt":
                    source = random_fsm(rng.randrange(10**9), n_states=n)
                    pairs.append((source, fsm_to_lebt(source).model))
                else:
                    source = random_bt(rng, n)
                    pairs.append((source, bt_to_hfsm(source).model))
            medians = row(family, n, measure(pairs, timeout), timeout)
            if medians:
                native_points.append((n, medians[0]))
                smv_points.append((n, medians[1]))
        smv_growth, native_growth = per_doubling(smv_points), per_doubling(native_points)
        if smv_growth and native_growth:
            print(
                f"  growth {family}: NuSMV x{smv_growth:.2f}, native x{native_growth:.2f} "
                f"per size doubling (sizes {smv_points[0][0]}..{smv_points[-1][0]})"
            )


def model_size(model) -> int:
    """States of an FSM (flattened count of its state table), nodes of a BT."""
    if isinstance(model, BTDocument):
        return sum(1 for _ in model.nodes())
    return len(model.states)


def examples(repeat: int, timeout: float) -> None:
    print(f"\nexamples/ (size = source states or BT nodes)\n{HEADER}")
    for path in sorted(EXAMPLES.iterdir()):
        try:
            model = api.load(path).model
            converted = converter_for("rules", model)(model)
        except FsmbtError:
            continue  # not a model (README) or not convertible
        label = f"{path.name} {converted.direction}"
        row(
            label, model_size(model), measure([(model, converted.model)] * repeat, timeout), timeout
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", default="2,3,4,6,8")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--no-examples", action="store_true")
    args = parser.parse_args()
    generated([int(x) for x in args.sizes.split(",")], args.repeat, args.timeout)
    if not args.no_examples:
        examples(args.repeat, args.timeout)


if __name__ == "__main__":
    main()
