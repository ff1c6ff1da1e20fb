"""NuSMV fails the same local check as the native walk past a broken entry condition (issue 27;
``pernode.check_region``'s ``tolerate``; docs/nusmv.md "Trees node by node").

A mutant whose retargeted transition jumps into a subtree elsewhere than its entry used to be
refused by the per-node decomposition, so NuSMV was not asked. Now the native walk goes on and
the fragment that reads the stray jump outputs an exit no status pairs with; NuSMV decides the
same distinct local checks (``encode_local``: the fragment explored with that exit as one more
output token, σ from the walk, which never pairs a status with it). On the seeded mutants
(``compositional.WHOLE_FIRST`` 0, so every such region is decided that way first), for each
pair refuted past a broken entry: NuSMV's verdict on every unit is the native one, the
failing unit included. Counts are printed (``-s``).
"""

from __future__ import annotations

from collections import Counter

from fsmbt import limits
from fsmbt.verify import compositional
from fsmbt.verify.compositional import CheckPlan, compositional_report
from support.pernode_mutants import BOUND, seeded_mutants
from support.pernode_units import units_agree


def test_nusmv_fails_the_unit_the_stray_jump_fails(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setattr(compositional, "WHOLE_FIRST", 0)
    tally: Counter[str] = Counter()
    for doc, _model, mutants in seeded_mutants(120, seed=4, rng_seed=27):
        for mutant in mutants:
            plan = CheckPlan()
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, mutant, max_states=BOUND, plan=plan)
            if report is None or "per_node_broken" not in report.stats:
                continue
            units, checked, refused = units_agree(plan)
            tally["pairs"] += 1
            tally["units agree"] += len(checked)
            tally["units refused by NuSMV"] += len(refused)
            tally["failing unit failed by NuSMV"] += id(units[-1]) not in refused
    print(f"\n[NuSMV past a broken entry] {dict(tally)}")
    assert tally["pairs"] >= 20
    assert tally["failing unit failed by NuSMV"] >= tally["pairs"] - 2
