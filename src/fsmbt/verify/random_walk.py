"""Random runs of the whole tree, replayed on the two whole machines: the last try at a
counterexample before a large region is checked whole (issue 27; docs/verification.md §3,
"Random runs").

Why: a per-node failure past a broken entry condition is only a candidate, and the lift
(``verify/lift.py``) drives the tree to the failing node along one planned path: when the
failing node is reached only by a combination the plan does not find, the region went to its
whole product, which stops on large trees with memory. A retargeted transition that fires often
shows in a few hundred random leaf outcomes: seeded walks from the root are a cheap search for
such a run. What they find is a real counterexample (the replay shows the two machines differ,
``lift.separating_prefix``) and is then shortened and reported like any lifted one; what they do
not find proves nothing, and the caller goes on as before.

The walks are deterministic (``random.Random(SEED)``), so a verdict does not depend on the
machine's load. Cost: at most ``budget(nodes)`` leaf outcomes (``WALK_BUDGET``, less on trees past
1 000 nodes) in walks of at most ``WALK_LEAVES``, each stepped on the tree and replayed on both
machines.
"""

from __future__ import annotations

import random
from typing import Any

from fsmbt.semantics.machine import Machine

#: Leaf outcomes all the walks of one search give together, the most one walk gives (a walk
#: also ends when the tree returns), and the seed.
WALK_BUDGET = 20_000
WALK_LEAVES = 200
SEED = 27
#: A step's cost grows with the tree (the interpreter's call stack, the result's active path):
#: the budget shrinks past this many leaf outcomes x nodes (about 2 s here: 20 000 leaves of
#: a 1 000-node tree; a 10 000-node tree gets 2 000), never below ``WALK_LEAVES`` x 5.
WALK_WORK = 20_000_000


def budget(nodes: int) -> int:
    """The leaf outcomes one search gives a tree of ``nodes`` nodes."""
    return max(5 * WALK_LEAVES, min(WALK_BUDGET, WALK_WORK // max(nodes, 1)))


def walk_inputs(source: Machine[Any], rng: random.Random, length: int) -> list[str]:
    """One random run of ``source`` from its start: at each step an input it offers, chosen by
    ``rng``, until ``length`` inputs or until it offers none (the tree returned)."""
    state, _outputs = source.start()
    inputs: list[str] = []
    for _ in range(length):
        offered = source.inputs(state)
        if not offered:
            break
        symbol = rng.choice(list(offered))
        inputs.append(symbol)
        state, _outputs = source.step(state, symbol)
    return inputs
