"""NuSMV options and BDD orders on FSM ~ state-variable tree pairs (BSD, CHDS; encode_sv).

    .venv/bin/python benchmarks/bench_nusmv_sv_options.py [--style bsd] [--sizes 10,20]
        [--timeout 60] [--seed 7] [--columns default,part,split,split-mono,tree-order]

One random FSM per size (``generate.random_fsm``, ``--seed``) against its conversion (``copy``)
and against the conversion of the FSM with its first transition retargeted (``mutant``). Per
column, NuSMV's CPU seconds (``RUSAGE_CHILDREN``, independent of the machine's load) for
``nusmv.check``; ``-`` = past ``--timeout`` wall seconds; ``!`` = a verdict differs from the
native checker's. Columns: ``default`` (``check``'s choice for these pairs: one ``-mono`` run,
blackboard-first order), ``part`` (one run, partitioned relation), ``split`` / ``split-mono``
(the FSM ~ FSM two runs, docs/nusmv.md "Two runs"), ``tree-order`` (the default run with the
tree's variables first in the BDD order, as ``BTCore`` declares them).
"""

from __future__ import annotations

import argparse
import copy
import resource
import sys
from collections.abc import Callable
from typing import Any

from fsmbt import limits
from fsmbt.convert.baselines.bsd import fsm_to_bsd
from fsmbt.convert.baselines.chds import fsm_to_chds
from fsmbt.generate.generator import random_fsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.verify import nusmv, verify
from fsmbt.verify.nusmv import encode_sv
from fsmbt.verify.nusmv.runner import NuSMVLimitError

COLUMNS: dict[str, dict[str, Any]] = {
    "default": {},
    "part": {"split": False, "mono": False},
    "split": {"split": True, "mono": False},
    "split-mono": {"split": True, "mono": True},
    "tree-order": {},
}


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def tree_order(self: encode_sv.SvEncoder) -> list[str]:
    return list(self.core.var_types)


def run(fsm: FSM, tree: BTDocument, column: str, expected: dict[str, bool]) -> str:
    saved: Callable[..., list[str]] = encode_sv.SvEncoder.bdd_order
    if column == "tree-order":
        encode_sv.SvEncoder.bdd_order = tree_order  # type: ignore[method-assign]
    before = child_cpu()
    try:
        report = nusmv.check(fsm, tree, **COLUMNS[column])
    except NuSMVLimitError:
        return "-"
    finally:
        encode_sv.SvEncoder.bdd_order = saved  # type: ignore[method-assign]
    mark = "" if report.verdicts() == expected else "!"
    return f"{child_cpu() - before:.2f}{mark}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--style", choices=("bsd", "chds"), default="bsd")
    parser.add_argument("--sizes", default="10,20")
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--columns", default=",".join(COLUMNS))
    args = parser.parse_args(argv)
    limits.use(limits.current().with_changes(nusmv_max_seconds=args.timeout))
    convert = {"bsd": fsm_to_bsd, "chds": fsm_to_chds}[args.style]
    columns = args.columns.split(",")
    header = f"{'pair':<7} {'states':>6} {'native':>7} " + " ".join(f"{c:>10}" for c in columns)
    print(header)
    print("-" * len(header))
    for size in (int(s) for s in args.sizes.split(",")):
        fsm = random_fsm(args.seed, n_states=size)
        mutant = copy.deepcopy(fsm)
        first = mutant.transitions[0]
        first.target = next(name for name in mutant.states if name != first.target)
        for kind, source in (("copy", fsm), ("mutant", mutant)):
            tree = convert(source).model
            assert isinstance(tree, BTDocument)
            native = verify(fsm, tree)
            verdict = "equiv" if native.equivalent else "fails"
            cells = [run(fsm, tree, c, native.verdicts()) for c in columns]
            print(
                f"{kind:<7} {size:>6} {verdict:>7} " + " ".join(f"{c:>10}" for c in cells),
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
