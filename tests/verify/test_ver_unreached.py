"""Three rules for a per-node check whose failure no planned run reaches (docs/semantics.md
§4d, "Transitions no local check fires" and "Children that never go on"; docs/verification.md
§3, "Random runs").

- *unfired*: a region that breaks condition 2 while no local check fails is walked again with
  condition 2 left out for the transitions no local check followed (``pernode._past_unfired``);
- *stages*: a failing node no run reaches is set aside when a stage on its path is proven never
  to go on (``verify/narrow.py``), and the region is checked again knowing it;
- *random runs*: seeded random leaf outcomes from the root, replayed on the two whole machines
  (``lift.walked_report``), refute a pair only with a run that separates them.

Each is held against the whole product, which uses none of them: a pair proven by a rule is one
the whole product proves, a pair refuted by random runs one it refutes, on small trees where it
decides; each rule decides some pair that was left to the whole product without it. Counts are
printed (``pytest -s``).
"""

from __future__ import annotations

import copy
import random
import sys
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import pytest

from fsmbt import limits
from fsmbt.convert.compress import inline_and_compress
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.verify import compositional, pernode
from fsmbt.verify.compositional import compositional_report
from fsmbt.verify.lift import lift_machines, separates
from fsmbt.verify.narrow import StagesNeverGoingOn
from fsmbt.verify.native import replay
from fsmbt.verify.pernode import NODE_ATTR
from fsmbt.verify.report import PER_NODE
from fsmbt.verify.tickable import NeverReturns, never_ticked, stage_never_passes
from support.pernode_mutants import BOUND, pernode_machine, whole

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402
from test_ver_tickable import (  # noqa: E402
    never_failing_in_one_tick,
    pernode_model,
    sample,
    ticked_nodes,
)


def _sample(count: int, seed: int) -> Iterator[tuple[BTDocument, FSM]]:
    """``test_ver_tickable``'s small trees (the per-node family and ``decorated``) written per
    node, those without a per-node sub-machine left out."""
    for doc in sample(count, seed):
        model = pernode_model(doc)
        if model is not None and pernode_machine(model) is not None:
            yield doc, model


def _retargets(model: FSM, rng: random.Random, count: int) -> Iterator[FSM]:
    """``count`` copies of ``model``, each with one transition of its first per-node
    sub-machine sent to another state of it (a stray jump, most of the time)."""
    sub = pernode_machine(model)
    assert sub is not None
    for _ in range(count):
        mutant = copy.deepcopy(model)
        msub = pernode_machine(mutant)
        assert msub is not None
        t = msub.transitions[rng.randrange(len(msub.transitions))]
        t.target = rng.choice([s for s in msub.states if s != t.target])
        yield mutant


def _per_node(doc: BTDocument, mutant: FSM) -> tuple[bool, dict[str, object]]:
    """Whether the compositional check proves the pair per node, and its stats."""
    with limits.changed(conversion_max_states=BOUND):
        report, _why = compositional_report(doc, mutant, max_states=BOUND)
    if report is None:
        return False, {}
    return report.method == PER_NODE and report.equivalent, report.stats


def test_transitions_no_check_follows_prove_only_what_the_whole_product_proves(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    rng = random.Random(11)
    tally: Counter[str] = Counter()
    for doc, model in _sample(160, seed=41):
        for mutant in _retargets(model, rng, 3):
            proved, stats = _per_node(doc, mutant)
            if not (proved and stats.get("per_node_unfired")):
                continue
            verdict = whole(doc, mutant)
            tally[f"proved past unfired transitions, whole {verdict}"] += 1
            assert verdict is not False, "proven past unfired transitions, refuted whole"
            # without the rule the pair is not proven per node (the rule bought it)
            with monkeypatch.context() as patch:
                patch.setattr(pernode, "UNFIRED_WALKS", 0)
                again, _stats = _per_node(doc, mutant)
            tally[f"without the rule: {'proved' if again else 'not proved'}"] += 1
    print(f"\n[unfired] {dict(tally)}")
    assert tally["proved past unfired transitions, whole True"] >= 10
    assert tally["without the rule: not proved"] >= 10


def _behind_a_stage(seed: int) -> BTDocument:
    """One region (a reactive root) whose second child is ticked only when the first fails:
    half the time the first is ``never_failing_in_one_tick`` (it never fails, though the set
    abstraction says it may: the second child is dead, and only a stage proof sees it), else
    a random ``mixed`` subtree, which can fail."""
    rng = random.Random(seed)
    second = family_tree(rng.choice(("memory", "mixed")), rng.randint(2, 4), seed + 1).main.root
    if rng.random() < 0.5:
        first = never_failing_in_one_tick()
    else:
        first = family_tree("mixed", rng.randint(2, 4), seed).main.root
    return BTDocument.single(BTNode("ReactiveFallback", NodeKind.CONTROL, children=[first, second]))


def _second_child_mutants(doc: BTDocument, model: FSM, rng: random.Random) -> Iterator[FSM]:
    """Copies of ``model`` with one transition out of a state of the root's second child's
    subtree sent anywhere else in the region (its fragment's path starts with ``1``)."""
    sub = pernode_machine(model)
    if sub is None:
        return
    tags = {name: state.attrs.get(NODE_ATTR) or "" for name, state in sub.states.items()}
    inside = [i for i, t in enumerate(sub.transitions) if tags[t.source].startswith("1")]
    for index in rng.sample(inside, min(3, len(inside))):
        mutant = copy.deepcopy(model)
        msub = pernode_machine(mutant)
        assert msub is not None
        t = msub.transitions[index]
        t.target = rng.choice([name for name in msub.states if name != t.target])
        yield mutant


def test_a_stage_that_never_goes_on_sets_aside_only_what_the_whole_product_does(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # a small region is checked whole before any other rule (WHOLE_FIRST): here the rules run
    # on every region, so that the whole product can hold them to account
    monkeypatch.setattr(compositional, "WHOLE_FIRST", 0)
    rng = random.Random(13)
    tally: Counter[str] = Counter()
    for index in range(45):
        doc = _behind_a_stage(5200 + 7 * index)
        model = pernode_model(doc)
        if model is None:
            continue
        for mutant in _second_child_mutants(doc, model, rng):
            verdict = whole(doc, mutant)
            if verdict is None:
                tally["whole product past its bound"] += 1
                continue
            proved, stats = _per_node(doc, mutant)
            staged = bool(stats.get("never_go_on"))
            tally[
                f"whole {verdict}, {'proved past a stage' if staged else 'proved' if proved else 'not'}"
            ] += 1
            if proved:
                assert verdict is True, stats.get("never_go_on")
    print(f"\n[stages] {dict(tally)}")
    assert tally["whole True, proved past a stage"] >= 10
    assert sum(v for k, v in tally.items() if k.startswith("whole False")) >= 10


def test_a_node_dead_behind_a_stage_is_never_ticked_by_the_interpreter() -> None:
    """``never_ticked`` told that a proven stage never goes on: no node it then calls dead is
    ticked by fsmbt's interpreter exploring the whole tree exhaustively."""
    tally: Counter[str] = Counter()
    for index in range(40):
        doc = _behind_a_stage(6300 + 7 * index)
        tree = CompiledTree(BTDocument.single(inline_and_compress(doc).compression.root))
        ticked = ticked_nodes(tree)
        if ticked is None:
            tally["past the limit"] += 1
            continue
        searches = NeverReturns(tree)
        plain = never_ticked(tree)
        for node in tree.nodes:
            proof = stage_never_passes(tree, node.id, searches)
            if proof is None:
                continue
            dead = never_ticked(tree, {proof[0]: proof[1]})
            assert not dead & ticked, [tree.nodes[d].path for d in dead & ticked]
            tally["stages"] += 1
            tally["more dead than without"] += len(dead - plain) > 0
    print(f"\n[dead behind a stage] {dict(tally)}")
    assert tally["more dead than without"] >= 20


def test_random_runs_refute_only_what_the_whole_product_refutes(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With the planned drives off and every region counted large, each failure reaches the
    random runs: a pair they refute is refuted by the whole product, and their counterexample
    separates the two whole machines when replayed."""
    monkeypatch.setattr(compositional, "WHOLE_FIRST", 0)
    planned_or_walked = compositional._use_candidate  # only the walk is left on
    monkeypatch.setattr(
        compositional,
        "_use_candidate",
        lambda *args, walk=False: walk and planned_or_walked(*args, walk=True),
    )
    monkeypatch.setattr(compositional, "_lifted", lambda *_args: None)
    monkeypatch.setattr(compositional, "StagesNeverGoingOn", _NoStages)
    rng = random.Random(17)
    tally: Counter[str] = Counter()
    for doc, model in _sample(120, seed=53):
        for mutant in _retargets(model, rng, 2):
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, mutant, max_states=BOUND)
            if report is None or report.equivalent:
                continue
            assert any("random runs" in a for a in report.abstractions), report.method
            verdict = whole(doc, mutant)
            tally[f"refuted by random runs, whole {verdict}"] += 1
            assert verdict is not True, "random runs refuted a pair the whole product proves"
            trace = next(p.counterexample for p in report.properties.values() if p.counterexample)
            inputs = [str(step.input) for step in trace[1:]]
            assert separates(replay(*lift_machines(doc, mutant), inputs))
    print(f"\n[random runs] {dict(tally)}")
    assert tally["refuted by random runs, whole False"] >= 20


class _NoStages(StagesNeverGoingOn):
    """Stage proofs off (so that the random runs are what decides)."""

    def add_for(self, failing: object) -> bool:
        return False
