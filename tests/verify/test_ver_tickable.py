"""Nodes the tree never ticks (``verify/tickable.py``; docs/semantics.md §4d, "Dead nodes").

Two claims, each against something the analysis does not use:
- *sound*: no node it calls dead is ever ticked by fsmbt's interpreter running the whole
  tree (every reachable snapshot explored, every leaf outcome offered at every request);
- *what it buys*: a one-transition mutant of the per-node machine inside a dead node's
  fragment, or leaving one for anywhere in the region (a stray jump from a state the machine
  never enters), is proven equivalent per node exactly when the whole product proves it, and a
  mutant that lets the parent enter a dead child is never proven (the whole product refutes
  it); a failing region that an earlier region never lets through (``NeverReturns``: the
  subtree run alone, exhaustively) is set aside only where the whole product proves the
  pair. Counts are printed (``pytest -s``).
"""

from __future__ import annotations

import copy
import random
import sys
from collections import Counter
from pathlib import Path

import pytest

from fsmbt import limits
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.compress import inline_and_compress
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledTree, LeafRequest
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify import compositional
from fsmbt.verify.compositional import compositional_report, structure, tree_regions
from fsmbt.verify.pernode import NODE_ATTR, NotPerNode, complete_walk
from fsmbt.verify.report import PER_NODE
from fsmbt.verify.tickable import NeverReturns, never_ticked, stage_never_passes
from support.pernode_mutants import BOUND, pernode_machine, seeded_mutants, whole
from support.pernode_trees import pernode_tree

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402

#: Most snapshots the concrete exploration of one tree holds (a tree past it is skipped).
CONCRETE_LIMIT = 60_000


def merged(doc: BTDocument) -> CompiledTree:
    """The tree as the per-node check reads a region headed by its root (lemma M's merge)."""
    return CompiledTree(BTDocument.single(inline_and_compress(doc).compression.root))


def ticked_nodes(tree: CompiledTree) -> set[int] | None:
    """Every node id the interpreter ticks in some run of ``tree`` (ticks repeated forever,
    every outcome at every leaf), from an exhaustive search of its snapshots; ``None`` past
    ``CONCRETE_LIMIT``. A node is ticked when it is on the call stack: the leaves requested
    and every ancestor of theirs, plus internal leaves met on the way (their frames)."""
    interp = BTInterpreter(tree, exactly_once=True)
    start = interp.initial()
    seen = {(start, None)}
    todo: list[tuple[object, object]] = [(start, None)]
    ticked: set[int] = {0}
    while todo:
        snap, request = todo.pop()
        if request is None:
            moves = [interp.advance(interp.begin_tick(snap), None)]
        else:
            node = tree.nodes[request]
            outcomes = [SUCCESS, FAILURE] + ([RUNNING] if not node.is_condition else [])
            moves = [interp.advance(snap, o) for o in outcomes]
        for nxt, event in moves:
            for frame in nxt[2]:
                ticked.add(frame[0])
            key = (nxt, event.node.id if isinstance(event, LeafRequest) else None)
            if key[1] is not None:
                ticked.add(key[1])
            if key[0][2] == () and key[1] is None:
                key = ((nxt[0], nxt[1], (), False), None)
            if key not in seen:
                if len(seen) >= CONCRETE_LIMIT:
                    return None
                seen.add(key)
                todo.append(key)
    return ticked


def pernode_model(doc: BTDocument) -> FSM | None:
    """``doc`` converted with its regions written per node, within ``BOUND`` states (``None``:
    the converter refuses it)."""
    try:
        with limits.changed(conversion_max_states=BOUND):
            return bt_to_hfsm(doc, pernode=True, max_states=BOUND).model
    except FsmbtError:
        return None


def sample(count: int, seed: int) -> list[BTDocument]:
    rng = random.Random(seed)
    docs = []
    for index in range(count):
        if index % 2:
            docs.append(pernode_tree(rng.randint(3, 8), seed * 1000 + index))
        else:
            docs.append(family_tree("decorated", rng.randint(4, 12), seed * 1000 + index))
    return docs


def test_no_dead_node_is_ever_ticked_by_the_interpreter() -> None:
    """Both proofs: the set abstraction (``never_ticked``) and a stage that never goes on
    (``stage_never_passes``, the subtree run alone)."""
    tally: Counter[str] = Counter()
    for doc in sample(160, seed=31):
        tree = merged(doc)
        ticked = ticked_nodes(tree)
        if ticked is None:
            tally["past the limit"] += 1
            continue
        dead = never_ticked(tree)
        assert not dead & ticked, [tree.nodes[d].path for d in dead & ticked]
        searches = NeverReturns(tree)
        for node in tree.nodes:
            if stage_never_passes(tree, node.id, searches) is not None:
                assert node.id not in ticked, node.path
                tally["never ticked by a stage"] += 1
        tally["trees"] += 1
        tally["nodes"] += len(tree.nodes)
        tally["dead"] += len(dead)
        tally["never ticked"] += len(tree.nodes) - len(ticked)
    print(f"\n[tickable] {dict(tally)}")
    assert tally["trees"] >= 120
    assert tally["dead"] >= 60  # the sample has dead code to find
    assert tally["never ticked by a stage"] >= 60
    # what the over-approximation misses (concretely dead, called live) stays small
    assert tally["dead"] >= 0.8 * tally["never ticked"], dict(tally)


def _dead_paths(doc: BTDocument) -> tuple[set[str], set[str]] | None:
    """(paths of dead nodes, paths of their live parents) when the whole tree is one region
    written per node (else ``None``)."""
    regions = tree_regions(doc)
    if len(regions) != 1 or regions[0] is not doc.main.root:
        return None
    tree = merged(doc)
    dead = never_ticked(tree)
    parents = {tree.nodes[tree.nodes[d].parent].path for d in dead} - {
        tree.nodes[d].path for d in dead
    }
    return {tree.nodes[d].path for d in dead}, parents


def test_mutants_inside_dead_fragments_are_proven_and_entering_one_is_not() -> None:
    rng, stray = random.Random(5), random.Random(6)
    tally: Counter[str] = Counter()
    for doc in sample(240, seed=37):
        paths = _dead_paths(doc)
        if not paths or not paths[0]:
            continue
        dead, parents = paths
        model = pernode_model(doc)
        sub = None if model is None else pernode_machine(model)
        if model is None or sub is None:
            continue
        inside = [t for t in sub.transitions if sub.states[t.source].attrs.get(NODE_ATTR) in dead]
        entries = {
            t.target
            for t in sub.transitions
            if sub.states[t.target].attrs.get(NODE_ATTR) in dead
            and sub.states[t.source].attrs.get(NODE_ATTR) not in dead
        }
        into = [t for t in sub.transitions if sub.states[t.source].attrs.get(NODE_ATTR) in parents]
        cases: list[tuple[str, int, str]] = []
        if inside:  # retargeted within its own node's fragment: the side conditions hold
            t = inside[rng.randrange(len(inside))]
            tag = sub.states[t.source].attrs.get(NODE_ATTR)
            same = [n for n, st in sub.states.items() if st.attrs.get(NODE_ATTR) == tag]
            cases.append(("inside", sub.transitions.index(t), rng.choice(same)))
        if inside:  # retargeted anywhere else: a stray jump, but from a state never entered
            t = inside[stray.randrange(len(inside))]
            tag = sub.states[t.source].attrs.get(NODE_ATTR)
            other = [n for n, st in sub.states.items() if st.attrs.get(NODE_ATTR) != tag]
            cases.append(("out of", sub.transitions.index(t), stray.choice(other)))
        if into and entries:
            t = rng.randrange(len(into))
            cases.append(("into", sub.transitions.index(into[t]), rng.choice(sorted(entries))))
        for kind, index, target in cases:
            mutant = copy.deepcopy(model)
            msub = pernode_machine(mutant)
            assert msub is not None
            if msub.transitions[index].target == target:
                continue
            msub.transitions[index].target = target
            verdict = whole(doc, mutant)
            if verdict is None:
                continue
            with limits.changed(conversion_max_states=BOUND):
                report, _why = compositional_report(doc, mutant, max_states=BOUND)
            proved = report is not None and report.method == PER_NODE and report.equivalent
            tally[f"{kind}: whole {verdict}, per node {'proved' if proved else 'not'}"] += 1
            if proved:
                assert verdict is True, f"per node proved a {kind} mutant the whole product refutes"
            if kind in ("inside", "out of") and verdict is True:
                assert proved, f"a mutant inside a dead fragment left to the whole product: {_why}"
    print(f"\n[dead fragments] {dict(tally)}")
    assert tally["inside: whole True, per node proved"] >= 20
    assert tally["out of: whole True, per node proved"] >= 20
    assert sum(v for k, v in tally.items() if k.startswith("into: whole False")) >= 10


def _pernode_machines(model: FSM) -> list[FSM]:
    """Every sub-machine the converter wrote per node, in the model's walk order."""
    return [
        state.regions[0]
        for _path, _machine, state in model.walk()
        if state.regions and state.regions[0].name.startswith("pernode_")
    ]


def _writes(machine: FSM, region: BTNode) -> bool:
    """Whether ``machine`` is the per-node machine of ``region``: each state of a control node
    is named after the type of the node its tag names (``Type.role#n``)."""
    types = {n.path: n.type for n in merged(BTDocument.single(region)).nodes}
    controls = [
        (state.attrs.get(NODE_ATTR), name.split(".")[0])
        for name, state in machine.states.items()
        if "." in name and state.attrs.get(NODE_ATTR) is not None
    ]
    return bool(controls) and all(types.get(path) == kind for path, kind in controls)


def _node(kind: str, *children: BTNode, **attrs: str) -> BTNode:
    if not children:
        leaf = NodeKind.CONDITION if kind == "Check" else NodeKind.ACTION
        return BTNode(kind, leaf)
    family = NodeKind.DECORATOR if len(children) == 1 and kind != "Sequence" else NodeKind.CONTROL
    return BTNode(kind, family, attrs=dict(attrs), children=list(children))


def never_failing_in_one_tick() -> BTNode:
    """A ``ReactiveFallback`` whose two children can each fail, but never in the same tick
    (met in the 11 727-node ``decorated`` tree of ``bench_reactive.py``): the set abstraction
    of ``never_ticked`` says it may fail, the subtree run alone says it never does."""
    one = {"success_count": "1", "failure_count": "1"}
    two = {"num_attempts": "2"}
    do, check = _node("Do"), _node("Check")
    return _node(
        "ReactiveFallback",
        _node(
            "Parallel",
            _node("Fallback", _node("Do"), _node("Do"), _node("Do")),
            _node(
                "SequenceWithMemory",
                _node("Check"),
                _node("ForceSuccess", _node("Do")),
                _node("Check"),
                _node("Do"),
            ),
            _node("Parallel", _node("Check"), check, **one),
            **one,
        ),
        _node(
            "ReactiveFallback",
            _node(
                "ReactiveFallback",
                _node("RetryUntilSuccessful", _node("Do"), **two),
                _node("RetryUntilSuccessful", _node("Do"), **two),
                _node("Do"),
            ),
            _node("ReactiveSequence", _node("Do"), _node("Do"), _node("Do"), _node("Check")),
            _node(
                "SequenceWithMemory",
                _node("Do"),
                _node("ForceFailure", _node("Do")),
                _node("Do"),
                _node("Check"),
            ),
            _node("Fallback", do, _node("Do")),
        ),
    )


def _two_regions(seed: int) -> BTDocument:
    """A plain ``Fallback`` or ``Sequence`` over two regions: the first decides whether the
    second is ever ticked - ``never_failing_in_one_tick`` under a Fallback half the time
    (the second region then never ticked, though the converter writes it), else a random
    ``mixed`` region - the second a random region with memory."""
    rng = random.Random(seed)
    second = family_tree(rng.choice(("memory", "mixed")), rng.randint(3, 5), seed + 1).main.root
    if rng.random() < 0.5:
        first, kind = never_failing_in_one_tick(), "Fallback"
    else:
        first = family_tree("mixed", rng.randint(3, 6), seed).main.root
        kind = rng.choice(("Sequence", "Fallback"))
    return BTDocument.single(BTNode(kind, NodeKind.CONTROL, children=[first, second]))


def test_a_region_never_ticked_is_set_aside_only_when_the_whole_product_agrees(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Mutants of the *second* region's per-node machine (found by its node types): the
    compositional check sets the region aside (``regions_never_ticked``) only when the whole
    product proves the pair, and a mutant of a region that is ticked is never proven. The
    lift is switched off, so that every failing region - real differences included - reaches
    the never-ticked rule (with it, a real difference is refuted before the rule is asked)."""
    monkeypatch.setattr(compositional, "_lifted", lambda *_args: None)
    rng = random.Random(11)
    tally: Counter[str] = Counter()
    for index in range(400):
        doc = _two_regions(4100 + 7 * index)
        model = pernode_model(doc)
        if model is None or len(_pernode_machines(model)) < 2:
            continue
        mutant = copy.deepcopy(model)
        subs = [m for m in _pernode_machines(mutant) if _writes(m, doc.main.root.children[1])]
        if len(subs) != 1:
            continue
        sub = subs[0]
        t = rng.choice(sub.transitions)
        tag = sub.states[t.source].attrs.get(NODE_ATTR)
        same = [n for n, st in sub.states.items() if st.attrs.get(NODE_ATTR) == tag]
        if len(same) < 2:
            continue
        t.target = rng.choice([n for n in same if n != t.target])
        verdict = whole(doc, mutant)
        if verdict is None:
            continue
        with limits.changed(conversion_max_states=BOUND):
            report, _why = compositional_report(doc, mutant, max_states=BOUND)
        aside = report is not None and bool(report.stats.get("regions_never_ticked"))
        proved = report is not None and report.equivalent
        tally[f"whole {verdict}, {'set aside' if aside else 'proved' if proved else 'not'}"] += 1
        if proved:
            assert verdict is True, (index, report.stats.get("never_ticked_by"))
        if aside:
            assert any("never returns" in p for p in report.stats["never_ticked_by"])
    print(f"\n[regions never ticked] {dict(tally)}")
    assert tally["whole True, set aside"] >= 10
    assert sum(v for k, v in tally.items() if k.startswith("whole False")) >= 8


def test_the_complete_walk_never_takes_a_failing_child_for_a_dead_one() -> None:
    """A failing node settled with an empty interface (its check failed before any status
    paired) is ticked by its parent's tree side like any live child; only the children the
    tree never ticks refuse when ticked. (Mistaking one for the other made the complete walk
    refuse, and the lower bound vanish, on the 15 560-node mutant of ``bench_reactive.py``.)"""
    tally: Counter[str] = Counter()
    for doc, _model, mutants in seeded_mutants(160, seed=4, rng_seed=27):
        for mutant in mutants:
            try:
                shape = structure(doc, mutant)
            except FsmbtError:
                continue
            for k, region in enumerate(shape.machine_regions):
                if not region.machine.name.startswith("pernode_") or k >= len(shape.regions):
                    continue
                try:
                    walk = complete_walk(shape.regions[k], region.machine, shape.declared)
                except NotPerNode as exc:
                    assert "proven never ticked" not in str(exc)
                    tally["refused"] += 1
                    continue
                tally["walked"] += 1
                empty = [f for f in walk.failed if not f.sigma]
                tally["failing with an empty interface"] += len(empty)
    print(f"\n[complete walk] {dict(tally)}")
    assert tally["walked"] >= 50
    assert tally["failing with an empty interface"] >= 5


def test_behaviortree_cpp_never_gets_past_the_never_failing_fallback() -> None:
    """The real engine agrees on the example the rule is built for: BehaviorTree.CPP 4.8 runs
    ``Fallback(never_failing_in_one_tick(), Sentinel)`` under 400 seeded scripts (12 ticks
    each, ``tickExactlyOnce``) and never ticks ``Sentinel`` (nor does the root fail), while the
    last leaf each child of the ``ReactiveFallback`` asks fails in hundreds of ticks (the
    scripts do drive both towards failing)."""
    from fsmbt.semantics.engines.btcpp_engine import BTCppRunner
    from support.random_trees import OutcomeScript

    sentinel = BTNode("Sentinel", NodeKind.ACTION, name="Sentinel")
    root = BTNode("Fallback", NodeKind.CONTROL, children=[never_failing_in_one_tick(), sentinel])
    doc = BTDocument.single(root)
    tree = merged(doc)
    assert stage_never_passes(tree, tree.nodes[0].children[1], NeverReturns(tree)) is not None
    failed: Counter[str] = Counter()
    for seed in range(400):
        engine = BTCppRunner(doc, OutcomeScript(seed), exactly_once=True)
        for _ in range(12):
            record = engine.tick_once()
            assert all(not path.startswith("1") for _label, path, _o in record.leaves), seed
            assert record.result != "FAILURE", seed
            last = {path.split("/")[1]: outcome for _label, path, outcome in record.leaves}
            for child, outcome in last.items():
                failed[f"last leaf under child {child}: {outcome}"] += 1
    print(f"\n[BehaviorTree.CPP] {dict(failed)}")
    assert failed["last leaf under child 0: failure"] > 100
    assert failed["last leaf under child 1: failure"] > 100
