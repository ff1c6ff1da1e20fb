"""Mutants outside the per-node decomposition decided node by node after all (issue 27;
``pernode.check_region``'s ``tolerate``, docs/verification.md §5, docs/semantics.md §4d).

A retargeted transition that jumps into a subtree elsewhere than its entry breaks the entry
condition (2) of the per-node check, which used to refuse the region (checked whole). With
``tolerate`` the walk goes on, each fragment outputs a stray jump as an exit no status pairs
with, and a local check that reaches one fails; the failure is only a candidate, kept when the
lift's replay separates the two whole machines. Here ``compositional.WHOLE_FIRST`` is 0, so
every such region is decided that way first (on these small trees ``verify`` checks it whole
first; ``test_ver_lift.py`` keeps its shortest counterexamples), on the seeded mutants of
``test_ver_pernode.py``:

- every pair so refuted is one the whole product refutes, and its counterexample replays to a
  difference on the two whole machines;
- a region breaking the condition is never proven (``check_region`` without ``tolerate``
  refuses it; with it, it fails or refuses: never a proof);
- the counts (refuted this way, lifted as long as the whole product's shortest or longer) are
  printed (``pytest -s``).
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import pytest

from fsmbt import limits
from fsmbt.semantics.execution import leaf_machine
from fsmbt.verify import compositional
from fsmbt.verify.compositional import CheckPlan, compositional_report
from fsmbt.verify.lazy_fsm import LazyDataMachine
from fsmbt.verify.native import replay
from fsmbt.verify.pernode import NotPerNode, check_region
from fsmbt.verify.report import PER_NODE_LIFTED
from support.pernode_mutants import BOUND, seeded_mutants, whole


def _trace(report: Any) -> list[Any]:
    return min((p.counterexample for p in report.properties.values() if p.counterexample), key=len)


class _Spy:
    """``compositional.check_region`` recorded: per call whether the region broke the entry
    condition, and the check without ``tolerate`` on the same region (it must refuse)."""

    def __init__(self) -> None:
        self.broken = 0

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        try:
            found = check_region(*args, **kwargs)
        except NotPerNode as exc:
            if "entered twice" in str(exc) or "not at its entry" in str(exc):
                self._strict_refuses(args)
            raise
        assert found.equivalent or found.failed is not None
        if found.tolerated is not None:
            assert not found.equivalent, "a region breaking the entry condition was proven"
            self._strict_refuses(args)
        return found

    def _strict_refuses(self, args: tuple[Any, ...]) -> None:
        self.broken += 1
        with pytest.raises(NotPerNode):
            check_region(*args[:3])


def test_stray_jumps_are_refuted_only_where_the_whole_product_refutes(monkeypatch) -> None:
    monkeypatch.setattr(compositional, "WHOLE_FIRST", 0)
    spy = _Spy()
    monkeypatch.setattr(compositional, "check_region", spy)
    tally: Counter[str] = Counter()
    for doc, _model, mutants in seeded_mutants(300, seed=4, rng_seed=27):
        for mutant in mutants:
            tally["pairs"] += 1
            plan = CheckPlan()
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, mutant, max_states=BOUND, plan=plan)
            tally["outside (region whole)"] += bool(plan.refused)
            if report is None or "per_node_broken" not in report.stats:
                continue
            assert report.method == PER_NODE_LIFTED and not report.equivalent
            verdict = whole(doc, mutant)
            assert verdict is not True, "a stray-jump refutation of a pair the whole product proves"
            inputs = [step.input for step in _trace(report)[1:]]
            assert replay(leaf_machine(doc), LazyDataMachine(mutant), inputs).differs
            failing = plan.units[-1][1][-1]
            assert not failing.held  # the plan's failing unit, what NuSMV decides again
            tally["refuted past a broken entry"] += 1
            tally[f"whole product {'refutes' if verdict is False else 'undecided'}"] += 1
    print(f"\n[stray jumps] {dict(tally)}; regions breaking the entry condition: {spy.broken}")
    assert tally["pairs"] >= 500
    assert spy.broken >= 60
    assert tally["refuted past a broken entry"] >= 45
