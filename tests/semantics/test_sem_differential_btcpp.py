"""Differential test: our interpreter vs BehaviorTree.CPP 4.8 (behaviortreepy) on random trees.

Same tree, same outcome script: the leaves ticked (label, path, outcome), in order, and the
root result of every ``tickOnce`` / ``tickExactlyOnce`` must be identical. Trees whose
``tickOnce`` never returns (the engine would hang) are run in ``tickExactlyOnce`` mode only.
"""

from __future__ import annotations

import random
from collections import Counter

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from support.btcpp_lockstep import matches_btcpp
from support.random_trees import ALL_NODE_TYPES, OutcomeScript, random_tree

SEEDS = st.integers(min_value=0, max_value=2**31 - 1)
SETTINGS = settings(
    max_examples=500, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)


def _compare(seed: int, exactly_once: bool) -> bool:
    """True when compared (False: tickOnce would not return, nothing to compare)."""
    doc = random_tree(random.Random(seed), max_nodes=16)
    return matches_btcpp(doc, OutcomeScript(seed), exactly_once, seed)


@SETTINGS
@given(SEEDS)
def test_sem_btcpp_tick_once_traces_match(seed: int) -> None:
    _compare(seed, exactly_once=False)


@SETTINGS
@given(SEEDS)
def test_sem_btcpp_tick_exactly_once_traces_match(seed: int) -> None:
    assert _compare(seed, exactly_once=True)


def test_sem_random_trees_cover_every_node_type() -> None:
    """The generator behind the differential tests reaches every supported node type."""
    seen: Counter[str] = Counter()
    for seed in range(300):
        doc = random_tree(random.Random(seed), max_nodes=16)
        for _, node in doc.nodes():
            seen[
                "Action"
                if node.type.startswith("Act")
                else "Condition"
                if node.type.startswith("Cond")
                else node.type
            ] += 1
    missing = [t for t in ALL_NODE_TYPES if seen[t] == 0]
    assert not missing, missing
