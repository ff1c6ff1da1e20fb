"""How long the native checker takes, and how it grows (issue 3, item 7). Prints a table.

    .venv/bin/python benchmarks/bench_checker.py [--sizes 10,30,100,1000,10000] [--repeat 3]
        [--generic]

``fsm~lebt`` runs the LEBT on the fast strict-grammar runtime (``fsmbt.semantics.lebt.fast``) when the tree has
that shape (the family's name then reads ``fsm~lebt*``); ``--generic`` forces the generic BT
interpreter path, to compare.

Families (each pair is equivalent, so the whole product is explored):
- ``fsm~fsm``: a random FSM of N states (a chain plus N/2 random extra edges, every transition
  with its own event, as the paper's ``eventXY``) against a renamed, reordered copy;
- ``fsm~lebt``: the same FSM against its LEBT (``fsmbt.convert.lebt.fsm_to_lebt``);
- ``bt~hfsm``: a random BT of N leaves (Sequence/Fallback, conditions and actions) against
  its HFSM (``fsmbt.convert.bt_to_hfsm``).
Times exclude conversion; ``time`` = ``explore`` (each machine alone: the machines' own step
cost, e.g. the BT interpreter, plus interning) + ``product`` (the checker's product on tables).
Targets (issue 3): a 30-state pair under 10 ms, a 10 000-state pair under 5 s, growth close to
linear in the product's size (the ``us/state`` column should stay roughly flat).
"""

from __future__ import annotations

import argparse
import random
import signal
import sys
import time
from collections.abc import Callable

from fsmbt.model import FSM, BTDocument, BTNode, NodeKind, State
from fsmbt.semantics.lebt.machine import LEBTMachine
from fsmbt.verify.native import check
from fsmbt.verify.pairing import LEBTWithActiveInputs, machines_for

Pair = tuple[object, object]


def chain_fsm(n: int, seed: int) -> FSM:
    """N states in a chain, N/2 extra random edges, one event per transition, last state final."""
    rng = random.Random(seed)
    fsm = FSM(name=f"chain{n}", start_name="Start", initial_event="eventStart", initial="s0")
    for i in range(n):
        fsm.add_state(State(f"s{i}", action=f"act{i}", final=i == n - 1))
    fsm.initial = "s0"
    for i in range(n - 1):
        fsm.add_transition(f"s{i}", f"event_{i}_{i + 1}", f"s{i + 1}")
    for _ in range(n // 2):
        a, b = rng.randrange(n - 1), rng.randrange(n)
        fsm.add_transition(f"s{a}", f"event_{a}_{b}_x", f"s{b}")
    return fsm


def renamed(fsm: FSM) -> FSM:
    out = FSM(name=f"{fsm.name}_copy", start_name="Init", initial_event=fsm.initial_event)
    for name in reversed(list(fsm.states)):
        s = fsm.states[name]
        out.add_state(State(f"r_{name}", action=s.action, final=s.final))
    out.initial = f"r_{fsm.initial}"
    for t in reversed(fsm.transitions):
        out.add_transition(f"r_{t.source}", t.event, f"r_{t.target}")
    return out


def random_tree(leaves: int, seed: int) -> BTDocument:
    """A random BT with exactly ``leaves`` leaves: groups of 2-4 nodes under Sequence or
    Fallback, bottom-up (no recursion), 40 % conditions."""
    rng = random.Random(seed)
    level: list[BTNode] = []
    for i in range(leaves):
        kind = NodeKind.CONDITION if rng.random() < 0.4 else NodeKind.ACTION
        level.append(BTNode("Check" if kind is NodeKind.CONDITION else "Do", kind, name=f"L{i}"))
    while len(level) > 1:
        grouped: list[BTNode] = []
        i = 0
        while i < len(level):
            k = min(rng.randint(2, 4), len(level) - i)
            if k == 1:
                grouped[-1].children.append(level[i])
                i += 1
                continue
            control = rng.choice(("Sequence", "Fallback"))
            grouped.append(BTNode(control, NodeKind.CONTROL, children=level[i : i + k]))
            i += k
        level = grouped
    root = level[0]
    if root.is_leaf:
        root = BTNode("Sequence", NodeKind.CONTROL, children=[root])
    return BTDocument.single(root)


def family_pairs() -> dict[str, Callable[[int], Pair]]:
    families: dict[str, Callable[[int], Pair]] = {
        "fsm~fsm": lambda n: (chain_fsm(n, n), renamed(chain_fsm(n, n))),
    }
    try:
        from fsmbt.convert.lebt import fsm_to_lebt

        families["fsm~lebt"] = lambda n: (chain_fsm(n, n), fsm_to_lebt(chain_fsm(n, n)).model)
    except ImportError:
        pass
    try:
        from fsmbt.convert.bt_to_hfsm import bt_to_hfsm

        families["bt~hfsm"] = lambda n: (random_tree(n, n), bt_to_hfsm(random_tree(n, n)).model)
    except ImportError:
        pass
    return families


class _Timeout(Exception):
    pass


def _alarm(_signum, _frame):  # type: ignore[no-untyped-def]
    raise _Timeout


def machines(pair: Pair, generic: bool):  # type: ignore[no-untyped-def]
    """The checker's machines for ``pair``; ``generic`` puts an LEBT on the interpreter path."""
    source, result, _mode = machines_for(pair[0], pair[1])  # type: ignore[arg-type]
    if isinstance(result, LEBTWithActiveInputs) and generic:
        result = LEBTWithActiveInputs(
            LEBTMachine(
                pair[1],
                result.alphabet,  # type: ignore[arg-type]
                generic=True,
            )
        )
    return source, result


def uses_fast_lebt(pair: Pair) -> bool:
    _source, result = machines(pair, False)
    return isinstance(result, LEBTWithActiveInputs) and result.machine.fast  # type: ignore[attr-defined]


def measure(
    pair: Pair, repeat: int, limit_s: int, generic: bool = False
) -> tuple[float, dict] | None:
    best = float("inf")
    stats: dict = {}
    signal.signal(signal.SIGALRM, _alarm)
    try:
        for attempt in range(repeat):
            if attempt and best > 1.0:
                break  # long runs are measured once
            source, result = machines(pair, generic)
            signal.alarm(limit_s)
            started = time.perf_counter()
            report = check(source, result)
            elapsed = time.perf_counter() - started
            signal.alarm(0)
            if not report.equivalent:
                raise SystemExit(f"benchmark pair is not equivalent: {report.verdicts()}")
            if elapsed < best:
                best, stats = elapsed, report.stats
    except _Timeout:
        return None
    finally:
        signal.alarm(0)
    return best, stats


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,30,100,1000,10000")
    parser.add_argument("--repeat", type=int, default=3, help="best of R runs (runs under 1 s)")
    parser.add_argument("--limit", type=int, default=120, help="seconds per check before giving up")
    parser.add_argument(
        "--generic",
        action="store_true",
        help="run LEBTs on the generic BT interpreter, not the fast runtime",
    )
    parser.add_argument("--families", default="", help="comma-separated subset of the families")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    sys.setrecursionlimit(10_000)
    header = (
        f"{'pair':<9} {'N':>6} {'src st':>7} {'res st':>7} {'product':>8} {'edges':>8} "
        f"{'time ms':>9} {'explore':>9} {'product':>8} {'us/state':>9} {'x time':>7} "
        f"{'x size':>7}"
    )
    print(header)
    print("-" * len(header))
    wanted = set(filter(None, args.families.split(",")))
    for family, make in family_pairs().items():
        if wanted and family not in wanted:
            continue
        previous: tuple[float, int] | None = None
        for n in sizes:
            pair = make(n)
            if uses_fast_lebt(pair) and not args.generic:
                family = family.rstrip("*") + "*"
            measured = measure(pair, args.repeat, args.limit, args.generic)
            if measured is None:
                print(f"{family:<9} {n:>6}  over {args.limit} s, stopped")
                break
            seconds, stats = measured
            product = stats["product_states"]
            ratio_t = f"{seconds / previous[0]:.1f}" if previous else "-"
            ratio_s = f"{product / previous[1]:.1f}" if previous else "-"
            print(
                f"{family:<9} {n:>6} {stats['source_states']:>7} {stats['result_states']:>7} "
                f"{product:>8} {stats['product_edges']:>8} {seconds * 1000:>9.2f} "
                f"{stats['explore_seconds'] * 1000:>9.2f} {stats['product_seconds'] * 1000:>8.2f} "
                f"{seconds / product * 1e6:>9.1f} {ratio_t:>7} {ratio_s:>7}",
                flush=True,
            )
            previous = (seconds, product)
    if not args.generic:
        print(
            "* LEBT on the fast strict-grammar runtime (semantics/lebt/fast.py); --generic for the interpreter"
        )
    print("bt~hfsm: plain Sequence/Fallback trees run on the fast leaf machine (leaf_fast)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
