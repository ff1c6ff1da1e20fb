"""NuSMV vs the native checker on FSM pairs of 10 … 2 000 states, under fsmbt.limits' caps (issue 19).

    .venv/bin/python benchmarks/bench_nusmv_scale.py [--sizes 10,30,100,300,1000,2000]
        [--timeout 60] [--memory 2048]

Pairs: ``bench_checker.chain_fsm(n)`` (a chain plus n/2 random edges, one event per transition)
against its renamed, reordered copy (macro-step mode; the pair is equivalent). ``native`` is the
native checker's wall time; ``NuSMV`` is ``fsmbt.verify.nusmv.check`` under the caps (time
``--timeout`` s, memory ``--memory`` MiB through RLIMIT_AS), or the limit message NuSMV's run
ended with. After the first size that hits a cap the sizes in between are skipped and the largest
one is run, so its message is printed too. Prints figures; nothing is asserted.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import chain_fsm, renamed  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.verify import nusmv  # noqa: E402
from fsmbt.verify.native import check as native_check  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError, count_variables  # noqa: E402
from fsmbt.verify.pairing import machines_for  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,30,100,300,1000,2000")
    parser.add_argument("--timeout", type=float, default=60.0, help="NuSMV seconds per run")
    parser.add_argument("--memory", type=int, default=2048, help="NuSMV MiB per run")
    args = parser.parse_args(argv)
    limits.use(
        limits.current().with_changes(
            nusmv_max_seconds=args.timeout, nusmv_max_memory_mb=args.memory
        )
    )
    sizes = [int(s) for s in args.sizes.split(",")]
    header = f"{'states':>6} {'SMV vars':>8} {'native s':>9} {'NuSMV s':>9} {'ratio':>8}  verdict"
    print(header)
    print("-" * len(header))
    index = 0
    while index < len(sizes):
        n = sizes[index]
        source, result = chain_fsm(n, n), renamed(chain_fsm(n, n))
        left, right, _mode = machines_for(source, result)
        started = time.perf_counter()
        native_report = native_check(left, right)
        native_s = time.perf_counter() - started
        text, _names, _context = nusmv.build_model(source, result)
        variables = count_variables(text)
        started = time.perf_counter()
        try:
            report = nusmv.check(source, result)
        except NuSMVLimitError as exc:
            print(f"{n:>6} {variables:>8} {native_s:>9.4f} {'-':>9} {'-':>8}  {exc}", flush=True)
            if index < len(sizes) - 1:
                print(
                    f"{'':>6} sizes {', '.join(map(str, sizes[index + 1 : -1])) or '-'} skipped: "
                    "the cap is reached; running the largest",
                    flush=True,
                )
                index = len(sizes) - 1
                continue
            break
        nusmv_s = time.perf_counter() - started
        agree = "agree" if report.equivalent == native_report.equivalent else "DISAGREE"
        print(
            f"{n:>6} {variables:>8} {native_s:>9.4f} {nusmv_s:>9.2f} "
            f"{nusmv_s / native_s:>8.0f}  equivalent={report.equivalent} ({agree})",
            flush=True,
        )
        index += 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
