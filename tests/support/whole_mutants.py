"""One-transition mutants of the results ``bt_to_hfsm`` writes whole (not per node): shared by
the compositional, lazy-runner and lift tests and ``benchmarks/bench_lift.py``.

``CONTROLS``/``DECORATORS``: the kinds of the compositional test's random trees (plain,
reactive and WithMemory controls; status maps and loop decorators). ``deep_mutants(hfsm,
seed, per_operator)``: single mutants (``fsmbt.verify.mutations``: retarget, drop, change an
action, flip a final flag) of one machine of ``hfsm`` - the top machine or any sub-machine,
so the regions' own transitions are mutated too. ``seeded_whole_mutants(...)``: seeded trees
converted whole, each with its model and mutants - the one sample of regions written whole.
"""

from __future__ import annotations

import copy
import random
from collections.abc import Iterator

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.verify.mutations import mutants
from support.random_trees import random_tree

CONTROLS = (
    "Sequence",
    "Fallback",
    "Sequence",
    "Fallback",
    "SequenceWithMemory",
    "ReactiveSequence",
    "ReactiveFallback",
)
DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "Repeat", "RetryUntilSuccessful")


def deep_mutants(
    hfsm: FSM, seed_value: int, per_operator: int | None, *, every_machine: bool = False
) -> list[FSM]:
    """Single mutants of one machine of ``hfsm`` - the top machine or any sub-machine, so the
    regions' own transitions are mutated too (``mutants`` mutates the machine it is given);
    ``per_operator=None`` or ``every_machine``: of every machine (shuffled)."""
    rng = random.Random(seed_value)
    count = len(list(hfsm.machines()))
    every = per_operator is None or every_machine
    picks = range(count) if every else [rng.randrange(count)]
    out: list[FSM] = []
    for index in picks:
        inner = list(hfsm.machines())[index]
        for mutant in mutants(inner, seed=seed_value, per_operator=per_operator):
            assert isinstance(mutant.model, FSM)
            whole = copy.deepcopy(hfsm)
            target = list(whole.machines())[index]
            target.states, target.transitions = mutant.model.states, mutant.model.transitions
            target.initial = mutant.model.initial
            out.append(whole)
    rng.shuffle(out)
    return out


def seeded_whole_mutants(
    trees: int, *, seed: int, per_tree: int = 2, max_nodes: int = 12
) -> Iterator[tuple[BTDocument, FSM, list[FSM]]]:
    """``trees`` seeded random trees converted whole; those the converter refuses or writes
    flat (no region state: nothing for a region check) are skipped; each with up to
    ``per_tree`` mutants of one random machine each, drawn from one ``random.Random(seed)``."""
    rng = random.Random(seed)
    for _ in range(trees):
        doc = random_tree(rng, controls=CONTROLS, decorators=DECORATORS, max_nodes=max_nodes)
        try:
            model = bt_to_hfsm(doc).model
        except (InputError, UnsupportedError):
            continue
        found = [deep_mutants(model, rng.randrange(1 << 30), 1)[:1] for _ in range(per_tree)]
        if not model.is_hierarchical:
            continue
        yield doc, model, [m for group in found for m in group]
