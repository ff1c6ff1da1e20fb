"""The native checker on reactive and memory trees of 100 … 10 000 nodes (issue 19). Prints a table.

    .venv/bin/python benchmarks/bench_reactive.py [--sizes 100,1000,10000] [--limit 120]
        [--faithful-up-to 1000]

Families (one random tree per size, the shape of ``bench_checker.random_tree``: groups of 2-4
under a control, 40 % conditions; every control then re-typed, seeded):
- ``plain``: Sequence/Fallback (the static table of ``leaf_fast``);
- ``reactive``: ReactiveSequence/ReactiveFallback (the static table widened to reactive nodes);
- ``reactive-plain``: each control reactive or plain at random (plain nodes under reactive ones
  keep a running index: canonical states, ``leaf_canonical``);
- ``memory``: SequenceWithMemory / Fallback (the WithMemory index is real, readable memory);
- ``mixed``: each control drawn from all five kinds;
- ``decorated``: ``mixed``, then a fifth of the leaves under a decorator (Inverter, ForceSuccess,
  ForceFailure, RetryUntilSuccessful 2, Repeat 2) and a tenth of the controls made Parallel
  (success_count 1, failure_count 1): the random family of issue 27.
Each tree is checked against its HFSM (``bt_to_hfsm``, not timed); ``time`` is the whole
``check`` (both machines explored, then the product). A row that stops prints why (the time limit,
or the state limit: WithMemory indices are real memory, so a tree with k of them may have a
product of k index ranges as states; the first stop ends the family). ``faithful`` is the number of states of the faithful
interpreter's leaf machine (``LeafMachine(generic=True)``), explored for trees up to
``--faithful-up-to`` nodes (it is the cost this work removes; past the limit it is not run).
Targets (issue 19): a 1 000-node reactive tree under 1 s, a 10 000-node one under 10 s.

``--convert`` times the whole ``fsmbt convert`` of each tree (read, convert, verify, load check,
write; wall and CPU seconds of this process - a load check in a child process is not in its CPU
seconds), the proof's seconds (``verify s``), the wait for the load check past the proof (``load s``:
it runs beside the proof, ``semantics.engines.load_beside``) and prints the verdict's method. ``--compositional`` (issue 27) prints another table: per tree the conversion's seconds, the
compositional check's regions, largest region product, summed products and seconds (or why the
pair falls back to the whole product), and the whole product's states and seconds beside it.
"""

from __future__ import annotations

import argparse
import random
import signal
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import random_tree  # noqa: E402

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.model import BTDocument  # noqa: E402
from fsmbt.model.bt import BTNode  # noqa: E402
from fsmbt.model.bt_nodes import NodeKind  # noqa: E402
from fsmbt.model.errors import InputError  # noqa: E402
from fsmbt.model.fsm import FSM  # noqa: E402
from fsmbt.semantics.leaf_machine import LeafMachine, StateLimitError, explore  # noqa: E402
from fsmbt.verify.compositional import compositional_report  # noqa: E402
from fsmbt.verify.native import check  # noqa: E402
from fsmbt.verify.pairing import machines_for  # noqa: E402
from fsmbt.verify.pernode import NODE_ATTR  # noqa: E402

FAMILIES: dict[str, dict[str, tuple[str, ...]]] = {
    "plain": {"Sequence": ("Sequence",), "Fallback": ("Fallback",)},
    "reactive": {"Sequence": ("ReactiveSequence",), "Fallback": ("ReactiveFallback",)},
    "reactive-plain": {
        "Sequence": ("ReactiveSequence", "Sequence"),
        "Fallback": ("ReactiveFallback", "Fallback"),
    },
    "memory": {"Sequence": ("SequenceWithMemory",), "Fallback": ("Fallback",)},
    "mixed": {
        "Sequence": ("Sequence", "ReactiveSequence", "SequenceWithMemory"),
        "Fallback": ("Fallback", "ReactiveFallback"),
    },
    # ``mixed``, then decorators over leaves and Parallel nodes (see ``decorate``)
    "decorated": {
        "Sequence": ("Sequence", "ReactiveSequence", "SequenceWithMemory"),
        "Fallback": ("Fallback", "ReactiveFallback"),
    },
}

#: The ``decorated`` family's decorators (type, ports), each over a leaf with probability 0.2.
DECORATORS: tuple[tuple[str, dict[str, str]], ...] = (
    ("Inverter", {}),
    ("ForceSuccess", {}),
    ("ForceFailure", {}),
    ("RetryUntilSuccessful", {"num_attempts": "2"}),
    ("Repeat", {"num_cycles": "2"}),
)


def family_tree(family: str, leaves: int, seed: int) -> BTDocument:
    """``random_tree(leaves, seed)`` with every control re-typed as ``family`` says."""
    doc = random_tree(leaves, seed)
    rng = random.Random(seed * 7 + len(family))
    table = FAMILIES[family]
    stack = [doc.main.root]
    while stack:
        node = stack.pop()
        if node.type in table:
            node.type = rng.choice(table[node.type])
        stack.extend(node.children)
    if family == "decorated":
        decorate(doc, rng)
    return doc


def decorate(doc: BTDocument, rng: random.Random) -> None:
    """Wrap each leaf in one of ``DECORATORS`` with probability 0.2, and make each control a
    ``Parallel`` (success_count 1, failure_count 1) with probability 0.1 (iterative)."""
    stack = [doc.main.root]
    while stack:
        node = stack.pop()
        if node.kind is NodeKind.CONTROL and rng.random() < 0.1:
            node.type = "Parallel"
            node.attrs = {"success_count": "1", "failure_count": "1"}
        for index, child in enumerate(node.children):
            if child.is_leaf and rng.random() < 0.2:
                kind, ports = rng.choice(DECORATORS)
                node.children[index] = BTNode(
                    kind, NodeKind.DECORATOR, attrs=dict(ports), children=[child]
                )
            else:
                stack.append(child)


def node_count(doc: BTDocument) -> int:
    count, stack = 0, [doc.main.root]
    while stack:
        node = stack.pop()
        count += 1
        stack.extend(node.children)
    return count


class _Timeout(Exception):
    pass


def _alarm(_signum, _frame):  # type: ignore[no-untyped-def]
    raise _Timeout


def leaves_for(nodes: int) -> int:
    """Leaves giving about ``nodes`` nodes (the generator makes ~1.45 nodes per leaf)."""
    return max(2, round(nodes / 1.45))


def _whole_check(doc: BTDocument, hfsm: FSM, limit: int) -> tuple[str, str]:
    """The whole product (``check`` on both machines): its product states and seconds, or
    why it stopped."""
    signal.alarm(limit)
    try:
        source, result, _mode = machines_for(doc, hfsm)
        started = time.perf_counter()
        report = check(source, result)
        seconds = time.perf_counter() - started
    except (_Timeout, StateLimitError, InputError) as exc:
        signal.alarm(0)
        return "-", f"over {limit} s" if isinstance(exc, _Timeout) else "state limit"
    signal.alarm(0)
    if not report.equivalent:
        raise SystemExit(f"tree and HFSM differ: {report.verdicts()}")
    return str(report.stats["product_states"]), f"{seconds:.3f}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,300,1000,3000,10000", help="nodes per tree")
    parser.add_argument("--limit", type=int, default=120, help="seconds per check")
    parser.add_argument(
        "--faithful-up-to",
        type=int,
        default=1000,
        help="explore the faithful machine for trees up to this many nodes",
    )
    parser.add_argument("--families", default=",".join(FAMILIES))
    parser.add_argument(
        "--compositional",
        action="store_true",
        help="time the compositional check (fsmbt.verify.compositional) and the conversion, "
        "and the whole product beside it (columns: conv s, regions, largest, comp st, comp s, "
        "whole st, whole s)",
    )
    parser.add_argument(
        "--convert",
        action="store_true",
        help="time the whole `fsmbt convert` of each tree (fsmbt.api.convert_file: read, "
        "convert, verify, write SCXML; the tree written to a temporary XML file first) and "
        "print the verdict and its method",
    )
    parser.add_argument(
        "--pernode",
        action="store_true",
        help="issue 27's per-node table: per tree the conversion (bt_to_hfsm, regions written "
        "per node past the estimate), the result's states, the per-node proof "
        "(compositional_report: distinct local checks, their product states, seconds); then a "
        "one-transition mutant of the biggest tree's result (see _pernode_table)",
    )
    args = parser.parse_args(argv)
    signal.signal(signal.SIGALRM, _alarm)
    if args.pernode:
        return _pernode_table(args)
    if args.compositional:
        return _compositional_table(args)
    if args.convert:
        return _convert_table(args)
    header = (
        f"{'family':<9} {'nodes':>6} {'path':<9} {'leaf st':>8} {'faithful':>9} "
        f"{'product':>8} {'time s':>8} {'us/node':>8} {'x time':>7} {'x nodes':>7}"
    )
    print(header)
    print("-" * len(header))
    for family in args.families.split(","):
        previous: tuple[float, int] | None = None
        for size in (int(s) for s in args.sizes.split(",")):
            doc = family_tree(family, leaves_for(size), size)
            nodes = node_count(doc)
            machine = LeafMachine(doc)
            path = "table" if machine.fast else "canonical" if machine.canonical else "faithful"
            faithful = "-"
            signal.alarm(args.limit)
            try:
                hfsm = bt_to_hfsm(doc).model
                source, result, _mode = machines_for(doc, hfsm)
                started = time.perf_counter()
                report = check(source, result)
                seconds = time.perf_counter() - started
                signal.alarm(0)
                if nodes <= args.faithful_up_to:
                    signal.alarm(args.limit)
                    try:
                        faithful = str(len(explore(LeafMachine(doc, generic=True), 2_000_000)))
                    except (_Timeout, StateLimitError):
                        faithful = f">{args.limit}s"
                    signal.alarm(0)
            except (_Timeout, StateLimitError) as exc:
                signal.alarm(0)
                print(
                    f"{family:<9} {nodes:>6} {path:<9}  stopped: "
                    f"{'over ' + str(args.limit) + ' s' if isinstance(exc, _Timeout) else exc}",
                    flush=True,
                )
                break
            if not report.equivalent:
                raise SystemExit(f"{family} {nodes}: tree and HFSM differ: {report.verdicts()}")
            stats = report.stats
            ratio_t = f"{seconds / previous[0]:.1f}" if previous else "-"
            ratio_n = f"{nodes / previous[1]:.1f}" if previous else "-"
            print(
                f"{family:<9} {nodes:>6} {path:<9} {stats['source_states']:>8} {faithful:>9} "
                f"{stats['product_states']:>8} {seconds:>8.3f} {seconds / nodes * 1e6:>8.1f} "
                f"{ratio_t:>7} {ratio_n:>7}",
                flush=True,
            )
            previous = (seconds, nodes)
    print(
        "path: table = leaf_fast static table; canonical = interpreter on canonical states "
        "(leaf_canonical); faithful = full interpreter snapshots"
    )
    return 0


def written_trees(
    args: argparse.Namespace, header: str, folder: Path
) -> Iterator[tuple[str, int, BTDocument, Path]]:
    """Print ``header`` and its rule, then, for each family and size of ``args``, the family's
    tree (seeded by its size) written as BT.CPP XML into ``folder``: (family, size, tree, its
    file) - the rows the ``--convert`` table and ``bench_load_check.py`` time."""
    from fsmbt import api

    print(header)
    print("-" * len(header))
    for family in args.families.split(","):
        for size in (int(s) for s in args.sizes.split(",")):
            doc = family_tree(family, leaves_for(size), size)
            yield family, size, doc, api.write(doc, folder / f"{family}{size}.xml")


def _convert_table(args: argparse.Namespace) -> int:
    """One row per tree: the whole ``convert`` (``fsmbt.api.convert_file``) in seconds (wall, and
    the process's CPU time: on a shared machine the wall time grows with the load, the CPU time
    much less), the verdict and the method that proved it, or why it stopped (the time limit or
    the error)."""
    from fsmbt import api

    header = (
        f"{'family':<14} {'nodes':>6} {'convert s':>10} {'cpu s':>8} {'verify s':>9} "
        f"{'load s':>7} {'verdict':>15} {'method':>14}"
    )
    with tempfile.TemporaryDirectory() as folder:
        for family, size, doc, tree in written_trees(args, header, Path(folder)):
            nodes = node_count(doc)
            signal.alarm(args.limit)
            try:
                started, cpu = time.perf_counter(), time.process_time()
                outcome = api.convert_file(
                    tree, Path(folder) / f"{family}{size}.scxml", overwrite=True
                )
                seconds = time.perf_counter() - started
                cpu = time.process_time() - cpu
                signal.alarm(0)
            except Exception as exc:  # the time limit, or what fsmbt refused and why
                signal.alarm(0)
                why = f"over {args.limit} s" if isinstance(exc, _Timeout) else str(exc)
                if "_Timeout" in why:  # the limit met inside a step that wraps errors
                    why = f"over {args.limit} s"
                print(f"{family:<14} {nodes:>6}  stopped: {why[:90]}", flush=True)
                continue
            report = outcome.report
            method = report.method if report is not None else "-"
            verify_s = outcome.timings.get("verify", 0.0)
            load_s = outcome.timings.get("load", 0.0)
            print(
                f"{family:<14} {nodes:>6} {seconds:>10.3f} {cpu:>8.3f} {verify_s:>9.2f} "
                f"{load_s:>7.2f} {api.verdict_word(report):>15} {method:>14}",
                flush=True,
            )
    return 0


def _never_ticked(doc: BTDocument, path: str) -> bool:
    """Whether the node at ``path`` (a per-node tag: the path in its region after the
    same-type merge) is one the tree never ticks in every region that has such a path."""
    from fsmbt.convert.compress import inline_and_compress
    from fsmbt.semantics.bt_interpreter import CompiledTree
    from fsmbt.verify.compositional import tree_regions
    from fsmbt.verify.tickable import never_ticked

    verdicts = []
    for root in tree_regions(doc):
        merged = inline_and_compress(BTDocument.single(root)).compression.root
        tree = CompiledTree(BTDocument.single(merged))
        ids = [n.id for n in tree.nodes if n.path == path]
        if ids:
            verdicts.append(ids[0] in never_ticked(tree))
    return bool(verdicts) and all(verdicts)


def _pernode_table(args: argparse.Namespace) -> int:
    """One row per tree: nodes, conversion seconds, result states (every state at any level),
    per-node regions, nodes checked, distinct local checks and their product states, proof
    seconds and method. Then the mutant row for the last tree: the first guarded transition
    of its first per-node region loses its guard; the per-node check must not prove it (it
    names the node whose local check fails, or the side condition that refuses), then the
    whole product is given ``--limit`` seconds to find the counterexample."""
    import copy

    from fsmbt.model.fsm_data import COND
    from fsmbt.verify import verify

    header = (
        f"{'family':<14} {'nodes':>6} {'conv s':>7} {'states':>7} {'regions':>7} "
        f"{'checked':>7} {'distinct':>8} {'local st':>8} {'proof s':>8} {'method':>24}"
    )
    print(header)
    print("-" * len(header))
    last: tuple[BTDocument, FSM] | None = None
    for family in args.families.split(","):
        for size in (int(s) for s in args.sizes.split(",")):
            doc = family_tree(family, leaves_for(size), size)
            nodes = node_count(doc)
            started = time.perf_counter()
            hfsm = bt_to_hfsm(doc).model
            converted = time.perf_counter() - started
            states = sum(1 for _ in hfsm.walk())
            signal.alarm(args.limit)
            try:
                started = time.perf_counter()
                proved, why = compositional_report(doc, hfsm)
                proof = time.perf_counter() - started
                signal.alarm(0)
            except _Timeout:
                proved, why, proof = None, f"over {args.limit} s", 0.0
            if proved is None:
                print(f"{family:<14} {nodes:>6} {converted:>7.2f} {states:>7}  falls back: {why}")
                continue
            st = proved.stats
            print(
                f"{family:<14} {nodes:>6} {converted:>7.2f} {states:>7} "
                f"{st.get('per_node_regions', 0):>7} {st.get('per_node_nodes', 0):>7} "
                f"{st.get('per_node_distinct', 0):>8} {st.get('per_node_local_states', 0):>8} "
                f"{proof:>8.2f} {proved.method:>24}",
                flush=True,
            )
            last = (doc, hfsm)
    if last is None:
        return 0
    doc, hfsm = last
    mutant = copy.deepcopy(hfsm)
    region = next(
        s.regions[0]
        for _p, _m, s in mutant.walk()
        if s.regions and s.regions[0].name.startswith("pernode_")
    )
    changed = next(t for t in region.transitions if COND in t.attrs)
    del changed.attrs[COND]
    changed_path = region.states[changed.source].attrs.get(NODE_ATTR, "")
    started = time.perf_counter()
    proved, why = compositional_report(doc, mutant)
    seconds = time.perf_counter() - started
    if proved is None:
        said = "not proven: " + why[:110]
    elif proved.equivalent:
        # a mutant is not always different: a change inside a node the tree never ticks is
        # none (docs/semantics.md §4d, "Dead nodes"); said so only when the tree says it
        said = (
            "proved EQUIVALENT: the changed region is never ticked ("
            + "; ".join(proved.stats["never_ticked_by"])
            + ")"
            if proved.stats.get("never_ticked_by")
            else f"proved EQUIVALENT: the changed transition is in node {changed_path!r}, which "
            f"the tree never ticks ({proved.stats.get('per_node_unticked', 0)} such nodes skipped)"
            if _never_ticked(doc, changed_path)
            else "PROVED (wrong)"
        )
    else:
        said = f"NOT EQUIVALENT ({proved.method}: {proved.stats.get('per_node_failed')})"
    print(
        f"mutant (guard of {changed.source} -> {changed.target} dropped): per node "
        f"{said} in {seconds:.2f} s"
    )
    signal.alarm(args.limit)
    try:
        started = time.perf_counter()
        report = verify(doc, mutant)
        signal.alarm(0)
        traces = [p.counterexample for p in report.properties.values() if p.counterexample]
        found = (
            f"found ({report.method}), counterexample of {min(len(t) for t in traces)} steps; "
            + "; ".join(a for a in report.abstractions if "shortest" in a.split(":")[0])
            if not report.equivalent and traces
            else ("not equivalent" if not report.equivalent else "EQUIVALENT")
        )
        spent = report.stats.get("lower_bound_seconds")
        bound = "" if spent is None else f" (of which the lower bound {spent:.2f} s)"
        print(f"verify: {found} in {time.perf_counter() - started:.2f} s{bound}")
    except _Timeout:
        print(f"verify: not found within {args.limit} s")
    except InputError as exc:
        signal.alarm(0)
        print(f"verify: stopped ({str(exc)[:100]})")
    return 0


def _compositional_table(args: argparse.Namespace) -> int:
    """One row per tree: the conversion's time, then the compositional check's (its regions,
    the largest region's product, the sum of the products, its seconds) or why it falls back,
    then the whole product's (states and seconds, or why it stopped)."""
    header = (
        f"{'family':<14} {'nodes':>6} {'conv s':>7} {'regions':>7} {'largest':>8} "
        f"{'comp st':>8} {'comp s':>7} {'whole st':>9} {'whole s':>9}"
    )
    print(header)
    print("-" * len(header))
    for family in args.families.split(","):
        for size in (int(s) for s in args.sizes.split(",")):
            doc = family_tree(family, leaves_for(size), size)
            nodes = node_count(doc)
            signal.alarm(args.limit)
            try:
                started = time.perf_counter()
                hfsm = bt_to_hfsm(doc).model
                converted = time.perf_counter() - started
                signal.alarm(0)
            except (_Timeout, InputError) as exc:
                signal.alarm(0)
                why = f"over {args.limit} s" if isinstance(exc, _Timeout) else "state limit"
                print(f"{family:<14} {nodes:>6}  conversion stopped: {why}", flush=True)
                break
            signal.alarm(args.limit)
            try:
                started = time.perf_counter()
                proved, why = compositional_report(doc, hfsm)
                comp_seconds = time.perf_counter() - started
                signal.alarm(0)
            except _Timeout:
                proved, why, comp_seconds = None, f"over {args.limit} s", 0.0
            whole_states, whole_seconds = _whole_check(doc, hfsm, args.limit)
            if proved is None:
                comp = f"{'falls back: ' + why[:40]:>41}"
            else:
                st = proved.stats
                comp = (
                    f"{st['regions']:>7} {st['largest_region']:>8} {st['product_states']:>8} "
                    f"{comp_seconds:>7.3f}"
                )
            print(
                f"{family:<14} {nodes:>6} {converted:>7.3f} {comp} {whole_states:>9} "
                f"{whole_seconds:>9}",
                flush=True,
            )
    print(
        "conv s = bt_to_hfsm (explores each region); comp = fsmbt.verify.compositional "
        "(regions alone + the skeleton); whole = the explicit product of the two machines"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
