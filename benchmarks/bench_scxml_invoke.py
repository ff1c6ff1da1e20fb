"""Cost of reading SCXML ``<invoke>`` (fsmbt.formats.scxml.invoke): a parallel state of N
regions, each invoking an autoforwarded child that toggles on its own event, so the reachable
configurations are 2**N (every child's state is part of the flat state). Prints, per N, the
flat states and transitions found and the read time (best of 3).

    PYTHONPATH=src .venv/bin/python benchmarks/bench_scxml_invoke.py [MAX_N]   (default 8)
"""

from __future__ import annotations

import sys
import time

from fsmbt.formats import loads
from fsmbt.model.fsm import FSM

NS = 'xmlns="http://www.w3.org/2005/07/scxml"'


def document(n: int) -> str:
    regions = "".join(
        f'<state id="r{i}"><invoke id="k{i}" autoforward="true"><content>'
        f'<scxml version="1.0"><state id="off"><transition event="t{i}" target="on"/></state>'
        f'<state id="on"><transition event="t{i}" target="off"/></state></scxml>'
        "</content></invoke></state>"
        for i in range(n)
    )
    return f'<scxml {NS} version="1.0"><parallel id="p">{regions}</parallel></scxml>'


def main() -> int:
    top = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    print("| children | flat states | transitions | read (s) |")
    print("|---|---|---|---|")
    for n in range(1, top + 1):
        text = document(n)
        best = float("inf")
        model: FSM | None = None
        for _ in range(3):
            start = time.perf_counter()
            read = loads(text, "scxml")
            best = min(best, time.perf_counter() - start)
            assert isinstance(read, FSM)
            model = read
        assert model is not None
        print(f"| {n} | {len(model.states)} | {len(model.transitions)} | {best:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
