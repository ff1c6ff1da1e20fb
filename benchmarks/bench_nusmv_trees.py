"""NuSMV's one run against its two runs on tree pairs (issue 27, item 2). Prints NuSMV CPU s.

    .venv/bin/python benchmarks/bench_nusmv_trees.py bt 8,32,64 60 whole,smono,after
    .venv/bin/python benchmarks/bench_nusmv_trees.py lebt 4,8,16 60 whole,smono,after

Arguments: the family (``bt``: ``bench_nusmv.random_bt`` of n leaves against its HFSM;
``lebt``: a random FSM of n states against its LEBT), the sizes, the wall cap per NuSMV run,
the columns: ``whole`` (one ``-mono`` run, ``check(split=False)``: what ``check`` does for
these pairs), ``smono`` (the two runs of FSM ~ FSM pairs with ``-mono``), ``after`` (the two
runs, partitioned), ``old`` (``check()`` with its defaults: run it with ``PYTHONPATH`` on an
older checkout to measure that version). Each cell: NuSMV CPU seconds (``RUSAGE_CHILDREN``)
and whether the five verdicts equal the native checker's; ``-`` past the cap.
"""

from __future__ import annotations

import random
import resource
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_nusmv import random_bt  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.convert.lebt import fsm_to_lebt  # noqa: E402
from fsmbt.generate.generator import random_fsm  # noqa: E402
from fsmbt.verify import nusmv, verify  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError  # noqa: E402


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main(argv: list[str]) -> int:
    family, sizes, cap = argv[0], [int(x) for x in argv[1].split(",")], float(argv[2])
    columns = argv[3].split(",") if len(argv) > 3 else ["whole", "after"]
    limits.use(limits.current().with_changes(nusmv_max_seconds=cap))
    rng = random.Random(7)
    for n in sizes:
        if family == "bt":
            source = random_bt(rng, n)
            result = bt_to_hfsm(source).model
        else:
            source = random_fsm(rng.randrange(10**9), n_states=n)
            result = fsm_to_lebt(source).model
        native = verify(source, result)
        row = [family, str(n)]
        for column in columns:
            before = child_cpu()
            try:
                if column == "old":
                    report = nusmv.check(source, result)
                else:
                    split = column != "whole"
                    report = nusmv.check(source, result, split=split, mono=column != "after")
            except NuSMVLimitError:
                row.append(f"{column} -")
                continue
            same = report.verdicts() == native.verdicts()
            row.append(f"{column} {child_cpu() - before:.2f} {'agree' if same else 'DISAGREE'}")
        print(*row, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
