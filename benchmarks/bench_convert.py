"""Conversion time of the rules engine (prints a table; not a test).

FSM -> LEBT for random FSMs of 30 ... 100 000 states and a 100 000-state chain; BT -> HFSM for
random BTs of 100 ... 100 000 nodes and a 100 000-deep BT (alternating Sequence/Fallback, so
compression cannot shorten it). Targets: near-linear growth, a 30-state FSM under 1 ms,
100 000 nodes under 5 s, no recursion-depth error at any size.

Run: .venv/bin/python benchmarks/bench_convert.py [--quick]
"""

from __future__ import annotations

import sys
import time

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.generate import random_bt, random_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind


def best_of(func, repeats: int) -> tuple[float, float]:
    """Minimum wall-clock and minimum CPU (process) time over ``repeats`` runs: on a shared
    machine the CPU time is the steadier figure, the wall time what a user waits."""
    best_wall = best_cpu = float("inf")
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        func()
        best_cpu = min(best_cpu, time.process_time() - cpu)
        best_wall = min(best_wall, time.perf_counter() - wall)
    return best_wall, best_cpu


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


def main() -> None:
    quick = "--quick" in sys.argv
    sizes = [30, 1_000, 10_000] if quick else [30, 1_000, 10_000, 100_000]
    rows = []
    for n in sizes:
        fsm = random_fsm(n, n, "basic", extra_edges=n // 2)
        seconds = best_of(
            lambda fsm=fsm: fsm_to_lebt(fsm), 50 if n <= 1000 else 3 if n <= 10_000 else 2
        )
        rows.append(("FSM->BT random", f"{n} states", seconds))
    chain_n = 10_000 if quick else 100_000
    chain = random_fsm(1, chain_n, "basic", shape="chain", extra_edges=0)
    seconds = best_of(lambda: fsm_to_lebt(chain), 1)
    rows.append(("FSM->BT chain", f"{chain_n} states", seconds))
    for n in [100, 1_000, 10_000] if quick else [100, 1_000, 10_000, 100_000]:
        doc = random_bt(n, 40, 10, "basic", max_nodes=n)
        nodes = sum(1 for _ in doc.main.root.walk())
        seconds = best_of(
            lambda doc=doc: bt_to_hfsm(doc), 20 if n <= 1000 else 3 if n <= 10_000 else 2
        )
        rows.append(("BT->HFSM random", f"{nodes} nodes", seconds))
    deep = deep_bt(chain_n // 2)
    nodes = sum(1 for _ in deep.main.root.walk())
    seconds = best_of(lambda: bt_to_hfsm(deep), 1)
    rows.append(("BT->HFSM deep", f"{nodes} nodes", seconds))

    print(
        f"{'conversion':<18} {'size':>14} {'wall':>12} {'cpu':>12} {'cpu/element':>12} "
        f"{'growth':>7}"
    )
    previous: dict[str, tuple[int, float]] = {}
    for kind, size, (wall, cpu) in rows:
        count = int(size.split()[0])
        growth = ""
        if kind in previous:  # time ratio against the previous (about 10x smaller) size
            before_count, before_cpu = previous[kind]
            growth = f"x{cpu / before_cpu:.1f}/{count / before_count:.0f}"
        previous[kind] = (count, cpu)
        print(
            f"{kind:<18} {size:>14} {wall * 1000:>10.2f}ms {cpu * 1000:>10.2f}ms "
            f"{cpu / count * 1e6:>10.2f}us {growth:>7}"
        )


if __name__ == "__main__":
    main()
