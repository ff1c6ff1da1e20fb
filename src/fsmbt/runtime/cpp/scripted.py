"""Run any BehaviorTree.CPP v4 tree in the C++ driver with every leaf scripted, logging it with
BehaviorTree.CPP 4.8.2's own loggers (docs/conform.md, 'Recording a run in C++').

``record_scripted`` calls ``fsmbt_lebt_driver TREE --scripted SEED`` (docs/runtime.md): every
condition type of the tree returns SUCCESS or FAILURE, every action type (a stateful action)
SUCCESS, FAILURE or RUNNING, drawn uniformly from one ``std::mt19937(SEED)``; the root is ticked
``ticks`` times with ``tickOnce``; ``--btlog`` attaches ``FileLogger2``, ``--db3``
``SqliteLogger``. The tree is read with fsmbt only to list its leaf types; nothing of it is
executed in Python. Costs: one process, the engine's ticks (the SQLite logger commits every
transition on its own: about 10^4 transitions per second).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

from fsmbt import api
from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.runtime.cpp import CppRuntimeError, require_driver

#: Wall seconds one recording may take.
TIMEOUT = 120


def leaf_types(doc: BTDocument) -> tuple[list[str], list[str]]:
    """The condition and the action types of ``doc`` that are not BehaviorTree.CPP built-ins,
    sorted."""
    conditions, actions = set(), set()
    for _tree, node in doc.nodes():
        if node.is_builtin:
            continue
        if node.kind is NodeKind.CONDITION:
            conditions.add(node.type)
        elif node.kind is NodeKind.ACTION:
            actions.add(node.type)
    return sorted(conditions), sorted(actions)


def record_scripted(
    tree: Path,
    *,
    seed: int,
    ticks: int,
    btlog: Path | None = None,
    db3: Path | None = None,
) -> list[str]:
    """Run ``tree`` scripted in the C++ driver, logging to ``btlog`` and/or ``db3`` (a ``.db3``
    is replaced); returns the root status of each tick (``SUCCESS``, ``FAILURE``, ``RUNNING``).

    Raises:
        CppRuntimeError: the driver is not built, or fails on the tree (its message).
        InputError: the tree does not load in fsmbt.
    """
    driver = require_driver()
    doc = api.load(tree).model
    if not isinstance(doc, BTDocument):
        raise CppRuntimeError(f"{tree}: not a behavior tree")
    conditions, actions = leaf_types(doc)
    command = [str(driver), str(tree), "--scripted", str(seed), "--ticks", str(ticks)]
    command += ["--conditions", ",".join(conditions), "--actions", ",".join(actions)]
    if btlog is not None:
        command += ["--btlog", str(btlog)]
    if db3 is not None:
        Path(db3).unlink(missing_ok=True)
        command += ["--db3", str(db3)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT, check=False)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        raise CppRuntimeError(f"{tree}: the C++ driver failed: {last}")
    return [str(json.loads(line)["status"]) for line in done.stdout.splitlines()]
