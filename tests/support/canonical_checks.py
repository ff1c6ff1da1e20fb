"""The three checks that a canonical leaf-execution machine (docs/semantics.md §4a) behaves as
the faithful interpreter does, shared by the tests of each widening of the canonical class:
a lockstep random walk, a full proof by the native checker, and the same verdict against a
converted HFSM and its mutants."""

from __future__ import annotations

import random

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics.leaf_machine import LeafMachine, RootResult, explore
from fsmbt.verify import native
from fsmbt.verify.mutations import mutants
from fsmbt.verify.pairing import machines_for

WALK_STEPS = 80


def lockstep(doc: BTDocument, loop: bool, rng: random.Random, steps: int = WALK_STEPS) -> None:
    """Walk both machines on the same random inputs: same outputs, statuses, descriptions and
    offered inputs after every step (restarting both after a root result)."""
    canon = LeafMachine(doc, loop=loop)
    faithful = LeafMachine(doc, loop=loop, generic=True)
    assert canon.canonical and not faithful.canonical
    c_state, c_out = canon.start()
    f_state, f_out = faithful.start()
    assert c_out == f_out
    for _ in range(steps):
        assert canon.status(c_state) == faithful.status(f_state)
        assert canon.describe(c_state) == faithful.describe(f_state)
        inputs = tuple(canon.inputs(c_state))
        assert inputs == tuple(faithful.inputs(f_state))
        if not inputs:
            assert isinstance(c_state, RootResult) and c_state == f_state
            c_state, c_out = canon.start()
            f_state, f_out = faithful.start()
            assert c_out == f_out
            continue
        symbol = rng.choice(inputs)
        c_state, c_out = canon.step(c_state, symbol)
        f_state, f_out = faithful.step(f_state, symbol)
        assert c_out == f_out, (symbol, c_out, f_out)


def proved_equivalent(doc: BTDocument, loop: bool) -> bool:
    """The native checker proves the canonical machine equivalent to the faithful one (every
    input sequence) and it has no more states; returns whether it has fewer."""
    canon = LeafMachine(doc, loop=loop)
    faithful = LeafMachine(doc, loop=loop, generic=True)
    report = native.check(faithful, canon, mode="lockstep")
    assert report.equivalent, report.verdicts()
    n_canon, n_faithful = len(explore(canon)), len(explore(faithful))
    assert n_canon <= n_faithful
    return n_canon < n_faithful


def same_verdicts_against_hfsm(doc: BTDocument, rng: random.Random) -> tuple[int, int]:
    """Check ``doc`` against its HFSM and the HFSM's mutants on both machines: the verdicts
    must agree. Returns (pairs checked, pairs not equivalent); (0, 0) if it does not convert."""
    try:
        hfsm = bt_to_hfsm(doc).model
    except UnsupportedError:
        return 0, 0
    targets = [hfsm] + [m.model for m in mutants(hfsm, seed=rng.randrange(1000), per_operator=1)]
    checked = caught = 0
    for target in targets:
        _src, result, _mode = machines_for(doc, target)
        on_canon = native.check(LeafMachine(doc), result, mode="lockstep").equivalent
        on_faithful = native.check(
            LeafMachine(doc, generic=True), result, mode="lockstep"
        ).equivalent
        assert on_canon == on_faithful
        checked += 1
        caught += not on_canon
    return checked, caught
