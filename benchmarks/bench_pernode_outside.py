"""Why one-transition mutants of per-node results fall *outside* the per-node check (issue 27;
docs/nusmv.md "Trees node by node", docs/verification.md §5). Prints one line per category.

    .venv/bin/python benchmarks/bench_pernode_outside.py [--sizes 100,1000] [--trees 2]
        [--first-seed 1] [--mutants 40] [--families memory,mixed,reactive-plain,decorated]
        [--budget 5] [--cap 900] [--details]

The sample is ``bench_nusmv_pernode.py``'s (same trees, same ``random.Random(seed * 1000 +
size)`` per tree, same ``tests/support/pernode_mutants.mutate``), so its *outside* column counts
the mutants classified here. Each mutant is decided by ``compositional.decompose`` (region
checked whole with ``--budget`` seconds and ``MUTANT_STATES`` states, as that bench does); a
mutant whose per-node region the per-node check refused (``CheckPlan.refused``) is *outside*,
classified by the side condition ``NotPerNode`` named (docs/semantics.md §4d: states, entries,
data, the root's interface) and by the mutation (the transition changed: operator, the nodes
its source and targets are tagged with).

Per category: the count, the operators, the type of the node the refusal names, and the size
of the smallest *pocket* that would contain the change: the lowest common ancestor of the
nodes the changed transition's source and (old and new) targets belong to, as nodes of the
region (``pocket nodes``, median and max, and its share of the region) - what a whole check of
that pocket instead of the region would cost. Then the native seconds and verdicts of the
region checked whole for those mutants (``NOT eq``, ``eq`` or ``undecided``: past the budget or
the state cap). Last, the mutants the per-node check refuted past a broken entry condition
(``pernode.check_region``'s ``tolerate``: a candidate lifted and replayed on the whole
machines; they are not outside) and their native seconds. ``--details`` prints one line per
outside mutant.
"""

from __future__ import annotations

import argparse
import os
import random
import re
import signal
import statistics
import sys
import time
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from bench_reactive import family_tree, leaves_for, node_count  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.convert.compress import inline_and_compress  # noqa: E402
from fsmbt.model.bt import BTDocument  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402
from fsmbt.model.fsm import FSM  # noqa: E402
from fsmbt.model.fsm_data import ASSIGN, COND  # noqa: E402
from fsmbt.semantics.bt_interpreter import CompiledTree  # noqa: E402
from fsmbt.verify.compositional import (  # noqa: E402
    CheckPlan,
    NotDecomposable,
    decompose,
    structure,
)
from fsmbt.verify.pernode import NODE_ATTR  # noqa: E402
from support.pernode_mutants import mutate, pernode_machine  # noqa: E402

NATIVE_STATES = 1_000  # bench_nusmv_pernode.MUTANT_STATES

#: NotPerNode's messages (verify/pernode.py) as categories: (pattern, category). The first
#: group, when there is one, is the node the message names.
CATEGORIES: tuple[tuple[str, str], ...] = (
    (r"node (.+) is entered twice", "entries: a node entered at two states"),
    (r"a transition of (.+) enters a child not at its entry", "entries: a child entered inside"),
    (r"the region's initial state is not a node's", "entries: initial state"),
    (r"variable (.+) is reset to two values", "data: two halt values"),
    (r"(.+) halts child \d+ partly", "data: a child halted partly"),
    (r"(.+) assigns (.+) of a descendant", "data: a descendant's variable assigned"),
    (r"a variable outside the node is assigned inside its tick", "data: outside var in a tick"),
    (r"variable (.+) is read by two nodes", "data: read by two nodes"),
    (r"leaf (.+)'s state has other transitions", "states: a leaf's transitions"),
    (r"state (.+) is not a transient state", "states: not transient"),
    (r"a transient state has no enabled transition", "states: no enabled transition"),
    (r"an eventless cycle without a leaf", "states: eventless cycle"),
    (r"the region's root returns (.+) elsewhere", "root interface"),
    (r"the local problem of (.+) passes", "local limit"),
)


def category(reason: str) -> tuple[str, str | None]:
    """(category, the name the message names or ``None``)."""
    for pattern, name in CATEGORIES:
        found = re.search(pattern, reason)
        if found:
            return name, found.group(1) if found.groups() else None
    return "other: " + reason, None


@dataclass
class Change:
    """The transition ``mutate`` changed: operator and the node paths of its source, old
    target and new target (``None``: a final state)."""

    operator: str
    source: str | None
    old: str | None
    new: str | None


def changed(model: FSM, mutant: FSM) -> Change:
    before, after = pernode_machine(model), pernode_machine(mutant)
    assert before is not None and after is not None

    def tag(machine: FSM, name: str) -> str | None:
        return machine.states[name].attrs.get(NODE_ATTR)

    for t0, t1 in zip(before.transitions, after.transitions, strict=True):
        if t0.target != t1.target:
            op = "retarget"
        elif t0.attrs.get(COND) != t1.attrs.get(COND):
            op = "guard"
        elif t0.attrs.get(ASSIGN) != t1.attrs.get(ASSIGN):
            op = "assignment"
        else:
            continue
        return Change(op, tag(before, t0.source), tag(before, t0.target), tag(after, t1.target))
    return Change("none", None, None, None)


def lca(paths: list[str | None]) -> str:
    """The common prefix of node paths (``a/b/c``; ``""`` is the region's root)."""
    parts = [p.split("/") if p else [] for p in paths if p is not None]
    if not parts:
        return ""
    common: list[str] = []
    for items in zip(*parts):
        if len(set(items)) != 1:
            break
        common.append(items[0])
    return "/".join(common)


class Region:
    """The region's merged tree (as ``pernode.NodeWalk`` compiles it): subtree sizes and
    types by path, ids by label."""

    def __init__(self, doc: BTDocument, model: FSM) -> None:
        shape = structure(doc, model)
        sub = pernode_machine(model)
        index = next(j for j, r in enumerate(shape.machine_regions) if r.machine is sub)
        label = shape.machine_regions[index].path.split("/")[-1].split("#")[0]
        roots = [n for n in shape.regions if n.label == label] or shape.regions[:1]
        merged = inline_and_compress(BTDocument.single(roots[0])).compression.root
        tree = CompiledTree(BTDocument.single(merged))
        self.nodes = len(tree.nodes)
        size = [1] * len(tree.nodes)
        for node in reversed(tree.nodes):
            for c in node.children:
                size[node.id] += size[c]
        self.size = {node.path: size[node.id] for node in tree.nodes}
        self.type = {node.path: node.type for node in tree.nodes}
        self.by_label = {node.label: node.path for node in tree.nodes}


class _Stop(Exception):
    pass


def _alarm(_signum, _frame):  # type: ignore[no-untyped-def]
    raise _Stop


def decide(doc: BTDocument, mutant: FSM, budget: float) -> tuple[CheckPlan, str, float]:
    """``decompose`` as bench_nusmv_pernode runs it: the plan, the verdict and the seconds."""
    plan = CheckPlan()
    started = time.perf_counter()
    try:
        with limits.changed(conversion_max_states=NATIVE_STATES):
            found = decompose(doc, mutant, plan=plan, max_states=NATIVE_STATES, max_seconds=budget)
        verdict = "eq" if found.equivalent else "NOT eq"
        if found.lifted is not None:  # a candidate past a broken entry, confirmed by replay
            verdict = "NOT eq (per node past a broken entry)"
    except (NotDecomposable, FsmbtError) as exc:
        verdict = "undecided: " + _why(exc)
    return plan, verdict, time.perf_counter() - started


def _why(exc: Exception) -> str:
    """Why the region's whole check did not decide, without the names (a category)."""
    text = str(exc)
    if isinstance(exc, NotDecomposable):
        text = re.sub(r"^region \S+: ", "", text)
        text = re.sub(r"region \S+ ends in", "region ends in", text)
        text = re.sub(r"\d[\d.,]*", "N", text)
        return text[:60]
    return type(exc).__name__


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default="100,1000")
    parser.add_argument("--trees", type=int, default=2)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--mutants", type=int, default=40)
    parser.add_argument("--families", default="memory,mixed,reactive-plain,decorated")
    parser.add_argument("--budget", type=float, default=5.0)
    parser.add_argument("--cap", type=int, default=900)
    parser.add_argument("--details", action="store_true")
    args = parser.parse_args()
    signal.signal(signal.SIGALRM, _alarm)
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} (1, 5 min)", flush=True)
    for size in [int(x) for x in args.sizes.split(",")]:
        rows: dict[str, list[dict[str, object]]] = defaultdict(list)
        pairs = inside = 0
        past: list[float] = []  # seconds of each mutant refuted past a broken entry
        for family in args.families.split(","):
            for seed in range(args.first_seed, args.first_seed + args.trees):
                doc = family_tree(family, leaves_for(size), seed)
                model = bt_to_hfsm(doc, pernode=True).model
                region = Region(doc, model)
                rng = random.Random(seed * 1000 + size)
                signal.alarm(args.cap)
                try:
                    for _ in range(args.mutants):
                        mutant = mutate(model, rng)
                        if mutant is None:
                            break
                        pairs += 1
                        plan, verdict, seconds = decide(doc, mutant, args.budget)
                        if not plan.refused:
                            inside += 1
                            if verdict.startswith("NOT eq (per node past"):
                                past.append(seconds)
                            continue
                        row = _row(region, model, mutant, plan, verdict, seconds)
                        row["tree"] = f"{family} {node_count(doc)} seed {seed}"
                        rows[str(row["category"])].append(row)
                        if args.details:
                            print("  ", row, flush=True)
                except _Stop:
                    print(f"  {family} seed {seed}: stopped after {args.cap} s", flush=True)
                finally:
                    signal.alarm(0)
        _report(size, pairs, inside, rows)
        if past:
            print(
                f"decided per node past a broken entry (lifted, replayed): {len(past)}, native s "
                f"med/max {statistics.median(past):.2f}/{max(past):.2f}"
            )
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} (1, 5 min)")
    return 0


def _row(
    region: Region, model: FSM, mutant: FSM, plan: CheckPlan, verdict: str, seconds: float
) -> dict[str, object]:
    reason = plan.refused[0][1]
    name, named = category(reason)
    change = changed(model, mutant)
    named_path = region.by_label.get(named or "")
    pocket = lca([change.source, change.old, change.new])
    return {
        "category": name,
        "operator": change.operator,
        "named": region.type.get(named_path, "-") if named_path is not None else "-",
        "pocket": region.size.get(pocket, region.nodes),
        "share": region.size.get(pocket, region.nodes) / region.nodes,
        "verdict": verdict,
        "seconds": seconds,
        "reason": reason,
    }


def _report(size: int, pairs: int, inside: int, rows: dict[str, list[dict[str, object]]]) -> None:
    outside = sum(len(r) for r in rows.values())
    print(
        f"\n~{size} nodes: {pairs} mutants, {inside} decided per node, {outside} outside "
        f"({100 * outside / max(pairs, 1):.0f} %)"
    )
    header = (
        "category", "n", "operators", "node named", "pocket nodes med/max", "pocket share med",
        "native s med/max", "native verdicts",
    )  # fmt: skip
    print(" | ".join(header))
    for name, items in sorted(rows.items(), key=lambda kv: -len(kv[1])):
        ops = Counter(str(r["operator"]) for r in items)
        named = Counter(str(r["named"]) for r in items)
        pockets = [int(str(r["pocket"])) for r in items]
        shares = [float(str(r["share"])) for r in items]
        secs = [float(str(r["seconds"])) for r in items]
        verdicts = Counter(str(r["verdict"]) for r in items)
        print(
            " | ".join(
                [
                    name,
                    str(len(items)),
                    ", ".join(f"{k} {v}" for k, v in ops.most_common()),
                    ", ".join(f"{k} {v}" for k, v in named.most_common(3)),
                    f"{statistics.median(pockets):.0f}/{max(pockets)}",
                    f"{100 * statistics.median(shares):.0f} %",
                    f"{statistics.median(secs):.2f}/{max(secs):.2f}",
                    ", ".join(f"{k} {v}" for k, v in verdicts.most_common()),
                ]
            ),
            flush=True,
        )


if __name__ == "__main__":
    sys.exit(main())
