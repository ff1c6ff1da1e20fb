"""One-transition mutants of the per-node sub-machines ``bt_to_hfsm`` writes, and the whole
product's verdict on small pairs: shared by the per-node, lift and certificate tests.

``mutate(model, rng)``: a copy of ``model`` with one transition of its first per-node
sub-machine retargeted, its guard dropped, one assignment dropped or its value changed.
``whole(doc, model)``: the whole-product verdict, ``None`` past ``BOUND`` states;
``whole_shortest(doc, model)``: the length of its shortest counterexample.
``seeded_mutants(...)``: the seeded trees written per node, each with its model and mutants -
the one sample the per-node, lift and NuSMV per-node tests and ``bench_lift.py`` draw.
"""

from __future__ import annotations

import copy
import random
from collections.abc import Iterator

from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import ASSIGN, COND, parse_lines
from fsmbt.verify.compositional import compositional_report
from fsmbt.verify.native import check
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import LIFTED, Report
from support.pernode_trees import seeded_trees

#: Most states per machine or product here: a mutant may blow a machine up (seconds each).
BOUND = 4_000


def pernode_machine(model: FSM) -> FSM | None:
    """The first sub-machine the converter wrote per node (``None``: there is none)."""
    for _path, _machine, state in model.walk():
        if state.regions and state.regions[0].name.startswith("pernode_"):
            return state.regions[0]
    return None


def mutate(model: FSM, rng: random.Random) -> FSM | None:
    """One transition of the first per-node sub-machine changed (``None``: nothing to do)."""
    mutant = copy.deepcopy(model)
    sub = pernode_machine(mutant)
    if sub is None:
        return None
    t = rng.choice(sub.transitions)
    operator = rng.choice(("retarget", "guard", "assignment", "value"))
    pairs = parse_lines(t.attrs.get(ASSIGN, ""))
    if operator == "guard" and COND in t.attrs:
        del t.attrs[COND]
    elif operator in ("assignment", "value") and pairs:
        i = rng.randrange(len(pairs))
        if operator == "assignment":
            del pairs[i]
        else:
            pairs[i] = (pairs[i][0], "1" if pairs[i][1] != "1" else "0")
        t.attrs[ASSIGN] = "\n".join(f"{n}={e}" for n, e in pairs)
        if not pairs:
            del t.attrs[ASSIGN]
    else:
        t.target = rng.choice([s for s in sub.states if s != t.target])
    return mutant


def whole(doc: BTDocument, model: FSM) -> bool | None:
    """The whole product's verdict on a small pair (``None``: not a machine, or past BOUND)."""
    try:
        with limits.changed(conversion_max_states=BOUND):  # the data expansion too
            source, result, _mode = machines_for(doc, model)
            return check(source, result, max_states=BOUND).equivalent
    except FsmbtError:
        return None  # an eventless cycle without a leaf (not a machine), or past BOUND


def whole_shortest(doc: BTDocument, model: FSM) -> int | None:
    """The whole product's shortest counterexample length (inputs; native breadth-first
    search), ``-1`` when it proves the pair, ``None`` past ``BOUND`` states."""
    try:
        with limits.changed(conversion_max_states=BOUND):
            source, result, _mode = machines_for(doc, model)
            report = check(source, result, max_states=BOUND)
    except FsmbtError:
        return None
    if report.equivalent:
        return -1
    return min(len(p.counterexample) - 1 for p in report.properties.values() if p.counterexample)


def seeded_mutants(
    trees: int, *, seed: int, rng_seed: int, per_tree: int = 2
) -> Iterator[tuple[BTDocument, FSM, list[FSM]]]:
    """``seeded_trees(trees, seed=seed)`` converted per node, the trees without a per-node
    sub-machine skipped, each with ``per_tree`` mutants drawn in order from one
    ``random.Random(rng_seed)``: the same sample wherever it is drawn."""
    rng = random.Random(rng_seed)
    for doc in seeded_trees(trees, seed=seed):
        model = bt_to_hfsm(doc, pernode=True).model
        if pernode_machine(model) is None:
            continue
        mutants = [mutate(model, rng) for _ in range(per_tree)]
        assert all(m is not None for m in mutants)
        yield doc, model, [m for m in mutants if m is not None]


def lifted_reports(count: int) -> Iterator[tuple[BTDocument, FSM, Report]]:
    """(tree, mutant, report) for the mutants of ``seeded_mutants(count, seed=4, rng_seed=5)``
    that the compositional check refutes by a lifted counterexample (``report.method`` in
    ``LIFTED``): the sample the shortest-counterexample tests read."""
    for doc, _model, mutants in seeded_mutants(count, seed=4, rng_seed=5):
        for mutant in mutants:
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, mutant, max_states=BOUND)
            if report is not None and report.method in LIFTED:
                yield doc, mutant, report
