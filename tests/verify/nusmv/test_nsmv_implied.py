"""NuSMV's reachability implied by the other four properties (docs/nusmv.md, "Reachability
implied") and the two runs (docs/nusmv.md, "Two runs"): on an equivalent pair without the
shared search, the invariants' run and the CTL run without the reachability spec; with it (the
default for FSM pairs), the invariants and the listing of the reachable states in one run and
the CTL run; a failing pair also gets the listing (or the witness runs); every way gives the
verdicts of one run of every spec and of the native checker."""

from __future__ import annotations

import copy
import os
import random
from pathlib import Path

from fsmbt import api
from fsmbt.generate.generator import random_fsm
from fsmbt.verify import nusmv, verify
from fsmbt.verify.nusmv import reach
from fsmbt.verify.nusmv.runner import run_nusmv
from fsmbt.verify.report import DEADLOCK_ABSENCE, REACHABILITY

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "guard_npc.csv"
SEED = int(os.environ.get("FSMBT_TEST_SEED", "27"))


def _copies_and_mutants(rng: random.Random, sizes: tuple[int, ...]):  # type: ignore[no-untyped-def]
    """For each size, a seeded random FSM with its copy, then with a one-transition mutant:
    (source, result) pairs."""
    for size in sizes:
        source = random_fsm(rng.randrange(10**9), n_states=size)
        mutant = copy.deepcopy(source)
        transition = mutant.transitions[rng.randrange(len(mutant.transitions))]
        transition.target = rng.choice([s for s in mutant.states if s != transition.target])
        yield source, copy.deepcopy(source)
        yield source, mutant


def test_equivalent_pair_skips_the_reachability_spec(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    fsm = api.load(EXAMPLE).model
    report = nusmv.check(fsm, copy.deepcopy(fsm), shared_search=False)
    assert report.equivalent and report.stats["nusmv_runs"] == 2
    assert report.properties[REACHABILITY].detail == nusmv.IMPLIED_DETAIL
    shared = nusmv.check(fsm, copy.deepcopy(fsm), implied_deadlock=False)  # off the listing
    assert shared.equivalent and shared.stats["nusmv_runs"] == 2
    assert shared.properties[REACHABILITY].detail == reach.STATES_DETAIL
    # the default: deadlock absence follows from the shared run, no CTL run
    lean = nusmv.check(fsm, copy.deepcopy(fsm))
    assert lean.equivalent and lean.stats["nusmv_runs"] == 1
    assert lean.properties[DEADLOCK_ABSENCE].detail == nusmv.DEADLOCK_IMPLIED_DETAIL
    assert lean.verdicts() == shared.verdicts()
    whole = nusmv.check(fsm, copy.deepcopy(fsm), implied_reachability=False, split=False)
    assert whole.stats["nusmv_runs"] == 1
    assert whole.verdicts() == report.verdicts() == shared.verdicts()


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
        report = nusmv.check(fsm, mutant, shared_search=False)
        # two runs, then reachability from the listed states: one run when it holds, three
        # when it fails (the listing, the witness, its replay; docs/nusmv.md)
        reached = report.properties[REACHABILITY].holds
        assert report.stats["nusmv_runs"] == (3 if reached else 5)
        assert report.verdicts() == native.verdicts()
        shared = nusmv.check(fsm, mutant)  # the invariants and the listing in one run
        assert shared.stats["nusmv_runs"] == (2 if reached else 4)
        assert shared.verdicts() == native.verdicts()
        whole = nusmv.check(fsm, mutant, implied_reachability=False, split=False)
        assert report.verdicts() == whole.verdicts()
        compared += 1
    assert compared >= 1


def test_the_ctl_run_beside_the_shared_run_gives_the_same_report(nusmv_binary, monkeypatch) -> None:
    """``check(beside=True)`` (the CTL run in a second process beside the shared run;
    docs/nusmv.md, "Sixth round") against the default ``beside=False`` (one after the other): the same
    runs, verdicts, details and counterexamples, on seeded random pairs, copies and mutants."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED)
    failing = 0
    for source, result in _copies_and_mutants(rng, (5, 12, 30, 60)):
        native = verify(source, result)
        beside = nusmv.check(source, result, beside=True)
        alone = nusmv.check(source, result, implied_deadlock=False)
        assert beside.verdicts() == alone.verdicts() == native.verdicts()
        assert beside.stats["nusmv_runs"] == alone.stats["nusmv_runs"]
        for name, found in beside.properties.items():
            other = alone.properties[name]
            assert (found.detail, found.counterexample) == (other.detail, other.counterexample)
        failing += not native.equivalent
    assert failing >= 1  # failing pairs (counterexamples) were compared too


def test_deadlock_is_implied_only_when_the_rest_holds(nusmv_binary, monkeypatch) -> None:
    """Deadlock absence implied by the shared run (``nusmv.deadlock_implied``): on seeded
    random FSM ~ FSM copies and one-transition mutants, the default gives the verdicts of the
    run that decides deadlock absence with its own CTL spec and of the native checker; the
    implication is used on every equivalent pair (one NuSMV run) and on no failing one (its
    deadlock verdict, holding or not, is NuSMV's own, with the CTL run)."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED + 1)
    implied = failing = 0
    for source, result in _copies_and_mutants(rng, (4, 8, 15, 25, 40, 70)):
        native = verify(source, result)
        lean = nusmv.check(source, result)
        full = nusmv.check(source, result, implied_deadlock=False)
        assert lean.verdicts() == full.verdicts() == native.verdicts()
        said = lean.properties[DEADLOCK_ABSENCE].detail == nusmv.DEADLOCK_IMPLIED_DETAIL
        assert said == native.equivalent
        assert lean.stats["nusmv_runs"] == full.stats["nusmv_runs"] - said
        implied += said
        failing += not native.equivalent
    assert implied >= 6 and failing >= 3


def _structured_mutant() -> tuple[str, list[str], str]:
    """A failing structured pair's product (every spec) and its variable order: a seeded
    outcome-driven machine with one transition retargeted (``fsmbt.verify.mutations``)
    against its structured tree - the first such mutant the native checker refutes."""
    from fsmbt.convert.structured import fsm_to_structured
    from fsmbt.generate.outcome_machines import random_outcome_fsm
    from fsmbt.model.errors import FsmbtError
    from fsmbt.verify.mutations import mutants

    source = random_outcome_fsm(SEED, states=6, containers=0.2)
    tree = fsm_to_structured(source).model
    for mutant in mutants(source, seed=SEED, per_operator=None):
        if mutant.operator != "retarget_transition":
            continue
        try:
            refuted = not verify(mutant.model, tree, outcome_driven=True).equivalent
        except FsmbtError:  # a retargeting the outcome view refuses: not a pair
            continue
        if refuted:
            text, names, context = nusmv.build_model(mutant.model, tree, outcome_driven=True)
            return text, names, context[-1]
    raise AssertionError("no retargeted transition is refuted")


def test_the_lean_run_drops_the_frozen_copies_only_reachability_read() -> None:
    text, names, order = _structured_mutant()
    # with the reachability spec every copy is read: nothing is dropped
    assert nusmv.without_unread_copies(text, order) == (text, order)
    lean = nusmv.without_spec(text, names, REACHABILITY)
    assert lean is not None
    lean_text, lean_order = nusmv.without_unread_copies(lean[0], order)
    declared = {line.split(" : ")[0].strip() for line in lean[0].split("\n") if " : " in line}
    kept = {line.split(" : ")[0].strip() for line in lean_text.split("\n") if " : " in line}
    dropped = declared - kept
    assert dropped and all(name.startswith(("ts_", "tr_")) for name in dropped)
    assert "FROZENVAR" not in lean_text.split("MODULE main")[1]  # the emptied section too
    assert not any(entry.split(".")[0] in dropped for entry in lean_order.split("\n"))
    assert set(order.split("\n")) - set(lean_order.split("\n")) == dropped


def test_without_the_copies_nusmv_gives_the_same_verdicts_and_trace_lengths(
    nusmv_binary, monkeypatch
) -> None:
    """The copies are free variables once reachability is left out: dropping them changes no
    verdict and no counterexample's length (NuSMV's traces are shortest), only its cost."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    text, names, order = _structured_mutant()
    lean = nusmv.without_spec(text, names, REACHABILITY)
    assert lean is not None
    runs = [(lean[0], order), nusmv.without_unread_copies(lean[0], order)]
    answers = [run_nusmv(model, len(lean[1]), order=model_order)[0] for model, model_order in runs]
    assert [r.holds for r in answers[0]] == [r.holds for r in answers[1]]
    assert not all(r.holds for r in answers[0])  # the mutant fails: there are traces
    lengths = [[len(r.trace or ()) for r in found] for found in answers]
    assert lengths[0] == lengths[1]


def test_a_copy_that_alone_declares_a_symbol_is_kept(nusmv_binary, monkeypatch) -> None:
    """A DEFINE may evaluate to a symbol only a frozen copy's type declares (an LEBT's
    ``runl`` to ``rl_4``, declared by ``tr_runl`` alone): that copy stays, the others go, and
    NuSMV reads the lean text."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    text = "\n".join(
        [
            "MODULE m",
            "VAR",
            "  x : boolean;",
            "DEFINE",
            "  d := case x : a1; TRUE : a0; esac;",
            "MODULE main",
            "VAR",
            "  r : m;",
            "FROZENVAR",
            "  tr_d : {a0, a1};",
            "  tr_x : boolean;",
            "INVARSPEC (r.d = a0 | r.d = a1);",
            "",
        ]
    )
    order = "r.x\ntr_x\ntr_d\n"
    lean, lean_order = nusmv.without_unread_copies(text, order)
    assert "  tr_d : {a0, a1};" in lean and "tr_x" not in lean
    assert lean_order.split() == ["r.x", "tr_d"]
    results, _seconds = run_nusmv(lean, 1, order=lean_order)
    assert results[0].holds
