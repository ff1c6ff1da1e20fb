"""The dispatch form against the LEBT in the pipeline (prints a table; not a test):
docs/semantics.md section 12, "Cost", holds its output.

For generated machines (``fsmbt.generate.random_fsm``: chains and trees, every event distinct)
of 1 000 and 10 000 states: the CPU seconds of building the LEBT (``--style lebt``) and the
dispatch form (``--style dispatch``, what ``auto`` gives an event-driven machine), of the
native checker proving each, and of BT -> FSM of the dispatch tree as BehaviorTree.CPP XML
reads it (``fsmbt.convert.dispatch_fsm``), with whether that machine has the source's states
and is proven equivalent to the source. Each figure is one run (process time).

Run: .venv/bin/python benchmarks/bench_dispatch_convert.py [--quick]   (--quick: 1 000 only)
"""

from __future__ import annotations

import sys
import time

from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.generate import random_fsm
from fsmbt.verify import verify


def _timed(func):  # type: ignore[no-untyped-def]
    started = time.process_time()
    value = func()
    return value, time.process_time() - started


def main() -> None:
    sizes = (1_000,) if "--quick" in sys.argv else (1_000, 10_000)
    print(
        "| machine | LEBT build / check | dispatch build / check | dispatch BT -> FSM "
        "| same states, proven |"
    )
    print("|---|---|---|---|---|")
    for n in sizes:
        for shape in ("chain", "tree"):
            extra = {"extra_edges": 0} if shape == "chain" else {}
            fsm = random_fsm(
                f"bench-dispatch-{shape}-{n}", n, start_event=False, shape=shape, **extra
            )  # type: ignore[arg-type]
            cells = []
            for style in ("lebt", "dispatch"):
                result, built = _timed(lambda style=style, fsm=fsm: convert(fsm, style=style))
                report, checked = _timed(lambda result=result, fsm=fsm: verify(fsm, result.model))
                assert report.equivalent, (shape, n, style)
                cells.append(f"{built:.2f} / {checked:.2f}")
            doc = loads(dumps(result.model, "btcpp"), "btcpp")
            back, read = _timed(lambda doc=doc: convert(doc))
            same = back.stats["states"] == len(fsm.states)
            proven = verify(fsm, back.model).equivalent
            print(
                f"| {shape}, {n:,} states | {cells[0]} | {cells[1]} | {read:.2f} | {same}, {proven} |"
            )


if __name__ == "__main__":
    main()
