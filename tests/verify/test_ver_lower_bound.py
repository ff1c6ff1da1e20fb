"""The lower bound on any counterexample's length (``verify/lower_bound.py``; docs/semantics.md
§4d, "A lower bound on any counterexample"; docs/verification.md §3): its soundness against
the interpreter (the leaves before a node's first tick, the leaves of a first tick) and against
the whole product's shortest counterexample on seeded one-transition mutants, and the verdict
that claims "shortest" by it."""

from __future__ import annotations

import contextlib

import pytest

from fsmbt import limits
from fsmbt.verify import lift
from fsmbt.verify.lower_bound import TickCosts
from support.lower_bound_samples import bounded_pairs, first_ticks
from support.pernode_mutants import lifted_reports, whole_shortest
from support.pernode_trees import seeded_trees


def test_the_costs_never_exceed_what_the_interpreter_does() -> None:
    """P(U) <= the fewest leaves before U is seen ticking; the root's ``first`` <= the fewest
    leaves of its first tick returning that status (both from the interpreter's own runs)."""
    checked = tight = 0
    for doc in seeded_trees(60, seed=31):
        tree, seen, root_first = first_ticks(doc)
        costs = TickCosts(tree)
        for nid, depth in seen.items():
            before = costs.before(nid)
            assert before is not None and before <= depth, (tree.nodes[nid].path, before, depth)
            checked += 1
            tight += before == depth
        for status, depth in root_first.items():
            assert costs.costs[0].first[status] <= depth
            assert costs.costs[0].any[status] <= costs.costs[0].first[status]
    assert checked >= 500
    assert tight >= checked // 2  # the bound is not trivially low


@pytest.mark.parametrize(
    ("trees", "seed", "rng_seed", "per_tree", "least"),
    [(60, 4, 5, 2, 25), (120, 41, 42, 3, 60)],
)
def test_the_bound_never_exceeds_the_whole_products_shortest(
    trees: int, seed: int, rng_seed: int, per_tree: int, least: int
) -> None:
    """On every seeded mutant the whole product decides: bound <= its shortest counterexample;
    and the bound meets it often (a bound one too high fails here)."""
    decided = equal = 0
    for doc, mutant, bound in bounded_pairs(trees, seed, rng_seed, per_tree):
        best = whole_shortest(doc, mutant)
        if best is None or best < 0:
            continue  # undecided, or equivalent (nothing to bound)
        assert bound.bound <= best, (bound, best)
        assert bound.failing >= 1 and bound.before + bound.inside == bound.bound
        decided += 1
        equal += bound.bound == best
    assert decided >= least
    assert equal >= least // 2


def test_a_verdict_claims_shortest_by_the_bound_only_when_it_is(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With the breadth-first search given no time (as on a large tree), the verdict falls to
    the bound: when it says "shortest" by the bound, the whole product's shortest is its
    length; otherwise it says "not known to be shortest"."""
    search = lift.search_shorter
    monkeypatch.setattr(
        lift, "search_shorter", lambda s, r, n, **kw: search(s, r, n, max_seconds=0.0)
    )
    claimed = unclaimed = 0
    for doc, mutant, report in lifted_reports(60):
        length = report.stats["lifted_steps"]
        said = " ".join(report.abstractions)
        if report.stats.get("shortest_method") == "lower bound":
            assert report.stats["shortest"] is True
            assert report.stats["shortest_lower_bound"] == length
            assert "shortest: no counterexample can be shorter than" in said
            assert whole_shortest(doc, mutant) == length
            claimed += 1
        elif length >= 2:  # (a budget of 0 s still finishes the first level)
            assert report.stats["shortest"] is False
            assert "not known to be shortest" in said
            unclaimed += 1
    assert claimed >= 15
    assert unclaimed >= 1


def test_the_verdict_names_the_label_limit_only_when_a_search_stopped_there(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A bound that falls short says to raise ``FSMBT_MAX_SHORTEST_LABELS`` only when one of
    its coupled-stage searches stopped at that limit (``verify/coupling.py``): never on the
    small sample at the default limit (its searches finish), and on some of it at a limit of
    one label."""
    search = lift.search_shorter
    monkeypatch.setattr(
        lift, "search_shorter", lambda s, r, n, **kw: search(s, r, n, max_seconds=0.0)
    )
    named: dict[bool, int] = {}
    for tight in (False, True):
        with limits.changed(shortest_max_labels=1) if tight else contextlib.nullcontext():
            for _doc, _mutant, report in lifted_reports(60):
                said = " ".join(report.abstractions)
                if "not known to be shortest by the lower bound either" in said:
                    named[tight] = named.get(tight, 0) + ("FSMBT_MAX_SHORTEST_LABELS" in said)
    assert named.get(False) == 0
    assert named.get(True, 0) >= 1
