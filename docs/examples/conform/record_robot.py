"""docs/conform.md's example: record two runs of a tree in BehaviorTree.CPP 4.8.2 (through
behaviortreepy, FileLogger2) with scripted leaves, seeded.

    .venv/bin/python docs/examples/conform/record_robot.py TREE.xml OUT_PREFIX
"""

import sys
from pathlib import Path

from fsmbt import api
from fsmbt.conform.record import record_btlog

tree, prefix = Path(sys.argv[1]), sys.argv[2]
doc = api.load(tree).model
for seed in (1, 2):
    out = Path(f"{prefix}-{seed}.btlog")
    out.parent.mkdir(parents=True, exist_ok=True)
    results = record_btlog(doc, tree.read_text(encoding="utf-8"), out, seed=seed, ticks=30)
    print(f"{out}: {len(results)} ticks")
