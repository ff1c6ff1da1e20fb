"""Is a lifted counterexample the shortest? A breadth-first search of the two whole machines,
bounded by the counterexample's own length (docs/verification.md §3, "Lifted counterexamples").

Why: a counterexample lifted from a local check (``verify/lift.py``) is real - replayed on the
two whole machines - but built node by node: a child's realization is costed from a fresh
start, and another failing node may be reached sooner. The whole product, whose first
difference in breadth-first order is shortest by construction, is what the lift avoids; but
only its first ``L - 1`` levels can hold a shorter counterexample when the lifted one has ``L``
inputs, and on a mutant found early those levels are small. So the levels are searched, within
a budget: when they are exhausted, the lifted counterexample is proven shortest; when they hold
a difference, the first one met is shortest and replaces it; when the budget runs out first,
the verdict says it is not known to be shortest.

Rules (docs/semantics.md §4, the leaf-execution machines; the same difference as
``native.replay``, less a source refusing its input, which ``lift.separates`` excludes too): a
step *separates* the machines when the outputs or the statuses differ, or the result refuses an
input the source takes (a machine that ``follows_environment`` never refuses). Only pairs
reached by agreeing steps are expanded; inputs are the source's offered inputs in their order,
so the first separating sequence met is the shortest and, among those, the first in that order.
Not searched: the product's properties that a single replay cannot show (a result accepting an
input the source refuses, a deadlock), so "shortest" means shortest among the differences a
replay shows - the ones a lifted counterexample can be.

Cost: O(P · I) steps of the two machines for P pairs reached in fewer than ``L - 1`` steps and I
inputs per state, bounded by ``max_pairs`` and ``max_seconds``; memory O(P) states.
"""

from __future__ import annotations

import time
from collections.abc import Hashable
from dataclasses import dataclass
from typing import Any

from fsmbt.semantics.machine import Machine

#: The search's default budget: it runs after every lifted counterexample, so it is bounded
#: well inside the time the lift saves (a refuted 15 000-node mutant takes about 10 s).
MAX_PAIRS = 200_000
MAX_SECONDS = 3.0


@dataclass(frozen=True)
class ShorterSearch:
    """The outcome of searching for a counterexample shorter than ``length`` inputs.

    ``shorter``: the first separating input sequence met (``None``: none met); ``exhausted``:
    every pair reached in fewer than ``length - 1`` steps was expanded, so nothing shorter than
    ``shorter`` (or than ``length`` when ``shorter`` is ``None``) exists; ``depth``: the levels
    searched completely; ``pairs``: the pairs reached."""

    length: int
    shorter: list[str] | None
    exhausted: bool
    depth: int
    pairs: int

    def sentence(self) -> str:
        """What the verdict says of its counterexample's length."""
        if self.shorter is not None:
            return (
                f"shortest: a breadth-first search of the two whole machines ({self.pairs} "
                f"pairs) found this {len(self.shorter)}-input counterexample, shorter than "
                f"the {self.length} inputs lifted, and none shorter"
            )
        if self.exhausted:
            return (
                f"shortest: a breadth-first search of the two whole machines to depth "
                f"{self.length - 1} ({self.pairs} pairs) found no shorter difference"
            )
        return (
            f"not known to be shortest: the breadth-first search of the two whole machines "
            f"stopped at its budget after {self.depth} complete levels of {self.length - 1} "
            f"({self.pairs} pairs)"
        )


def search_shorter(
    source: Machine[Any],
    result: Machine[Any],
    length: int,
    *,
    max_pairs: int = MAX_PAIRS,
    max_seconds: float = MAX_SECONDS,
) -> ShorterSearch:
    """Search every input sequence of fewer than ``length`` inputs for one that separates the
    machines (module docstring: the rules, the cost). Never raises on its budget: it says it
    stopped."""
    deadline = time.perf_counter() + max_seconds
    follows = bool(getattr(result, "follows_environment", False))
    s0, out_s = source.start()
    r0, out_r = result.start()
    if tuple(out_s) != tuple(out_r) or source.status(s0) != result.status(r0):
        # they differ before any input: nothing is shorter than that
        return ShorterSearch(length, [] if length > 0 else None, True, 0, 1)
    start: tuple[Hashable, Hashable] = (s0, r0)
    seen: set[tuple[Hashable, Hashable]] = {start}
    level: list[tuple[tuple[Hashable, Hashable], tuple[str, ...]]] = [(start, ())]
    depth = 0
    while level and depth < length - 1:
        following: list[tuple[tuple[Hashable, Hashable], tuple[str, ...]]] = []
        for (s, r), path in level:
            if time.perf_counter() > deadline:
                return ShorterSearch(length, None, False, depth, len(seen))
            for symbol in source.inputs(s):
                inputs = [*path, symbol]
                if not follows and symbol not in result.inputs(r):
                    return ShorterSearch(length, inputs, True, depth, len(seen))
                s2, o1 = source.step(s, symbol)
                r2, o2 = result.step(r, symbol)
                if tuple(o1) != tuple(o2) or source.status(s2) != result.status(r2):
                    return ShorterSearch(length, inputs, True, depth, len(seen))
                pair = (s2, r2)
                if pair in seen:
                    continue
                if len(seen) >= max_pairs:
                    return ShorterSearch(length, None, False, depth, len(seen))
                seen.add(pair)
                following.append((pair, tuple(inputs)))
        level = following
        depth += 1
    return ShorterSearch(length, None, True, depth, len(seen))
