"""Reachability from NuSMV's listing of the reachable states (docs/nusmv.md, "Fifth round:
reachability from the listed states"; ``fsmbt.verify.nusmv.reach``): on seeded FSM ~ FSM
mutants it gives the verdict of the frozen-copy spec it replaces and of the native checker,
names the same unmatched states as the native checker, and its witness is as short as the
native one and replays (on the native machines) to a real difference; so do failing FSM ~
dispatch pairs in both orders; the listing is the faithful product and the source's own
states; a 300-state mutant and copy are decided and agree."""

from __future__ import annotations

import copy
import os
import random
import re

from fsmbt.generate.generator import random_fsm
from fsmbt.model.fsm import FSM, State
from fsmbt.verify import nusmv, verify
from fsmbt.verify.native import replay
from fsmbt.verify.nusmv import reach
from fsmbt.verify.nusmv.runner import list_reachable
from fsmbt.verify.nusmv.specs import REACH, SEEN, product
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import REACHABILITY

SEED = int(os.environ.get("FSMBT_TEST_SEED", "27"))


def _mutant(source: FSM, rng: random.Random) -> FSM:
    """``source`` with one transition retargeted."""
    mutant = copy.deepcopy(source)
    transition = mutant.transitions[rng.randrange(len(mutant.transitions))]
    transition.target = rng.choice([n for n in mutant.states if n != transition.target])
    return mutant


def _named(detail: str) -> tuple[int, set[str]]:
    """The count and the names of ``N source state(s) never reached ...: A, B`` (source side)."""
    head, _, names = detail.split(";")[0].partition(": ")
    return int(head.split()[0]), {n.strip() for n in names.split(",") if n.strip() != "..."}


def _check_witness(source: FSM, result: FSM, native_trace: list, trace: list) -> None:
    assert trace and trace[0].input is None
    assert len(trace) == len(native_trace)  # both shortest
    inputs = [step.input for step in trace[1:]]
    src, res, _mode = machines_for(source, result)
    replayed = replay(src, res, inputs)
    assert replayed.differs  # had every step agreed, the last state would be matched
    for ours, theirs in zip(trace, replayed.steps):  # NuSMV's replay is the native one
        assert (ours.source_state, ours.result_state) == (theirs.source_state, theirs.result_state)
        assert (ours.source_outputs, ours.result_outputs) == (
            theirs.source_outputs,
            theirs.result_outputs,
        )


def test_state_by_state_agrees_with_frozen_copies_and_native(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED)
    unreached = compared = 0
    while compared < 12:
        source = random_fsm(rng.randrange(10**9), n_states=rng.randint(4, 12))
        result = _mutant(source, rng)
        native = verify(source, result)
        if native.equivalent:
            continue  # reachability is then implied; the state-by-state run is not made
        compared += 1
        new = nusmv.check(source, result)
        old = nusmv.check(source, result, state_reach=False)
        assert new.verdicts() == old.verdicts() == native.verdicts()
        ours, theirs = new.properties[REACHABILITY], native.properties[REACHABILITY]
        if ours.holds:
            # the invariants with the listing of the reachable states, the CTL run
            assert ours.detail == reach.STATES_DETAIL and new.stats["nusmv_runs"] == 2
            continue
        unreached += 1
        # the invariants with the listing, the CTL run, the witness and its replay
        assert new.stats["nusmv_runs"] == 4
        count, names = _named(ours.detail)
        native_count, native_names = _named(theirs.detail)
        assert count == native_count
        if count <= 5:
            assert names == native_names
        _check_witness(source, result, theirs.counterexample or [], ours.counterexample or [])
    assert unreached >= 3  # the sample exercises the failing verdict and its witness


def test_start_pair_disagreeing_gives_an_empty_witness(nusmv_binary, monkeypatch) -> None:
    """The start outputs differ: F is empty, every state is unmatched, the witness is the start
    alone (the replay model then has no input: its counter ``k`` must not be a constant)."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    source, result = FSM(name="a"), FSM(name="b")
    for fsm, action in ((source, "hello"), (result, "bye")):
        fsm.add_state(State("A", action=action))
        fsm.add_state(State("B", action="x", final=True))
        fsm.initial = "A"
        fsm.add_transition("A", "go", "B")
    native = verify(source, result)
    report = nusmv.check(source, result)
    assert report.verdicts() == native.verdicts()
    assert not report.properties[REACHABILITY].holds
    assert _named(report.properties[REACHABILITY].detail) == (2, {"A", "B"})
    trace = report.properties[REACHABILITY].counterexample or []
    assert [step.input for step in trace] == [None]
    assert (trace[0].source_outputs, trace[0].result_outputs) == (["hello"], ["bye"])


def test_the_listing_is_every_reachable_state_classified_by_nusmv(nusmv_binary, monkeypatch):
    """The ``REACH`` model keeps no frozen copy and no CTL; NuSMV lists its reachable states
    with ``seen``: the listed ``fa`` states are exactly the faithful product's pairs and the
    ``sa`` states exactly the source's own states, both found here by walking the two FSMs
    (an explicit search independent of NuSMV and of the native checker's product)."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED + 1)
    source = random_fsm(rng.randrange(10**9), n_states=7)
    mutant = _mutant(source, rng)
    src_enc, res_enc, inputs, _outputs, _mode = nusmv.encode(source, mutant)
    src, res = src_enc.encode(), res_enc.encode()
    prod = product(src, res, inputs, part=REACH, listing=True)
    assert re.search(r"\b(ts|tr)_\w+", prod.text) is None  # no frozen copy
    assert re.search(r"\b(EF|AG|EX)\b", prod.text) is None and "INVARSPEC" not in prod.text
    states, _seconds = list_reachable(src.text + "\n" + res.text + "\n" + prod.text)
    code = {name: code for code, name in src_enc.codes.to_name.items()}
    rcode = {name: code for code, name in res_enc.codes.to_name.items()}
    faithful = {(st["s.q"], st["r.q"]) for st in states if st[SEEN] == "fa"}
    alone = {st["s.q"] for st in states if st[SEEN] == "sa"}
    # the faithful product and the source's own states by the interpreter's machines
    s_m, r_m, _mode = machines_for(source, mutant)
    (s0, s_out), (r0, r_out) = s_m.start(), r_m.start()

    def agree(a: str, b: str, a_out: tuple, b_out: tuple) -> bool:
        return a_out == b_out and s_m.status(a) == r_m.status(b)

    pairs: set[tuple[str, str]] = set()
    todo = [(s0, r0)] if agree(s0, r0, s_out, r_out) else []
    while todo:
        a, b = todo.pop()
        if (a, b) in pairs:
            continue
        pairs.add((a, b))
        for event in set(s_m.inputs(a)) & set(r_m.inputs(b)):
            (u, u_out), (w, w_out) = s_m.step(a, event), r_m.step(b, event)
            if agree(u, w, u_out, w_out):
                todo.append((u, w))
    assert len(pairs) > 1 and faithful == {(code[a], rcode[b]) for a, b in pairs}
    own: set[str] = set()
    todo_s = [s0]
    while todo_s:
        a = todo_s.pop()
        if a not in own:
            own.add(a)
            todo_s += [s_m.step(a, event)[0] for event in s_m.inputs(a)]
    assert len(own) > 1 and alone == {code[a] for a in own}


def test_300_states_copy_and_mutant_are_decided_and_agree(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED + 300)
    source = random_fsm(rng.randrange(10**9), n_states=300)
    mutant = _mutant(source, rng)
    for result in (copy.deepcopy(source), mutant):
        native = verify(source, result)
        report = nusmv.check(source, result)
        assert report.verdicts() == native.verdicts()
    assert not native.equivalent  # the mutant's failing path ran


def test_state_codes_round_trip_and_exclude_unused_words() -> None:
    """Each FSM state is one ``unsigned word`` constant (its index) that decodes back to its
    name; the width is the fewest bits that hold every state, and the codes past the last one
    are excluded by an ``INVAR`` exactly when there are some."""
    for size in (1, 2, 5, 8, 9):
        fsm = FSM(name=f"n{size}")
        for i in range(size):
            fsm.add_state(State(f"S{i}", action=f"a{i}", final=i == size - 1))
        fsm.initial = "S0"
        for i in range(size - 1):
            fsm.add_transition(f"S{i}", f"e{i}", f"S{i + 1}")
        src_enc, _res_enc, _inputs, _outputs, _mode = nusmv.encode(fsm, copy.deepcopy(fsm))
        enc = src_enc.encode()
        bits = max(1, (size - 1).bit_length())
        assert enc.id_vars == [("q", f"unsigned word[{bits}]")]
        assert enc.id_values == [f"0ud{bits}_{i}" for i in range(size)]
        assert [enc.decode_state({"q": code}) for code in enc.id_values] == list(fsm.states)
        assert ("INVAR" in enc.text) == ((1 << bits) > size)
        assert f"init(q) := {enc.id_values[0]};" in enc.text
        statuses = [src_enc.status_of({"q": code}) for code in enc.id_values]
        assert statuses == ["running"] * (size - 1) + ["final"]


def test_one_state_machines_use_a_one_bit_word(nusmv_binary, monkeypatch) -> None:
    """A one-state FSM is a ``word[1]`` with its unused code excluded; NuSMV decides both an
    equal and a different one-state pair as the native checker does."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    a, b = FSM(name="a"), FSM(name="b")
    a.add_state(State("X", action="x"))
    b.add_state(State("Y", action="y"))
    a.initial, b.initial = "X", "Y"
    for result in (copy.deepcopy(a), b):
        report = nusmv.check(a, result)
        assert report.verdicts() == verify(a, result).verdicts()
    assert _named(report.properties[REACHABILITY].detail) == (1, {"X"})


def test_dispatch_pairs_failing_reachability_get_a_replayed_witness(
    nusmv_binary, monkeypatch
) -> None:
    """FSM ~ dispatch tree pairs (both orders) leave the frozen-copy spec too: a mutant of the
    FSM against the original's tree whose reachability fails gets the native verdict from the
    listing, a witness as short as the native one that replays on the native machines to a
    real difference, and the FSM side's unmatched states named as the native checker names
    them."""
    from fsmbt.convert import convert

    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED + 2)
    failing = {"fsm first": 0, "tree first": 0}
    for _ in range(40):
        source = random_fsm(rng.randrange(10**9), n_states=rng.randint(4, 12))
        tree = convert(source, style="dispatch").model
        mutant = _mutant(source, rng)
        for a, b in ((mutant, tree), (tree, mutant)):
            native = verify(a, b)
            ours = nusmv.check(a, b)
            assert ours.verdicts() == native.verdicts()
            mine, theirs = ours.properties[REACHABILITY], native.properties[REACHABILITY]
            if mine.holds:
                continue
            failing["fsm first" if a is mutant else "tree first"] += 1
            assert ours.stats["nusmv_runs"] == 4  # listing with invariants, CTL, witness x2
            if a is mutant:  # the FSM is the source: its unmatched states, by name
                (count, names), (native_count, native_names) = map(
                    _named, (mine.detail, theirs.detail)
                )
                assert count == native_count and (count > 5 or names == native_names)
            _check_witness(a, b, theirs.counterexample or [], mine.counterexample or [])
        if min(failing.values()) >= 2:
            break
    assert min(failing.values()) >= 2, failing  # the failing verdict, in both orders


def _counts(detail: str) -> dict[str, int]:
    """``{"source": N, "result": M}`` from a failing reachability detail (either side)."""
    return {side: int(n) for n, side in re.findall(r"(\d+) (source|result) state", detail)}


def _region_mutant(machine: FSM, rng: random.Random) -> FSM:
    """``machine`` (hierarchical, outcome-driven) with one transition of one of its regions
    retargeted to another state of that region."""
    mutant = copy.deepcopy(machine)
    regions = [m for _p, m, _s in mutant.walk() if m.transitions]
    regions += [r for _p, _m, s in mutant.walk() for r in s.regions if r.transitions]
    region = rng.choice(regions or [mutant])
    transition = region.transitions[rng.randrange(len(region.transitions))]
    transition.target = rng.choice([n for n in region.states if n != transition.target])
    return mutant


def _micro_step_pairs(rng: random.Random):  # type: ignore[no-untyped-def]
    """Failing pairs whose tree takes micro-steps (``check`` does not split them): an
    outcome-driven machine with one transition retargeted against its structured tree."""
    from fsmbt.convert.structured import fsm_to_structured
    from fsmbt.generate.outcome_machines import random_outcome_fsm

    for size in (4, 5, 6, 7, 8, 5, 6, 7, 8, 10):
        machine = random_outcome_fsm(rng.randrange(10**9), states=size, containers=0.2)
        tree = fsm_to_structured(machine).model
        yield _region_mutant(machine, rng), tree, nusmv.AUTO


def test_micro_step_pairs_read_reachability_off_the_listing(nusmv_binary, monkeypatch) -> None:
    """A failing structured pair (not split: the tree takes micro-steps) gets reachability from
    the listing too, not the frozen-copy spec (a transitive closure: a 10-state structured mutant passed 120 s there, the listing
    decides it): the same verdicts as that spec and the native checker, the same number of
    unmatched states per side, a witness that ends in a difference (at least as long as the
    native one: NuSMV's search is breadth first in its own steps, micro-steps included)."""
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    rng = random.Random(SEED)
    listed = unreached = 0
    for source, result, encoding in _micro_step_pairs(rng):
        native = verify(source, result)
        if native.equivalent:
            continue
        new = nusmv.check(source, result, tree_encoding=encoding)
        old = nusmv.check(source, result, tree_encoding=encoding, state_reach=False)
        assert new.verdicts() == old.verdicts() == native.verdicts()
        ours, theirs = new.properties[REACHABILITY], native.properties[REACHABILITY]
        if ours.detail == reach.STATES_DETAIL:
            listed += 1
        elif not ours.holds:
            unreached += 1
            assert _counts(ours.detail) == _counts(theirs.detail)
            # NuSMV's path is breadth first in its own steps, micro-steps included, so it may
            # take more inputs than the native shortest; it still ends in a difference
            trace = ours.counterexample or []
            assert trace and trace[0].input is None
            assert len(trace) >= len(theirs.counterexample or [])
            last = trace[-1]
            assert (last.source_outputs, last.source_status) != (
                last.result_outputs,
                last.result_status,
            )
    assert listed + unreached >= 4 and unreached >= 2, (listed, unreached)
