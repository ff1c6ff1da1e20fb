"""The checks that a reduced leaf-execution machine (the canonical states of docs/semantics.md
§4a, the static fast path) behaves as the faithful interpreter does, shared by their tests: a
lockstep random walk, a full proof by the native checker, and the same verdict against a
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


def walk_alike(
    reduced: LeafMachine, faithful: LeafMachine, rng: random.Random, steps: int = WALK_STEPS
) -> None:
    """Walk a reduced machine (canonical or fast path) and the faithful one on the same random
    inputs: same outputs, statuses, descriptions and offered inputs after every step
    (restarting both after a root result)."""
    r_state, r_out = reduced.start()
    f_state, f_out = faithful.start()
    assert r_out == f_out
    for _ in range(steps):
        assert reduced.status(r_state) == faithful.status(f_state)
        assert reduced.describe(r_state) == faithful.describe(f_state)
        inputs = tuple(reduced.inputs(r_state))
        assert inputs == tuple(faithful.inputs(f_state))
        if not inputs:
            assert isinstance(r_state, RootResult) and r_state == f_state
            r_state, r_out = reduced.start()
            f_state, f_out = faithful.start()
            assert r_out == f_out
            continue
        symbol = rng.choice(inputs)
        r_state, r_out = reduced.step(r_state, symbol)
        f_state, f_out = faithful.step(f_state, symbol)
        assert r_out == f_out, (symbol, r_out, f_out)


def lockstep(doc: BTDocument, loop: bool, rng: random.Random, steps: int = WALK_STEPS) -> None:
    """``walk_alike`` on ``doc``'s canonical machine and its faithful one."""
    canon = LeafMachine(doc, loop=loop)
    faithful = LeafMachine(doc, loop=loop, generic=True)
    assert canon.canonical and not faithful.canonical
    walk_alike(canon, faithful, rng, steps)


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
