"""Figures for docs/diff.md, docs/conform.md and docs/testgen.md (issue 28), printed as Markdown.

    .venv/bin/python benchmarks/bench_after.py [--part diff|conform|testgen|all] [--models 200]

- diff: the time of ``fsmbt.diff.diff_models`` (behaviour + edit script) of each example model
  against its first mutant that behaves differently, and on random trees of about 1 000 nodes
  (depth 12, breadth 10, a 1 000-node budget) against a
  copy with two children of one control node swapped (seeded), median of 3 runs;
- conform: a 10^6-transition ``.btlog`` recorded by BehaviorTree.CPP 4.8.2 (behaviortreepy,
  scripted leaves) of the paper's robot tree, read and replayed: transitions per second (read,
  replay, both);
- testgen: suite size (cases, scripted leaf ticks), transitions covered and mutation score over
  the example trees (specification: the tree itself, and for the robot tree its HFSM) and over
  ``--models`` random trees (``fsmbt.generate.random_bt``, seeds 0..N-1, at most 40 nodes).
"""

from __future__ import annotations

import argparse
import copy
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from fsmbt import api, conform, diff, testgen
from fsmbt.conform.record import record_btlog
from fsmbt.generate import random_bt
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError
from fsmbt.verify import verify
from fsmbt.verify.mutations import mutants

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
MODEL_FILES = [
    "paper_fsm.xml",
    "robot_bt.xml",
    "game_npc_bt.xml",
    "prey_bt.xml",
    "door_hfsm.scxml",
    "predator_fsm.scxml",
    "turnstile.mmd",
]


def _median_seconds(run, repeat: int = 3) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        run()
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def part_diff() -> None:
    print("| model | kind | groups | edits | diff time |")
    print("|---|---|---|---|---|")
    for name in MODEL_FILES:
        model = api.load(EXAMPLES / name).model
        other = next(
            (m.model for m in mutants(model, seed=0) if not verify(model, m.model).equivalent),
            None,
        )
        if other is None:
            continue
        report = diff.diff_models(model, other)
        seconds = _median_seconds(lambda m=model, o=other: diff.diff_models(m, o))
        kind = api.model_kind(model).upper()
        edits = len(report.script or [])
        groups = report.behaviour.total_groups
        print(f"| {name} | {kind} | {groups} | {edits} | {seconds * 1000:.1f} ms |")
    print()
    print("| random tree (seed) | nodes | groups | edits | diff time |")
    print("|---|---|---|---|---|")
    for seed in range(3):
        doc = random_bt(seed, depth=12, breadth=10, max_nodes=1000)
        size = sum(1 for _ in doc.nodes())
        changed = copy.deepcopy(doc)
        controls = [n for _t, n in changed.nodes() if len(n.children) >= 2]
        target = controls[len(controls) // 2]
        target.children[0], target.children[1] = target.children[1], target.children[0]
        report = diff.diff_models(doc, changed)
        seconds = _median_seconds(lambda d=doc, c=changed: diff.diff_models(d, c))
        edits = len(report.script or [])
        groups = report.behaviour.total_groups
        print(f"| {seed} | {size} | {groups} | {edits} | {seconds * 1000:.0f} ms |")


def part_conform(events: int = 1_000_000) -> None:
    robot = EXAMPLES / "robot_bt.xml"
    doc = api.load(robot).model
    xml = robot.read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory() as tmp:
        log_path = Path(tmp) / "run.btlog"
        ticks = events // 13  # about 14 transitions per tick on this tree: past 10^6
        started = time.perf_counter()
        record_btlog(doc, xml, log_path, seed=0, ticks=ticks)
        recorded = time.perf_counter() - started
        started = time.perf_counter()
        log = conform.read_log(log_path)
        read = time.perf_counter() - started
        started = time.perf_counter()
        report = conform.conform(doc, [log])
        replayed = time.perf_counter() - started
        n = len(log)
        print(
            "| log | transitions | leaf ticks | record (BT.CPP) | read | replay | read + replay |"
        )
        print("|---|---|---|---|---|---|---|")
        [result] = report.results
        verdict = "conforms" if result.conforms else "DEVIATES"
        print(
            f"| robot_bt.xml, {ticks} ticks ({verdict}) | {n} | {result.leaf_ticks} | "
            f"{recorded:.1f} s | {n / read:,.0f} /s | {n / replayed:,.0f} /s | "
            f"{n / (read + replayed):,.0f} /s |"
        )


def _suite_row(spec: api.Model, tree: BTDocument) -> tuple[int, int, int, int, int, int]:
    suite = testgen.generate(spec)
    killed, found = testgen.mutation_score(tree, suite, per_operator=2)
    return len(suite.cases), suite.steps, suite.covered, suite.targets, killed, len(found)


def part_testgen(models: int) -> None:
    print("| specification | tree | cases | leaf ticks | transitions covered | mutants killed |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        hfsm = Path(tmp) / "robot.scxml"
        robot = api.load(EXAMPLES / "robot_bt.xml").model
        result = api.convert_model(robot)
        api.write(result.model, hfsm)
        pairs = [("robot_bt.xml (HFSM)", api.load(hfsm).model, "robot_bt.xml", robot)]
        for name in ("robot_bt.xml", "game_npc_bt.xml", "prey_bt.xml"):
            tree = api.load(EXAMPLES / name).model
            pairs.append((name, tree, name, tree))
        for spec_name, spec, tree_name, tree in pairs:
            assert isinstance(tree, BTDocument)
            cases, steps, covered, targets, killed, total = _suite_row(spec, tree)
            print(
                f"| {spec_name} | {tree_name} | {cases} | {steps} | {covered}/{targets} | "
                f"{killed}/{total} ({100 * killed / max(total, 1):.0f}%) |"
            )
    rows = []
    refused = 0
    started = time.perf_counter()
    for seed in range(models):
        doc = random_bt(seed, max_nodes=40)
        try:
            rows.append(_suite_row(doc, doc))
        except FsmbtError:
            refused += 1
    seconds = time.perf_counter() - started
    cases = [r[0] for r in rows]
    killed = sum(r[4] for r in rows)
    total = sum(r[5] for r in rows)
    covered = sum(r[2] for r in rows)
    targets = sum(r[3] for r in rows)
    print(
        f"| {len(rows)} random trees (seeds 0..{models - 1}, each its own specification"
        f"{f'; {refused} over the limits' if refused else ''}) | the tree | median "
        f"{statistics.median(cases):.0f}, max {max(cases)} | {sum(r[1] for r in rows)} in all | "
        f"{covered}/{targets} | {killed}/{total} ({100 * killed / max(total, 1):.1f}%) |"
    )
    print(f"\n({seconds:.0f} s for the {models} random trees: generation and mutation scores)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--part", choices=("diff", "conform", "testgen", "all"), default="all")
    parser.add_argument("--models", type=int, default=200)
    parser.add_argument("--events", type=int, default=1_000_000)
    args = parser.parse_args(argv)
    cores = os.cpu_count()
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"(machine: {cores} cores, load average {load} at the start)\n")
    if args.part in ("diff", "all"):
        print("## diff\n")
        part_diff()
        print()
    if args.part in ("conform", "all"):
        print("## conform\n")
        part_conform(args.events)
        print()
    if args.part in ("testgen", "all"):
        print("## testgen\n")
        part_testgen(args.models)
    return 0


if __name__ == "__main__":
    sys.exit(main())
