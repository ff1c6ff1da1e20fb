"""How long the SMACH reader and writer take on large machines. Prints a table.

    .venv/bin/python benchmarks/bench_smach.py [--sizes 100,1000,10000]

For each size N: a random FSM of N states (``fsmbt.generate.random_fsm``) is written as a SMACH
module (``write``), that module is read back statically (``read``: ast parse, analysis,
model), and the two models are checked equivalent (``verify``, the native checker).
``us/state`` should stay roughly flat (both directions are linear in the source).
"""

from __future__ import annotations

import argparse
import time

from fsmbt.formats import loads
from fsmbt.formats.pysm.smach_write import write_smach
from fsmbt.generate.generator import random_fsm
from fsmbt.verify import verify


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,1000,10000")
    args = parser.parse_args()
    loads(write_smach(random_fsm(0, n_states=3)), "smach")  # warm up: imports, registry
    print("| states | source KiB | write ms | read ms | read us/state | verify ms | equivalent |")
    print("|---|---|---|---|---|---|---|")
    for size in (int(s) for s in args.sizes.split(",")):
        model = random_fsm(size, n_states=size)
        start = time.perf_counter()
        text = write_smach(model)
        write_ms = (time.perf_counter() - start) * 1000
        start = time.perf_counter()
        back = loads(text, "smach")
        read_s = time.perf_counter() - start
        start = time.perf_counter()
        equivalent = verify(model, back).equivalent
        verify_ms = (time.perf_counter() - start) * 1000
        print(
            f"| {size} | {len(text.encode()) / 1024:.0f} | {write_ms:.0f} | {read_s * 1000:.0f} "
            f"| {read_s * 1e6 / size:.0f} | {verify_ms:.0f} | {equivalent} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
