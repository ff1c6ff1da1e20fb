"""SCXML written per node (``convert/bt_pernode``; issue 27) runs in python-statemachine as
fsmbt proved it: the engine's configuration after each seeded leaf outcome is fsmbt's
(``FSMMachine`` over the machine's W3C meaning), the same leaf active, the same termination
(the oracle of ``test_rt_scxml_bt_differential.py``, ``scxml_oracle.replay``). The trees are
the per-node property test's (bench families and every kind written per node), converted with
``pernode=True``; counts are printed (``pytest -s``).
"""

from __future__ import annotations

import random
import sys
from pathlib import Path

from scxml_oracle import Engine, python_spelled, replay

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.formats import dumps
from fsmbt.semantics.machine import FSMMachine
from support.pernode_trees import pernode_tree

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402

FAMILIES = ("memory", "mixed", "reactive-plain", "decorated")


def test_pernode_scxml_runs_in_python_statemachine_as_proven() -> None:
    rng = random.Random(27)
    models = sequences = events = 0
    mismatches: list[str] = []
    for index in range(60):
        leaves = rng.randint(3, 7)
        doc = (
            pernode_tree(leaves, 500 + index)
            if index % 2
            else family_tree(FAMILIES[(index // 2) % 4], leaves, 500 + index)
        )
        result = bt_to_hfsm(doc, pernode=True)
        if not result.stats["pernode_regions"]:
            continue
        written = dumps(result.model, "scxml")
        text = python_spelled(written) or written
        Engine(text)  # loads at all
        machine = FSMMachine(result.model)
        models += 1
        for _ in range(4):
            found = replay(
                text,
                result.model,
                rng,
                length=25,
                machine=machine,
                alphabet=("success", "failure", "running"),
            )
            sequences += 1
            events += found.sent
            if found.mismatch is not None:
                mismatches.append(f"tree {index}: {found.mismatch}")
    print(f"\n[per-node scxml] {models} models, {sequences} sequences, {events} events")
    assert models >= 40 and not mismatches, mismatches[:3]
