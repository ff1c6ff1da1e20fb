"""Deep chains in BehaviorTree.CPP: depth, load and tick figures of the depth-bounded LEBT.

    PYTHONPATH=src python benchmarks/bench_deep_chain.py [--sizes 1000,10000,100000]

For each size ``n``: the chain ``S0 -next-> ... -> S(n-1)`` (the last final) is converted with
``--style lebt`` (docs/semantics.md §5, "Depth-bounded LEBT"), written as BehaviorTree.CPP XML,
loaded by ``convert``'s load check (``fsmbt.semantics.engines.btcpp_load``: BehaviorTree.CPP
4.8.2 itself) and run by the C++ LEBT driver through all ``n - 1`` events; the driver's last step
must be ``S(n-1)``, terminated. Printed: tree depth, deepest XML element, root selectors, the
paper shape's depth (``2n + 1``: what tinyxml2 refused past ~245 states), seconds to convert,
to load, and the driver's run (load + every macro step, one process), and the C++ CPU time per
macro step (``--bench``). Nothing is asserted on time: a figure, not a test.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.runtime.cpp import DriverSession, find_driver
from fsmbt.semantics.engines.btcpp_load import check_loads

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from support.chains import chain, xml_depth  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1000,10000,100000")
    args = parser.parse_args()
    driver = find_driver()
    print(
        f"{'states':>7} {'depth':>5} {'xml':>4} {'roots':>5} {'paper':>7} {'convert s':>9} "
        f"{'load s':>7} {'loads':>5} {'run s':>7} {'last state':>10} {'ns/step CPU':>11}"
    )
    with tempfile.TemporaryDirectory() as folder:
        for n in (int(size) for size in args.sizes.split(",")):
            fsm = chain(n)
            started = time.perf_counter()
            result = convert(fsm, style="lebt")
            converted = time.perf_counter() - started
            text = dumps(result.model, "btcpp")
            tree = Path(folder) / f"chain{n}.xml"
            tree.write_text(text, encoding="utf-8")
            started = time.perf_counter()
            load = check_loads(text)
            loading = time.perf_counter() - started
            last, per_step, running = "-", "-", "-"
            if driver is not None and load.loaded:
                events = ["next"] * (n - 1)
                session = DriverSession(tree, driver=driver, timeout=1800)
                started = time.perf_counter()
                [run] = session.run([events])
                running = f"{time.perf_counter() - started:.2f}"
                end = run[-1]
                last = end.state + ("*" if end.terminated else "")
                figures = session.bench([events], 1)
                per_step = f"{figures['cpu_ns_per_step']:,.0f}"
            print(
                f"{n:>7} {result.stats['depth']:>5} {xml_depth(text):>4} "
                f"{result.stats['root_subtrees']:>5} {2 * n + 1:>7} {converted:>9.2f} "
                f"{loading:>7.2f} {'yes' if load.loaded else 'NO':>5} {running:>7} "
                f"{last:>10} {per_step:>11}"
            )
            sys.stdout.flush()
    print("(* = terminated in the final state; loads = " + load.engine + ")")
    return 0


if __name__ == "__main__":
    sys.exit(main())
