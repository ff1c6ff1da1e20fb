"""Seeded random trees over every kind the per-node conversion writes (``convert/bt_pernode``),
for its property tests: the controls of the sequence and reactive families (with memory,
asynchronous), the status maps and the loop decorators with small counts and -1.

``pernode_tree(leaves, seed)``: groups of 2-3 nodes under a random control (Parallel and
ParallelAll with random thresholds among them), bottom-up (no
recursion), 40 % conditions, and each node wrapped in a random decorator with probability 0.25.
``family_tree`` of ``benchmarks/bench_reactive.py`` gives the bench families; this one covers
the kinds those families lack (Async*, KeepRunningUntilFailure, counts 1, 3 and -1).
``seeded_trees(count, seed)`` mixes the two: the sample the per-node and lift tests share.
"""

from __future__ import annotations

import random
import sys
from pathlib import Path

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind

CONTROLS = (
    "Sequence",
    "Fallback",
    "ReactiveSequence",
    "ReactiveFallback",
    "SequenceWithMemory",
    "AsyncSequence",
    "AsyncFallback",
    "Parallel",
    "ParallelAll",
)
DECORATORS: tuple[tuple[str, dict[str, str]], ...] = (
    ("Inverter", {}),
    ("ForceSuccess", {}),
    ("ForceFailure", {}),
    ("KeepRunningUntilFailure", {}),
    ("RetryUntilSuccessful", {"num_attempts": "1"}),
    ("RetryUntilSuccessful", {"num_attempts": "2"}),
    ("RetryUntilSuccessful", {"num_attempts": "3"}),
    ("RetryUntilSuccessful", {"num_attempts": "-1"}),
    ("Repeat", {"num_cycles": "1"}),
    ("Repeat", {"num_cycles": "2"}),
    ("Repeat", {"num_cycles": "-1"}),
)


def _decorated(node: BTNode, rng: random.Random) -> BTNode:
    if rng.random() >= 0.25:
        return node
    kind, ports = rng.choice(DECORATORS)
    return BTNode(kind, NodeKind.DECORATOR, attrs=dict(ports), children=[node])


def _ports(control: BTNode, rng: random.Random) -> None:
    """A Parallel's thresholds (1, all, "all but one" as -2) and ParallelAll's max_failures,
    within its children (they may still grow by one: counts stay valid)."""
    if control.type == "Parallel":
        control.attrs = {
            "success_count": rng.choice(("1", "-1", "2")),
            "failure_count": rng.choice(("1", "-1", "2")),
        }
    elif control.type == "ParallelAll":
        control.attrs = {"max_failures": rng.choice(("1", "2", "-1"))}


def pernode_tree(leaves: int, seed: int) -> BTDocument:
    """A random tree of ``leaves`` leaves over ``CONTROLS`` and ``DECORATORS`` (see above)."""
    rng = random.Random(seed)
    level: list[BTNode] = []
    for i in range(leaves):
        kind = NodeKind.CONDITION if rng.random() < 0.4 else NodeKind.ACTION
        leaf = BTNode("Check" if kind is NodeKind.CONDITION else "Do", kind, name=f"L{i}")
        level.append(_decorated(leaf, rng))
    while len(level) > 1:
        controls: list[BTNode] = []
        i = 0
        while i < len(level):
            k = min(rng.randint(2, 3), len(level) - i)
            if k == 1:
                controls[-1].children.append(level[i])
                i += 1
                continue
            controls.append(
                BTNode(rng.choice(CONTROLS), NodeKind.CONTROL, children=level[i : i + k])
            )
            _ports(controls[-1], rng)
            i += k
        level = [_decorated(control, rng) for control in controls]
    root = level[0]
    if root.is_leaf or root.kind is NodeKind.DECORATOR:
        root = BTNode(rng.choice(CONTROLS), NodeKind.CONTROL, children=[root])
    return BTDocument.single(root)


#: The bench families of the sample, in the order that fixes which tree each index draws.
SAMPLE_FAMILIES = ("memory", "mixed", "reactive-plain", "decorated")


def seeded_trees(count: int, seed: int) -> list[BTDocument]:
    """``count`` small trees (2-10 leaves): odd indices ``pernode_tree`` (at most 7 leaves: a
    Parallel's product of completed sets grows fast), even ones the bench families in turn."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from bench_reactive import family_tree

    rng = random.Random(seed)
    found = []
    for index in range(count):
        leaves = rng.randint(2, 10)
        if index % 2:
            found.append(pernode_tree(min(leaves, 7), seed * 10_000 + index))
        else:
            family = SAMPLE_FAMILIES[(index // 2) % len(SAMPLE_FAMILIES)]
            found.append(family_tree(family, leaves, seed * 10_000 + index))
    return found
