"""Conversion time of the rules engine (prints tables; not a test).

1. FSM -> BT, the call the CLI makes (``fsmbt.api.convert_model``, rules engine, without the
   checker) on random FSMs (``fsmbt.generate.random_fsm``: n states, n/2 extra edges tried,
   every event distinct) and on chains, 30 ... 100 000 states: CPU time per state, and the ratio
   of the per-state cost at 100 000 states to the one at 30 states against the target of issue
   19 (within 2x). Runs follow each other in a loop (a small machine's figure is the one with
   warm caches, the favourable case for the 30-state base of the ratio); each run's result is
   released after the clock is read, so its deallocation is not counted.
2. Where the FSM -> BT time goes at 1 000 / 10 000 / 100 000 states: structure analysis and tree
   building (collector off, as in the conversion), the young-generation collector passes that
   the promotion of ``convert/perf.py`` saves, the kernel's share (fresh memory pages), memory
   (tracemalloc peak, objects tracked by the collector in the result, per state) and,
   separately, the native checker's and the BehaviorTree.CPP XML writer's cost.
3. BT -> HFSM for random BTs of 100 ... 100 000 nodes and a 100 000-node deep BT (alternating
   Sequence/Fallback, so compression cannot shorten it).

CPU (process) time is the figure to read on a shared machine (wall time includes waiting for
a core). Minimum over repeated runs.

Run: .venv/bin/python benchmarks/bench_convert.py [--quick] [--fsm-only] [--rounds N]
     (--quick: up to 10 000 elements; --fsm-only: part 1 only, e.g. to compare two checkouts;
     --rounds N: part 1 N times over, sizes interleaved, minimum per size - on a machine whose
     load changes, so that the two ends of the ratio are measured across the same time)
"""

from __future__ import annotations

import gc
import resource
import sys
import time
import tracemalloc
from collections.abc import Callable

from fsmbt.api import convert_model, verify_models
from fsmbt.convert import perf
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.lebt import _build
from fsmbt.convert.structure import analyse
from fsmbt.formats import dumps
from fsmbt.generate import random_bt, random_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM

TARGET_RATIO = 2.0


def best_of(func: Callable[[], object], repeats: int) -> tuple[float, float]:
    """Minimum wall-clock and minimum CPU time of ``func()`` over ``repeats`` runs; each
    run's result is released after the clocks are read (its deallocation is not counted)."""
    best_wall = best_cpu = float("inf")
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        result = func()
        cpu = time.process_time() - cpu
        wall = time.perf_counter() - wall
        del result
        best_cpu, best_wall = min(best_cpu, cpu), min(best_wall, wall)
    return best_wall, best_cpu


def repeats_for(count: int) -> int:
    return 300 if count <= 100 else 60 if count <= 1000 else 8 if count <= 10_000 else 3


def fsm_for(kind: str, n: int) -> FSM:
    if kind == "random":
        return random_fsm(n, n, "basic", extra_edges=n // 2)
    return random_fsm(1, n, "basic", shape="chain", extra_edges=0)


def part_fsm_to_bt(sizes: list[int], rounds: int = 1) -> None:
    """Part 1. ``rounds`` > 1 measures every size once per round, the sizes one after the
    other in each round, and keeps each size's minimum over all rounds: on a shared machine
    whose load changes while the script runs, the 30-state and the 100 000-state figures are
    then both taken across the same stretch of time, not ten seconds apart."""
    print("FSM -> BT: fsmbt.api.convert_model (rules engine, no checker)")
    if rounds > 1:
        print(f"(minimum over {rounds} rounds, sizes interleaved)")
    print(f"{'machine':<8} {'states':>7} {'wall':>11} {'cpu':>11} {'cpu/state':>10} {'x 30':>6}")
    for kind in ("random", "chain"):
        best: dict[int, tuple[float, float]] = {}
        for _ in range(rounds):
            for n in sizes:
                fsm = fsm_for(kind, n)
                wall, cpu = best_of(lambda fsm=fsm: convert_model(fsm), repeats_for(n))
                old_wall, old_cpu = best.get(n, (wall, cpu))
                best[n] = (min(wall, old_wall), min(cpu, old_cpu))
        per_state = {n: cpu / n for n, (_wall, cpu) in best.items()}
        for n in sizes:
            wall, cpu = best[n]
            print(
                f"{kind:<8} {n:>7} {wall * 1e3:>9.2f}ms {cpu * 1e3:>9.2f}ms "
                f"{cpu / n * 1e6:>8.2f}us {per_state[n] / per_state[sizes[0]]:>6.2f}"
            )
        largest = sizes[-1]
        ratio = per_state[largest] / per_state[sizes[0]]
        verdict = "met" if ratio <= TARGET_RATIO else "NOT met"
        print(
            f"{kind}: per-state cost {largest}/{sizes[0]} states = {ratio:.2f} "
            f"(target <= {TARGET_RATIO:.0f}: {verdict})"
        )


def _young_passes(fsm: FSM) -> float:
    """CPU seconds of the two young-generation passes over a fresh result when it is left in
    the young generation (what ``perf.promote_young_objects`` saves)."""
    gc.collect()
    gc.disable()
    try:
        result = convert_model(fsm)  # gc_paused sees the collector off: no promotion
    finally:
        started = time.process_time()
        gc.enable()
        gc.collect(0)
        gc.collect(1)
        elapsed = time.process_time() - started
    del result
    return elapsed


def _memory(fsm: FSM) -> tuple[float, float]:
    """Tracemalloc peak bytes of one conversion and the collector-tracked objects its result
    holds (both per state)."""
    gc.collect()
    before = len(gc.get_objects())
    result = convert_model(fsm)
    tracked = len(gc.get_objects()) - before
    del result
    gc.collect()
    tracemalloc.start()
    result = convert_model(fsm)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    del result
    n = len(fsm.states)
    return peak / n, tracked / n


def _phase_row(fsm: FSM) -> str:
    """One row of part 2 for ``fsm``."""
    n = len(fsm.states)
    repeats = repeats_for(n)
    gc.disable()
    try:
        _, t_analyse = best_of(lambda: analyse(fsm), repeats)
        structure = analyse(fsm)
        _, t_build = best_of(lambda: _build(fsm, structure), repeats)
    finally:
        gc.enable()
    _, t_convert = best_of(lambda: convert_model(fsm), repeats)
    perf.PROMOTE_ON_EXIT = False
    try:
        _, t_plain = best_of(lambda: convert_model(fsm), repeats)
    finally:
        perf.PROMOTE_ON_EXIT = True
    t_young = min(_young_passes(fsm) for _ in range(min(repeats, 3)))
    result = convert_model(fsm).model
    started = time.process_time()
    report = verify_models(fsm, result, "native")
    t_check = time.process_time() - started
    if not report.equivalent:
        raise SystemExit(f"the checker refutes the LEBT of a {n}-state machine")
    _, t_write = best_of(lambda: dumps(result, "btcpp"), max(1, repeats // 3))
    peak, tracked = _memory(fsm)
    system, faults = _kernel_share(fsm, repeats)
    return (
        f"{n:>7} {t_analyse / n * 1e6:>8.2f} {t_build / n * 1e6:>8.2f} "
        f"{t_convert / n * 1e6:>8.2f} {system / n * 1e6:>6.2f} {faults / n:>7.3f} "
        f"{t_plain / n * 1e6:>9.2f} {t_young / n * 1e6:>7.2f} "
        f"{t_check / n * 1e6:>9.1f} {t_write / n * 1e6:>7.2f} {peak:>7.0f}B {tracked:>8.1f}"
    )


def _kernel_share(fsm: FSM, repeats: int) -> tuple[float, float]:
    """Kernel (system) CPU seconds and minor page faults of one conversion, averaged over
    ``repeats`` runs: the part of its CPU time spent by the kernel handing out fresh memory
    pages."""
    system = faults = 0.0
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_SELF)
        result = convert_model(fsm)
        after = resource.getrusage(resource.RUSAGE_SELF)
        del result
        system += after.ru_stime - before.ru_stime
        faults += after.ru_minflt - before.ru_minflt
    return system / repeats, faults / repeats


def part_phases(sizes: list[int]) -> None:
    print()
    print("FSM -> BT, random machines: us per state (CPU); memory per state")
    print(
        f"{'states':>7} {'analyse':>8} {'build':>8} {'convert':>8} {'sys':>6} {'faults':>7} "
        f"{'no-promo':>9} {'young':>7} {'checker':>9} {'write':>7} {'peak':>8} {'tracked':>8}"
    )
    for n in sizes:
        print(_phase_row(fsm_for("random", n)))
    print(
        "analyse/build: collector off; convert: the whole call, of which sys: kernel time "
        "(faults: minor page faults per state,\nfresh memory pages); no-promo: the whole call "
        "without the promotion on exit; young: the young-generation passes\nover a fresh "
        "result the promotion saves; checker: native verify_models, write: btcpp XML text "
        "(neither is part of convert);\npeak: tracemalloc peak of one conversion; tracked: "
        "collector-tracked objects in the result"
    )


def deep_bt(depth: int) -> BTDocument:
    """Sequence(a, Fallback(b, Sequence(c, ...))) with ``depth`` control levels."""
    root = BTNode(type="Sequence", kind=NodeKind.CONTROL)
    node = root
    for level in range(depth):
        node.children.append(BTNode(type=f"L{level}", kind=NodeKind.ACTION))
        if level == depth - 1:
            break
        child = BTNode(
            type="Fallback" if node.type == "Sequence" else "Sequence", kind=NodeKind.CONTROL
        )
        node.children.append(child)
        node = child
    return BTDocument.single(root)


def part_bt_to_hfsm(sizes: list[int], deep_nodes: int) -> None:
    print()
    print("BT -> HFSM: fsmbt.convert.bt_to_hfsm.bt_to_hfsm")
    print(f"{'tree':<8} {'nodes':>7} {'wall':>11} {'cpu':>11} {'cpu/node':>10}")
    rows = []
    for n in sizes:
        doc = random_bt(n, 40, 10, "basic", max_nodes=n)
        rows.append(("random", doc))
    rows.append(("deep", deep_bt(deep_nodes // 2)))
    for kind, doc in rows:
        nodes = sum(1 for _ in doc.main.root.walk())
        wall, cpu = best_of(lambda doc=doc: bt_to_hfsm(doc), repeats_for(nodes))
        print(
            f"{kind:<8} {nodes:>7} {wall * 1e3:>9.2f}ms {cpu * 1e3:>9.2f}ms "
            f"{cpu / nodes * 1e6:>8.2f}us"
        )


def main() -> None:
    quick = "--quick" in sys.argv
    largest = 10_000 if quick else 100_000
    rounds = int(sys.argv[sys.argv.index("--rounds") + 1]) if "--rounds" in sys.argv else 1
    part_fsm_to_bt([30, 100, 1_000, 10_000] + ([] if quick else [100_000]), rounds)
    if "--fsm-only" in sys.argv:
        return
    part_phases([1_000, 10_000] + ([] if quick else [100_000]))
    part_bt_to_hfsm([100, 1_000, 10_000] + ([] if quick else [100_000]), largest)


if __name__ == "__main__":
    main()
