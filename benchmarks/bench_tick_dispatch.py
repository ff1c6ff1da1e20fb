"""How long the BT interpreter takes per node tick, on a tree that uses many node families (the
tick dispatch of docs/semantics.md §9a). Prints one line: best-of-R microseconds per tick.

    .venv/bin/python benchmarks/bench_tick_dispatch.py [--ticks 3000] [--repeat 7]

The environment answers from a fixed pseudo-random sequence (seeded), so two checkouts run the
same ticks; compare two checkouts by running this with each one's ``src`` on ``PYTHONPATH``,
alternately, on the same machine.
"""

from __future__ import annotations

import argparse
import random
import time

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import BTRunner


def _leaf(name: str, condition: bool = False) -> BTNode:
    return BTNode(name, NodeKind.CONDITION if condition else NodeKind.ACTION, name=name)


def _node(kind: str, node_kind: NodeKind, *children: BTNode, **attrs: str) -> BTNode:
    return BTNode(kind, node_kind, attrs=dict(attrs), children=list(children))


def tree() -> BTDocument:
    """Sequence, Fallback, ReactiveSequence, Parallel, Repeat, Retry, Inverter, IfThenElse."""
    c, d = NodeKind.CONTROL, NodeKind.DECORATOR
    branch = _node(
        "Fallback",
        c,
        _node("Inverter", d, _leaf("c1", True)),
        _node("Repeat", d, _node("Sequence", c, _leaf("a1"), _leaf("a2")), num_cycles="2"),
        _node(
            "RetryUntilSuccessful",
            d,
            _node("Sequence", c, _leaf("a3"), _leaf("a4")),
            num_attempts="2",
        ),
    )
    root = _node(
        "ReactiveSequence",
        c,
        _leaf("c0", True),
        _node("IfThenElse", c, _leaf("c2", True), branch, _leaf("a5")),
        _node("Parallel", c, _leaf("a6"), _leaf("a7"), success_count="1", failure_count="1"),
    )
    return BTDocument.single(root)


def run(ticks: int) -> tuple[float, int]:
    rng = random.Random(25)
    answers = [rng.choice(["success", "success", "failure", "running"]) for _ in range(4096)]
    position = [0]

    def env(node: BTNode, path: str) -> str:
        position[0] += 1
        outcome = answers[position[0] % len(answers)]
        return "failure" if outcome == "running" and node.kind is NodeKind.CONDITION else outcome

    runner = BTRunner(tree(), env)
    started = time.perf_counter()
    for _ in range(ticks):
        runner.tick_once()
    return time.perf_counter() - started, position[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--ticks", type=int, default=3000)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    best = min(run(args.ticks)[0] for _ in range(args.repeat))
    leaves = run(args.ticks)[1]
    print(
        f"{args.ticks} tree ticks, {leaves} leaf ticks: best of {args.repeat} "
        f"{best * 1000:.1f} ms, {best / args.ticks * 1e6:.1f} us per tree tick"
    )


if __name__ == "__main__":
    main()
