"""Whether a lifted counterexample is the shortest (``verify/shortest.py``; docs/verification.md
§3): the bounded breadth-first search of the two whole machines, checked against the whole
product's own shortest counterexample (native breadth-first search) on the seeded small mutants
of the lift tests."""

from __future__ import annotations

from fsmbt.verify.lift import lift_machines, separates
from fsmbt.verify.native import replay
from fsmbt.verify.shortest import search_shorter
from support.pernode_mutants import lifted_reports, whole_shortest


def _lifted_pairs():  # type: ignore[no-untyped-def]
    """(tree, mutant, lifted report, whole product's shortest) for the sample's lifted ones."""
    for doc, mutant, report in lifted_reports(40):
        best = whole_shortest(doc, mutant)
        if best is not None and best >= 0:  # refuted by the whole product
            yield doc, mutant, report, best


def test_every_lifted_verdict_says_it_is_proven_shortest_and_is() -> None:
    checked = 0
    for _doc, _mutant, report, best in _lifted_pairs():
        traces = [p.counterexample for p in report.properties.values() if p.counterexample]
        assert min(len(t) - 1 for t in traces) == best
        assert report.stats["shortest"] is True
        assert any(a.startswith("shortest: ") for a in report.abstractions)
        checked += 1
    assert checked >= 30


def test_the_search_finds_the_shortest_below_a_longer_bound_and_says_when_it_stops() -> None:
    checked = 0
    for doc, mutant, _report, best in _lifted_pairs():
        machines = lift_machines(doc, mutant)
        found = search_shorter(*machines, best + 3)  # as if the lift had been 3 inputs longer
        assert found.exhausted and found.shorter is not None
        assert len(found.shorter) == best  # the whole product's shortest, no shorter
        assert separates(replay(*machines, found.shorter))
        edge = search_shorter(*machines, best + 1)  # the last level searched holds it
        assert edge.shorter is not None and len(edge.shorter) == best
        exact = search_shorter(*machines, best)  # nothing shorter than the shortest
        assert exact.exhausted and exact.shorter is None
        if best >= 2:
            stopped = search_shorter(*machines, best, max_seconds=0.0)
            assert not stopped.exhausted and stopped.shorter is None
            assert stopped.sentence().startswith("not known to be shortest")
        checked += 1
    assert checked >= 30
