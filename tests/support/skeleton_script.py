"""Scripted leaf outcomes by label, the same in fsmbt's interpreter and in generated skeletons.

The skeleton tests replace the user's leaf classes with classes that return, at the k-th tick
of the leaf labelled L, the k-th outcome of L's plan (cycled). Plans are seeded by (seed,
label); conditions never return ``running``. ``write`` saves the plans as the text file the
scripted C++ and Python classes read (one line per label: ``label outcome...``), ``run_interpreter``
runs the tree in ``BTRunner`` with the same plans and returns, per tick, the leaves ticked and
the root's result - what the skeleton's run must print.
"""

from __future__ import annotations

import random
from pathlib import Path

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.bt_interpreter import BTRunner

Trace = list[tuple[list[tuple[str, str]], str]]  # per tick: (label, outcome) leaves, root status


def plans(doc: BTDocument, seed: int, length: int = 6) -> dict[str, list[str]]:
    """label -> outcomes, for every non-built-in leaf of every tree of ``doc``."""
    found: dict[str, list[str]] = {}
    for tree in doc.trees.values():
        for node in tree.root.walk() if tree.root is not None else ():
            if not node.is_leaf or node.is_builtin or node.label in found:
                continue
            rng = random.Random(f"{seed}:{node.label}")
            condition = node.kind is NodeKind.CONDITION
            found[node.label] = [
                "running"
                if not condition and rng.random() < 0.3
                else rng.choice(["success", "failure"])
                for _ in range(length)
            ]
    return found


def write(path: Path, script: dict[str, list[str]]) -> Path:
    path.write_text(
        "".join(f"{label} {' '.join(outcomes)}\n" for label, outcomes in script.items()),
        encoding="utf-8",
    )
    return path


def run_interpreter(
    doc: BTDocument, script: dict[str, list[str]], ticks: int, *, exactly_once: bool
) -> Trace:
    """Tick ``doc`` up to ``ticks`` times (stopping when the root is not RUNNING)."""
    count: dict[str, int] = {}

    def env(node: BTNode, path: str) -> str:
        index = count.get(node.label, 0)
        count[node.label] = index + 1
        plan = script[node.label]
        return plan[index % len(plan)]

    runner = BTRunner(doc, env, exactly_once=exactly_once)
    trace: Trace = []
    for _ in range(ticks):
        record = runner.tick_once()
        trace.append(([(label, outcome) for label, _, outcome in record.leaves], record.result))
        if record.result != "RUNNING":
            break
    return trace


def parse_run(stdout: str) -> Trace:
    """The trace a skeleton's main printed: ``leaf L O`` lines, then ``tick k: STATUS``."""
    trace: Trace = []
    leaves: list[tuple[str, str]] = []
    for line in stdout.splitlines():
        if line.startswith("leaf "):
            _, label, outcome = line.split(" ")
            leaves.append((label, outcome))
        elif line.startswith("tick "):
            trace.append((leaves, line.split(": ", 1)[1].strip()))
            leaves = []
    return trace
