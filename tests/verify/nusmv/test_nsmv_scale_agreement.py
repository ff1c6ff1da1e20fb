"""NuSMV's two runs agree with the native checker on FSM ~ FSM pairs of up to 300 states (issue
27, item 2): a seeded sample of benchmarks/bench_nusmv_agreement.py's pairs (renamed copies up
to 300 states, one-transition mutants up to 40 states, whose reachability spec gets its own run),
all five verdicts compared. ``FSMBT_TEST_SEED`` draws another sample (tests/support/sampling.py
convention); the full count (>= 1 000 pairs, up to 1 000 states) is the benchmark's."""

from __future__ import annotations

import copy
import os
import random

from fsmbt.generate.generator import random_fsm
from fsmbt.model.fsm import FSM, State
from fsmbt.verify import nusmv, verify
from fsmbt.verify.report import DEADLOCK_ABSENCE

SEED = int(os.environ.get("FSMBT_TEST_SEED", "27"))
COPY_SIZES = (5, 20, 60, 150, 300)
MUTANT_SIZES = (5, 10, 20, 40)


def _renamed(fsm: FSM) -> FSM:
    """The same machine with every state renamed and listed in reverse (ids differ in SMV)."""
    out = FSM(name=f"{fsm.name}_copy", start_name="Init", initial_event=fsm.initial_event)
    for name in reversed(list(fsm.states)):
        state = fsm.states[name]
        out.add_state(State(f"r_{name}", action=state.action, final=state.final))
    out.initial = f"r_{fsm.initial}"
    for t in reversed(fsm.transitions):
        out.add_transition(f"r_{t.source}", t.event, f"r_{t.target}")
    return out


def test_copies_agree_and_are_equivalent(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED)
    for size in COPY_SIZES:
        source = random_fsm(rng.randrange(10**9), n_states=size)
        result = _renamed(source)
        report = nusmv.check(source, result)
        assert report.verdicts() == verify(source, result).verdicts(), size
        # one run: the invariants with the listing; deadlock absence implied (no CTL run)
        assert report.equivalent and report.stats["nusmv_runs"] == 1
        assert report.properties[DEADLOCK_ABSENCE].detail == nusmv.DEADLOCK_IMPLIED_DETAIL


def test_mutants_agree_on_every_property(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED + 1)
    failing = 0
    for size in MUTANT_SIZES:
        for _ in range(2):
            source = random_fsm(rng.randrange(10**9), n_states=size)
            mutant = copy.deepcopy(source)
            transition = mutant.transitions[rng.randrange(len(mutant.transitions))]
            transition.target = rng.choice([n for n in mutant.states if n != transition.target])
            native = verify(source, mutant)
            report = nusmv.check(source, mutant)
            assert report.verdicts() == native.verdicts(), (size, native.verdicts())
            failing += not native.equivalent
    assert failing >= 3  # the sample exercises the failing path (the reachability run)
