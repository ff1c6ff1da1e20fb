"""NuSMV's reachability implied by the other four properties (docs/nusmv.md, "Reachability
implied") and the two runs (docs/nusmv.md, "Two runs"): on an equivalent pair the invariants' run
and the CTL run without the reachability spec; a failing pair also gets the reachability spec's
own run; every way gives the verdicts of one run of every spec and of the native checker."""

from __future__ import annotations

import copy
from pathlib import Path

from fsmbt import api
from fsmbt.verify import nusmv, verify
from fsmbt.verify.report import REACHABILITY

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "guard_npc.csv"


def test_equivalent_pair_skips_the_reachability_spec(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    fsm = api.load(EXAMPLE).model
    report = nusmv.check(fsm, copy.deepcopy(fsm))
    assert report.equivalent and report.stats["nusmv_runs"] == 2
    assert report.properties[REACHABILITY].detail == nusmv.IMPLIED_DETAIL
    whole = nusmv.check(fsm, copy.deepcopy(fsm), implied_reachability=False, split=False)
    assert whole.stats["nusmv_runs"] == 1
    assert whole.verdicts() == report.verdicts()


def test_failing_pairs_get_every_spec_verdict(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    fsm = api.load(EXAMPLE).model
    compared = 0
    for index in range(min(3, len(fsm.transitions))):
        mutant = copy.deepcopy(fsm)
        transition = mutant.transitions[index]
        others = [name for name in mutant.states if name != transition.target]
        transition.target = others[0]
        native = verify(fsm, mutant)
        if native.equivalent:
            continue
        report = nusmv.check(fsm, mutant)
        # two runs, then reachability from the listed states: one run when it holds, three
        # when it fails (the listing, the witness, its replay; docs/nusmv.md)
        reached = report.properties[REACHABILITY].holds
        assert report.stats["nusmv_runs"] == (3 if reached else 5)
        assert report.verdicts() == native.verdicts()
        whole = nusmv.check(fsm, mutant, implied_reachability=False, split=False)
        assert report.verdicts() == whole.verdicts()
        compared += 1
    assert compared >= 1
