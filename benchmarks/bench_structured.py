"""The structured style against the LEBT and BSD on outcome-driven machines (prints tables; not
a test). docs/conversion.md, "The structured style", holds its output.

Inputs: the SMACH and FlexBE files of the shared corpus (``$FSMBT_CORPUS``, else
``../shared/corpus``; read as their formats say, events = outcomes) and 200 seeded generated
outcome-driven machines (``fsmbt.generate.outcome_machines``, 5-20 states, some containers).
For each machine: nodes and depth (levels, root = 1; the deepest ``<BehaviorTree>``) of the
structured tree, of the LEBT (``--style lebt``) and of the BSD baseline; whether the tree is
fully structured (no blackboard flag); its flags and LEBT blocks; the structured conversion's
time and the outcome pairing's proof time (CPU seconds, minimum of 3 runs). Every structured
tree must be proven equivalent; the script stops with an error otherwise.

Run: .venv/bin/python benchmarks/bench_structured.py [--quick]   (--quick: 40 generated)
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

from fsmbt.convert import convert
from fsmbt.convert.structured import fsm_to_structured
from fsmbt.convert.structured.convert import count_nodes
from fsmbt.formats import read_model
from fsmbt.generate.outcome_machines import random_outcome_fsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify

REPO = Path(__file__).resolve().parents[1]
CORPUS = Path(os.environ.get("FSMBT_CORPUS", REPO / ".." / "shared" / "corpus")) / "fsm"


def cpu(func: Callable[[], object], repeats: int = 3) -> tuple[float, object]:
    best, value = float("inf"), None
    for _ in range(repeats):
        start = time.process_time()
        value = func()
        best = min(best, time.process_time() - start)
    return best, value


def size(doc: object) -> tuple[int, int] | None:
    if not isinstance(doc, BTDocument):
        return None
    counts = count_nodes(doc)
    return counts["nodes"], counts["depth"]


def other(fsm: FSM, **options: object) -> tuple[int, int] | None:
    try:
        return size(convert(fsm, **options).model)
    except Exception:  # noqa: BLE001 - a baseline that refuses the machine: shown as "-"
        return None


def measure(name: str, fsm: FSM) -> dict[str, object]:
    seconds, result = cpu(lambda: fsm_to_structured(fsm))
    proof, report = cpu(lambda: verify(fsm, result.model, outcome_driven=True))  # type: ignore[attr-defined]
    if not report.equivalent:  # type: ignore[attr-defined]
        raise SystemExit(f"{name}: the structured tree is NOT proven equivalent")
    stats = result.stats  # type: ignore[attr-defined]
    return {
        "name": name,
        "states": sum(1 for _p, _m, s in fsm.walk() if not s.final),
        "structured": (stats["nodes"], stats["depth"]),
        "lebt": other(fsm, style="lebt"),
        "bsd": other(fsm, engine="bsd"),
        "full": stats["fully_structured"],
        "flags": stats["flags"],
        "lebt_blocks": stats["lebt_blocks"],
        "convert_s": seconds,
        "proof_s": proof,
    }


def cell(pair: object) -> str:
    return "-" if pair is None else f"{pair[0]} / {pair[1]}"  # type: ignore[index]


def table(rows: list[dict[str, object]]) -> None:
    print(
        "| machine | states | structured nodes / depth | LEBT | BSD | flags | convert ms | proof ms |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['name']} | {r['states']} | {cell(r['structured'])} | {cell(r['lebt'])} | "
            f"{cell(r['bsd'])} | {r['flags']} | {1000 * r['convert_s']:.1f} | "  # type: ignore[operator]
            f"{1000 * r['proof_s']:.1f} |"  # type: ignore[operator]
        )


def summary(label: str, rows: list[dict[str, object]]) -> None:
    def mean(key: str, index: int) -> str:
        values = [r[key][index] for r in rows if r[key] is not None]  # type: ignore[index]
        return f"{statistics.mean(values):.1f}" if values else "-"

    full = sum(1 for r in rows if r["full"])
    flags = [int(r["flags"]) for r in rows]  # type: ignore[call-overload]
    conv = [float(r["convert_s"]) for r in rows]  # type: ignore[arg-type]
    proof = [float(r["proof_s"]) for r in rows]  # type: ignore[arg-type]
    print(
        f"| {label} | {len(rows)} | {mean('structured', 0)} / {mean('structured', 1)} | "
        f"{mean('lebt', 0)} / {mean('lebt', 1)} | {mean('bsd', 0)} / {mean('bsd', 1)} | "
        f"{100 * full / len(rows):.0f} % | {statistics.mean(flags):.2f} (max {max(flags)}) | "
        f"{sum(int(r['lebt_blocks']) for r in rows)} | "  # type: ignore[call-overload]
        f"{1000 * statistics.mean(conv):.1f} (max {1000 * max(conv):.1f}) | "
        f"{1000 * statistics.mean(proof):.1f} (max {1000 * max(proof):.1f}) |"
    )


def main() -> None:
    quick = "--quick" in sys.argv
    files = sorted(
        [*CORPUS.glob("smach_tutorials/*.py"), *CORPUS.glob("smach_tests/*.py"),
         *CORPUS.glob("flexbe_turtlesim_demo/*_sm.py")]
    )  # fmt: skip
    corpus = [measure(f"{p.parent.name}/{p.name}", read_model(p)) for p in files]
    count = 40 if quick else 200
    generated = [
        measure(f"gen {seed}", random_outcome_fsm(seed, states=5 + seed % 16))
        for seed in range(count)
    ]
    print("### Corpus SMACH/FlexBE files (nodes / depth; CPU ms, min of 3)\n")
    table(corpus)
    print(
        "\n### Means (nodes / depth); share fully structured; flags and LEBT blocks per machine\n"
    )
    print("| set | machines | structured | LEBT | BSD | fully structured | flags per machine | "
          "LEBT blocks | convert ms | proof ms |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    summary("corpus SMACH/FlexBE", corpus)
    summary(f"generated ({count}, 5-20 states)", generated)


if __name__ == "__main__":
    main()
