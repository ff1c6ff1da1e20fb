"""NuSMV on real trees that hold the built-ins encoded in issue 12 (Repeat, RetryUntilSuccessful,
RunOnce, Parallel, ParallelAll): each corpus or example BT that the rules engine converts, with
its conversion, checked by both engines.

Prints, per pair: the built-ins it holds, the native machines' states, NuSMV's CPU seconds
(``RUSAGE_CHILDREN``: the figure that does not depend on the machine's load) and wall seconds,
and both verdicts; then the CPU total. Pairs above ``--max-states`` native states are listed
and not given to NuSMV (the agreement test's bound). ``--counts 10,20,40`` also sweeps the
count of ``Repeat(a, num_cycles=L)`` checked against itself (each count value is a state for
both engines): how NuSMV's time grows with L. Prints figures only; nothing is asserted.

Run: ``FSMBT_CORPUS=... .venv/bin/python benchmarks/bench_nusmv_builtins.py [--max-states 100]
[--counts 10,20,40] [--timeout 600]``.
"""

from __future__ import annotations

import argparse
import os
import resource
import time
from pathlib import Path

from fsmbt import api
from fsmbt.convert.engines import converter_for
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.verify import verify
from fsmbt.verify.nusmv import check
from fsmbt.verify.nusmv.runner import NuSMVLimitError

REPO = Path(__file__).resolve().parents[1]
KINDS = frozenset({"Repeat", "RetryUntilSuccessful", "RunOnce", "Parallel", "ParallelAll"})


def built_ins(doc: BTDocument) -> list[str]:
    """The kinds of ``KINDS`` in any tree of ``doc`` (explicit stack)."""
    found: set[str] = set()
    for tree in doc.trees.values():
        stack = [tree.root] if tree.root is not None else []
        while stack:
            node = stack.pop()
            if node.type in KINDS:
                found.add(node.type)
            stack.extend(node.children)
    return sorted(found)


def models(corpus: Path) -> list[Path]:
    files = sorted(p for p in (REPO / "examples").iterdir() if p.suffix == ".xml")
    if corpus.is_dir():
        files += sorted(
            p
            for p in corpus.rglob("*.xml")
            if not {"_malformed", "_legacy_draft", "LICENSES"} & set(p.parts)
        )
    return files


def cpu_of_children() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def count_sweep(counts: list[int], timeout: float) -> None:
    """NuSMV on ``Repeat(a, num_cycles=L)`` against itself, for each L."""
    print(
        f"\n{'num_cycles':>10}{'native states':>15}{'native s':>10}{'NuSMV CPU s':>13}{'wall s':>9}"
    )
    for count in counts:
        leaf = BTNode("a", NodeKind.ACTION, name="a")
        repeat = BTNode("Repeat", NodeKind.DECORATOR, attrs={"num_cycles": str(count)})
        repeat.children.append(leaf)
        doc = BTDocument.single(repeat)
        native = time.perf_counter()
        states = verify(doc, doc).stats["source_states"]
        native = time.perf_counter() - native
        cpu, wall = cpu_of_children(), time.perf_counter()
        try:
            check(doc, doc, timeout=timeout)
            figure = ""
        except NuSMVLimitError:
            figure = f"  past the {timeout:.0f} s cap"
        cpu, wall = cpu_of_children() - cpu, time.perf_counter() - wall
        print(f"{count:>10}{states:>15}{native:>10.2f}{cpu:>13.1f}{wall:>9.1f}{figure}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-states", type=int, default=100)
    parser.add_argument("--timeout", type=float, default=600.0)
    parser.add_argument("--counts", default="", help="e.g. 10,20,40: the Repeat count sweep")
    args = parser.parse_args()
    corpus = Path(os.environ.get("FSMBT_CORPUS", REPO.parent / "shared" / "corpus"))
    total = 0.0
    print(f"{'model':<66} {'built-ins':<37}{'states':>7}{'CPU s':>8}{'wall s':>8}  verdicts")
    for path in models(corpus):
        try:
            doc = api.load(path).model
            if not isinstance(doc, BTDocument) or not built_ins(doc):
                continue
            result = converter_for("rules", doc)(doc).model
        except FsmbtError:
            continue
        name = str(path.relative_to(corpus if corpus in path.parents else REPO))
        stats = verify(doc, result).stats
        states = max(stats["source_states"], stats["result_states"])
        kinds = ",".join(built_ins(doc))
        if states > args.max_states:
            print(f"{name:<66} {kinds:<37}{states:>7}  above --max-states: not run")
            continue
        cpu, wall = cpu_of_children(), time.perf_counter()
        smv = check(doc, result, timeout=args.timeout)
        cpu, wall = cpu_of_children() - cpu, time.perf_counter() - wall
        total += cpu
        native = verify(doc, result).equivalent
        print(
            f"{name:<66} {kinds:<37}{states:>7}{cpu:>8.1f}{wall:>8.1f}  "
            f"nusmv equivalent={smv.equivalent}, native equivalent={native}"
        )
    print(f"NuSMV CPU seconds in total: {total:.1f}")
    if args.counts:
        count_sweep([int(c) for c in args.counts.split(",")], args.timeout)


if __name__ == "__main__":
    main()
