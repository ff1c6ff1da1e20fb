"""Properties of conversion and verification over random valid models.

1. Every rule engine (``rules``, ``bsd``, ``chds``; both directions) turns a random model into
   one the checker proves equivalent (``fsmbt.verify.verify``). An engine may refuse a model
   with ``UnsupportedError`` (the baselines do not map every node type; ``rules`` must map all);
   it may not fail any other way or return a non-equivalent result.
2. A random behaviour-changing mutation (``fsmbt.verify.mutations``) of a converted result, or
   of its source, is found not equivalent, and every failing property's counterexample replays
   (``fsmbt.verify.replay``) to a real difference on both models. Whether a mutation changes
   behaviour is decided independently of the checker, by random simulation of both models;
   a mutant the simulation cannot tell apart is still checked: if the checker calls it not
   equivalent, its counterexamples must replay too. A mutant that is no longer a valid model
   (an eventless cycle, say) must be refused with a one-line ``InputError``; it is counted.

Counts (examples, refusals, mutants caught) are printed (``pytest -s``).
"""

from __future__ import annotations

import random
from collections import Counter

from hypothesis import given
from hypothesis import strategies as st

from fsmbt.convert import convert
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.verify import replay, verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.pairing import machines_for
from support.prop_strategies import BUDGET, bts, fsms

ENGINES = ("rules", "bsd", "chds")
Model = FSM | BTDocument


def check_engines(model: Model, tally: Counter[str]) -> None:
    direction = "fsm->bt" if isinstance(model, FSM) else "bt->fsm"
    for engine in ENGINES:
        try:
            result = convert(model, engine=engine).model
        except UnsupportedError as exc:
            assert "\n" not in str(exc) and exc.message
            tally[f"{engine} {direction}: refused"] += 1
            continue
        report = verify(model, result)
        failing = [p.name for p in report.properties.values() if not p.holds]
        assert report.equivalent, f"{engine} {direction}: not equivalent ({failing})"
        tally[f"{engine} {direction}: equivalent"] += 1


def test_every_rule_engine_converts_random_models_to_verified_equivalents() -> None:
    tally: Counter[str] = Counter()

    @BUDGET
    @given(st.one_of(fsms(), bts()))
    def run(model: Model) -> None:
        tally["examples"] += 1
        check_engines(model, tally)

    run()
    print("\nconversions:", dict(sorted(tally.items())))
    for engine in ENGINES:
        for direction in ("fsm->bt", "bt->fsm"):
            assert tally[f"{engine} {direction}: equivalent"] > 0, f"{engine} {direction}"
    # the paper's engine maps every node type the interpreter runs; the baselines only the
    # classic ones (docs/baselines.md), so only their refusals are expected
    assert tally["rules fsm->bt: refused"] == 0 and tally["rules bt->fsm: refused"] == 0


def simulation_differs(
    source: Model, result: Model, seed: int, runs: int = 120, length: int = 25
) -> bool:
    """Random input sequences on both machines; any difference in outputs, status or offered
    inputs counts. Independent of the checker's product construction."""
    src, res, _mode = machines_for(source, result)
    follows = getattr(res, "follows_environment", False)
    rng = random.Random(seed)
    for _ in range(runs):
        s, o1 = src.start()
        r, o2 = res.start()
        if tuple(o1) != tuple(o2) or src.status(s) != res.status(r):
            return True
        for _ in range(length):
            offered = list(src.inputs(s))
            if not follows and set(offered) != set(res.inputs(r)):
                return True
            if not offered:
                break
            symbol = rng.choice(offered)
            s, o1 = src.step(s, symbol)
            r, o2 = res.step(r, symbol)
            if tuple(o1) != tuple(o2) or src.status(s) != res.status(r):
                return True
    return False


def judge_mutant(source: Model, result: Model, seed: int, tally: Counter[str]) -> None:
    try:
        report = verify(source, result)
    except InputError as exc:  # the mutation made the model invalid (e.g. an eventless cycle)
        assert "\n" not in str(exc) and exc.message
        tally["mutant refused as invalid"] += 1
        return
    differs = simulation_differs(source, result, seed)
    if not report.equivalent:
        src, res, _mode = machines_for(source, result)
        for prop in report.properties.values():
            if not prop.holds:
                assert prop.counterexample, f"{prop.name} fails without a counterexample"
                inputs = [step.input for step in prop.counterexample[1:]]
                assert replay(src, res, inputs).differs, f"{prop.name}: trace does not replay"
                tally["counterexamples replayed"] += 1
    if differs:
        tally["behaviour-changing"] += 1
        assert not report.equivalent, "simulation finds a difference; the checker says equivalent"
        tally["caught"] += 1
    elif not report.equivalent:
        tally["checker only (replayed)"] += 1
    else:
        tally["no difference found"] += 1


def test_random_mutations_are_caught_with_counterexamples_that_replay() -> None:
    tally: Counter[str] = Counter()

    @BUDGET
    @given(st.one_of(fsms(), bts()), st.integers(0, 2**16), st.booleans())
    def run(model: Model, pick: int, mutate_source: bool) -> None:
        tally["examples"] += 1
        result = convert(model, engine="rules").model
        target = model if mutate_source else result
        candidates = mutants(target, seed=pick, per_operator=2)
        if not candidates:
            tally["no mutant"] += 1
            return
        mutant = candidates[pick % len(candidates)]
        tally[f"operator {mutant.operator}"] += 1
        if mutate_source:
            judge_mutant(mutant.model, result, pick, tally)
        else:
            judge_mutant(model, mutant.model, pick, tally)

    run()
    print("\nmutations:", dict(sorted(tally.items())))
    assert tally["behaviour-changing"] > tally["examples"] // 4
    assert tally["caught"] == tally["behaviour-changing"]
