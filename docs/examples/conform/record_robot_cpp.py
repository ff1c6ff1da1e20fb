"""docs/conform.md's C++ example: record two runs of a tree in BehaviorTree.CPP 4.8.2 through
fsmbt's C++ driver (``--scripted``), every leaf scripted with seeded outcomes, each run logged
twice: FileLogger2 (.btlog) and SqliteLogger (.db3).

    .venv/bin/python docs/examples/conform/record_robot_cpp.py TREE.xml OUT_PREFIX
"""

import sys
from pathlib import Path

from fsmbt.runtime.cpp.scripted import record_scripted

tree, prefix = Path(sys.argv[1]), sys.argv[2]
for seed in (1, 2):
    btlog, db3 = Path(f"{prefix}-{seed}.btlog"), Path(f"{prefix}-{seed}.db3")
    btlog.parent.mkdir(parents=True, exist_ok=True)
    results = record_scripted(tree, seed=seed, ticks=30, btlog=btlog, db3=db3)
    print(f"{btlog}, {db3}: {len(results)} ticks")
