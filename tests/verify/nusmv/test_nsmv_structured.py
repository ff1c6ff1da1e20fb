"""NuSMV checks the outcome pairing (docs/nusmv.md, "The outcome pairing (structured trees)";
docs/semantics.md §11): on the structured conversion of generated outcome-driven machines and
of the corpus' SMACH/FlexBE files, and on one-change mutants of each (a swapped outcome, a
wrong child order, a dropped state), NuSMV and the native checker give the same five verdicts;
mutants that differ are found by both, with counterexamples in the machine's own words; what
the encoding does not cover is refused by name, and ``--engine both`` then keeps the native
verdict; the CLI prints both engines' verdict."""

from __future__ import annotations

import copy
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert.structured import fsm_to_structured
from fsmbt.generate.outcome_machines import random_outcome_fsm
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import FsmbtError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.verify import verify
from fsmbt.verify.nusmv import check
from support.corpus import CORPUS
from support.structured_machines import machine, pipeline

pytestmark = pytest.mark.usefixtures("nusmv_binary")

DISPATCH = {
    "Look": {"found": "Grasp", "lost": "Search", "blocked": "aborted"},
    "Grasp": {"succeeded": "succeeded", "aborted": "aborted"},
    "Search": {"succeeded": "Grasp", "aborted": "aborted"},
}
LOOP = {
    "A": {"succeeded": "B", "aborted": "A"},
    "B": {"succeeded": "succeeded", "aborted": "aborted"},
}
BRANCH = {
    "A": {"succeeded": "B", "aborted": "C"},
    "B": {"succeeded": "succeeded", "aborted": "aborted"},
    "C": {"succeeded": "succeeded", "aborted": "aborted"},
}
#: The corpus' SMACH, FlexBE and YASMIN files (read-only, never copied).
FSM_DIR = CORPUS / "fsm"
CORPUS_FILES = sorted(
    [
        *FSM_DIR.glob("smach_tutorials/*.py"),
        *FSM_DIR.glob("smach_tests/*.py"),
        *FSM_DIR.glob("flexbe_turtlesim_demo/*_sm.py"),
        *FSM_DIR.glob("yasmin/*.xml"),
    ]
)
#: Trees up to this many nodes are checked with their mutants here (~60 s in all); the
#: benchmark (benchmarks/bench_nusmv_agreement.py --style structured) runs every file.
MAX_NODES = 20


def _agree(fsm: FSM, doc: BTDocument) -> bool:
    """Both engines' five verdicts, asserted equal; the native verdict."""
    native = verify(fsm, doc, outcome_driven=True)
    symbolic = check(fsm, doc, outcome_driven=True)
    assert symbolic.verdicts() == native.verdicts(), (native.verdicts(), symbolic.verdicts())
    return bool(native.equivalent)


def _state_leaves(doc: BTDocument, fsm: FSM) -> list[tuple[BTNode, BTNode]]:
    """(parent, leaf) for every leaf named after a state of ``fsm``."""
    names = {s for _p, _m, s in ((p, m, s.name) for p, m, s in fsm.walk())}
    return [
        (parent, child)
        for _t, parent in doc.nodes()
        for child in parent.children
        if child.is_leaf and child.name in names
    ]


def tree_mutants(fsm: FSM, doc: BTDocument) -> Iterator[tuple[str, BTDocument]]:
    """One change each: a wrong child order, a swapped outcome, a dropped state."""
    order = copy.deepcopy(doc)
    for _t, node in order.nodes():
        if node.type in ("Sequence", "Fallback") and len(node.children) >= 2:
            node.children[0], node.children[1] = node.children[1], node.children[0]
            yield "wrong child order", order
            break
    swapped = copy.deepcopy(doc)
    for _t, node in swapped.nodes():
        if node.type.startswith("Switch"):
            node.attrs["case_1"], node.attrs["case_2"] = node.attrs["case_2"], node.attrs["case_1"]
            yield "swapped outcome (Switch cases)", swapped
            break
        if node.type == "IfThenElse" and len(node.children) == 3:
            node.children[1], node.children[2] = node.children[2], node.children[1]
            yield "swapped outcome (branches)", swapped
            break
    else:
        leaves = _state_leaves(swapped, fsm)
        if leaves:
            parent, leaf = leaves[0]
            index = parent.children.index(leaf)
            parent.children[index] = BTNode("Inverter", NodeKind.DECORATOR, children=[leaf])
            yield "swapped outcome (inverted leaf)", swapped
    dropped = copy.deepcopy(doc)
    leaves = _state_leaves(dropped, fsm)
    if leaves:
        parent, leaf = leaves[-1]
        if len(parent.children) > 1 and parent.type in ("Sequence", "Fallback"):
            parent.children.remove(leaf)
        else:
            leaf.name = "Dropped"
        yield "dropped state", dropped


def fsm_mutant(fsm: FSM) -> FSM | None:
    """The machine with the targets of one state's two outcomes swapped (one transition each)."""
    wrong = copy.deepcopy(fsm)
    for _path, region, state in wrong.walk():
        outgoing = [t for t in region.transitions if t.source == state.name and t.event]
        if len(outgoing) >= 2 and outgoing[0].target != outgoing[1].target:
            outgoing[0].target, outgoing[1].target = outgoing[1].target, outgoing[0].target
            return wrong
    return None


def machines() -> Iterator[tuple[str, FSM]]:
    yield "pipeline(3)", pipeline(3)
    yield "dispatch", machine(DISPATCH)
    yield "loop", machine(LOOP)
    yield "branch", machine(BRANCH)
    for seed in range(4):
        yield f"random {seed}", random_outcome_fsm(seed, states=4, containers=0.3, depth=1)


@pytest.mark.parametrize("name", [name for name, _fsm in machines()])
def test_engines_agree_on_generated_machines_and_their_mutants(name: str) -> None:
    fsm = dict(machines())[name]
    doc = fsm_to_structured(fsm).model
    assert _agree(fsm, doc), "the structured conversion is proven equivalent by both"
    verdicts = [_agree(fsm, mutant) for _what, mutant in tree_mutants(fsm, doc)]
    wrong = fsm_mutant(fsm)
    if wrong is not None:
        verdicts.append(_agree(wrong, doc))
    assert verdicts and not all(verdicts), "some mutant differs, and both engines find it"


def test_a_differing_mutant_gets_a_counterexample_in_the_machines_words() -> None:
    fsm = machine(DISPATCH)
    doc = fsm_to_structured(fsm).model
    label, mutant = next(m for m in tree_mutants(fsm, doc) if m[0].startswith("swapped"))
    report = check(fsm, mutant, outcome_driven=True)
    failing = [p for p in report.properties.values() if not p.holds and p.counterexample]
    assert failing, label
    outcomes = {o for targets in DISPATCH.values() for o in targets} | {"running"}
    steps = failing[0].counterexample or []
    assert {s.input for s in steps[1:]} <= outcomes
    assert {s.source_state for s in steps} <= {*DISPATCH, "SUCCESS", "FAILURE"}
    assert steps[0].source_outputs == ["Look"]


def test_a_livelock_is_refused_by_name_and_both_keeps_the_native_verdict() -> None:
    fsm = machine(LOOP)
    doc = copy.deepcopy(fsm_to_structured(fsm).model)
    for _t, node in doc.nodes():  # the retried leaf becomes AlwaysFailure: ticks forever
        node.children = [
            BTNode("AlwaysFailure", NodeKind.ACTION) if c.name == "A" else c for c in node.children
        ]
    with pytest.raises(UnsupportedError, match="LIVELOCK"):
        check(fsm, doc, outcome_driven=True)
    report = verify(fsm, doc, engine="both", outcome_driven=True)
    assert report.equivalent is False
    assert "LIVELOCK" in report.stats["nusmv_limit"]


def _corpus_pair(path: Path) -> tuple[FSM, BTDocument] | None:
    """The machine and its structured tree; ``None`` when the file is no outcome-driven
    machine the structured style converts (an SCXML-like YASMIN file, a reader's refusal)."""
    try:
        fsm = api.load(path).model
        assert isinstance(fsm, FSM)
        return fsm, fsm_to_structured(fsm).model
    except (FsmbtError, AssertionError):
        return None


def _has_parallel(doc: BTDocument) -> bool:
    return any(n.type.startswith("Parallel") for _t, n in doc.nodes())


@pytest.mark.skipif(not FSM_DIR.exists(), reason=f"corpus not found at {CORPUS} (FSMBT_CORPUS)")
def test_engines_agree_on_corpus_files_and_their_mutants() -> None:
    checked = []
    for path in CORPUS_FILES:
        pair = _corpus_pair(path)
        if pair is None:
            continue
        fsm, doc = pair
        if _has_parallel(doc) or sum(1 for _ in doc.nodes()) > MAX_NODES:
            continue  # the concurrences: the next test
        assert _agree(fsm, doc), path
        verdicts = [_agree(fsm, mutant) for _what, mutant in tree_mutants(fsm, doc)]
        assert verdicts and not all(verdicts), path
        checked.append(path.name)
    assert len(checked) >= 10, checked


def parallel_mutants(doc: BTDocument) -> tuple[BTDocument, BTDocument]:
    """The tree with its first parallel's children in the reverse order (the round order:
    always observable), and with its threshold moved by one (ParallelAll ``max_failures``,
    Parallel ``success_count``, wrapping round within 1..children: observable only when a
    child may fail)."""
    swapped, moved = copy.deepcopy(doc), copy.deepcopy(doc)
    first = next(n for _t, n in swapped.nodes() if n.type.startswith("Parallel"))
    first.children.reverse()
    node = next(n for _t, n in moved.nodes() if n.type.startswith("Parallel"))
    port = "max_failures" if node.type == "ParallelAll" else "success_count"
    node.attrs[port] = str(int(node.attrs.get(port, "1")) % len(node.children) + 1)
    return swapped, moved


@pytest.mark.skipif(not FSM_DIR.exists(), reason=f"corpus not found at {CORPUS} (FSMBT_CORPUS)")
def test_engines_agree_on_corpus_concurrences_and_refute_seeded_mutants() -> None:
    """Every corpus Concurrence read in rounds (a Parallel in the tree: SMACH, FlexBE, YASMIN,
    leaf and container children): NuSMV decides it, as the native checker does; on the trees
    of at most ``MAX_NODES`` nodes (the FlexBE ones, 40-47 nodes, cost 10-50 s per mutant)
    the parallel's children reversed are refuted by both, and its threshold moved gets the
    same verdicts from both, refuted where a child may fail."""
    decided, moved_refuted = [], []
    for path in CORPUS_FILES:
        pair = _corpus_pair(path)
        if pair is None or not _has_parallel(pair[1]):
            continue
        fsm, doc = pair
        assert _agree(fsm, doc), path
        decided.append(path.name)
        if sum(1 for _ in doc.nodes()) > MAX_NODES:
            continue
        swapped, moved = parallel_mutants(doc)
        assert not _agree(fsm, swapped), path
        if not _agree(fsm, moved):
            moved_refuted.append(path.name)
    assert len(decided) == 7 and len(moved_refuted) >= 2, (decided, moved_refuted)


def _convert_both(name: str, out: Path) -> str:
    source = Path(__file__).resolve().parents[3] / "examples" / name
    done = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "convert", str(source), "--style", "structured",
         "--verify-engine", "both", "-o", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_cli_prints_both_engines_verdict(tmp_path: Path) -> None:
    out = _convert_both("pick_place_smach.py", tmp_path / "pick.xml")
    assert "verdict: EQUIVALENT" in out
    assert "+symbolic (fsmbt native checker" in out and "NuSMV 2.5.4" in out  # both proved it
    assert "gave up" not in out
    # a Concurrence read in rounds (a Parallel in the tree): proven by both engines too
    out = _convert_both("delivery_smach.py", tmp_path / "delivery.xml")
    assert "verdict: EQUIVALENT" in out and "+symbolic" in out and "NuSMV 2.5.4" in out
    assert "gave up" not in out
