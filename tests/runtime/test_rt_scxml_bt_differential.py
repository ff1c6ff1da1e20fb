"""Every SCXML that BT->FSM writes runs in python-statemachine as fsmbt proved it (issue 11, 5a).

The BT is converted by the rules engine (``bt_to_hfsm``), the HFSM written as SCXML, the text
loaded in python-statemachine 3.2.2 and driven with seeded random leaf outcomes; after each
outcome the engine's configuration must be fsmbt's (``FSMMachine`` over the flattened HFSM the
conversion proved), the same leaf active, the same termination and the same final state.

Groups (one test each): the examples (``examples/*_bt.xml``), every corpus BT that converts
(``FSMBT_CORPUS``, default ``<repo>/../shared/corpus``) and ``FSMBT_SCXML_BTS`` generated BTs
(default 300; paper controls and, every other one, the extended node set whose regions are
explored; every fourth converted with ``loop=True``). ``FSMBT_SCXML_SEQUENCES`` sequences per model (default 5 for generated trees, 4x for
the examples and the corpus) of up to ``FSMBT_SCXML_LENGTH`` outcomes (default 30). Counts are
printed (``pytest -s``). The full run used for the report: ``FSMBT_SCXML_BTS=1000
FSMBT_SCXML_SEQUENCES=20``.
"""

from __future__ import annotations

import os
import random
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from scxml_oracle import PARALLEL_STOPS, Engine, Mismatch, Replay, python_spelled, replay

from fsmbt import api
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.formats import dumps
from fsmbt.generate import random_bt
from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import FSMMachine
from support.corpus import CORPUS

REPO = Path(__file__).resolve().parents[2]
GENERATED = int(os.environ.get("FSMBT_SCXML_BTS", "300"))
SEQUENCES = int(os.environ.get("FSMBT_SCXML_SEQUENCES", "5"))
LENGTH = int(os.environ.get("FSMBT_SCXML_LENGTH", "30"))
SEED = int(os.environ.get("FSMBT_SCXML_SEED", "11"))
HFSMS = int(os.environ.get("FSMBT_SCXML_HFSMS", "100"))


@dataclass
class Tally:
    group: str
    models: int = 0
    sequences: int = 0
    events: int = 0
    refused: Counter[str] = field(default_factory=Counter)
    mismatches: list[str] = field(default_factory=list)
    departures: Counter[str] = field(default_factory=Counter)

    def add(self, label: str, result: Replay) -> None:
        self.sequences += 1
        self.events += result.sent
        if result.mismatch is not None:
            self.mismatches.append(f"{label}: {result.mismatch}")
        if result.departure is not None:
            self.departures[result.departure] += 1

    def report(self) -> str:
        return (
            f"\n[{self.group}] {self.models} models, {self.sequences} sequences, "
            f"{self.events} events, {len(self.mismatches)} mismatches, "
            f"{sum(self.departures.values())} sequences ended by a documented engine "
            f"departure {dict(self.departures)}; not converted/written: "
            f"{sum(self.refused.values())} {dict(self.refused.most_common(4))}"
        )


def random_hfsm(seed: int, *, parallel: bool) -> FSM:
    """tests/convert's seeded HFSM generator (imported, not copied)."""
    from support.conv_hfsm_gen import random_hfsm as make

    return make(seed, parallel=parallel)


def check_tree(
    tally: Tally,
    label: str,
    doc: BTDocument,
    rng: random.Random,
    sequences: int,
    *,
    loop: bool = False,
) -> None:
    try:
        hfsm = bt_to_hfsm(doc, loop=loop).model
    except FsmbtError as exc:
        tally.refused[f"{type(exc).__name__}: {getattr(exc, 'message', str(exc))[:60]}"] += 1
        return
    written = dumps(hfsm, "scxml")
    # a data model (the compact conversion) is written in ECMAScript; the engine evaluates
    # Python: the same document with its expressions spelled for it (scxml_oracle)
    text = python_spelled(written) or written
    Engine(text)  # loads in the engine at all (raises otherwise)
    machine = FSMMachine(hfsm)
    tally.models += 1
    for _ in range(sequences):
        result = replay(
            text,
            hfsm,
            rng,
            length=LENGTH,
            machine=machine,
            alphabet=("success", "failure", "running"),
        )
        tally.add(label, result)


def test_reported_bug_robot_pick_failure_is_not_delivery() -> None:
    """Issue 11's report: after MovetoCube2 fails the engine must leave the pick unit by its
    FAILURE end (the BT fails), not go on to RobotatDelivery as if the pick had succeeded."""
    doc = api.load(REPO / "examples" / "robot_bt.xml").model
    hfsm = bt_to_hfsm(doc).model
    text = dumps(hfsm, "scxml")
    engine = Engine(text)
    machine = FSMMachine(hfsm)
    state, _ = machine.start()
    for outcome in ("success", "failure", "failure", "failure", "failure"):
        engine.send(outcome)
        state, _ = machine.step(state, outcome)
        assert engine.configuration() == state
    assert "RobotatDelivery" not in engine.configuration()
    assert engine.terminated and engine.configuration() == "FAILURE" == state


def test_examples() -> None:
    tally = Tally("examples")
    rng = random.Random(SEED)
    paths = sorted((REPO / "examples").glob("*_bt.xml"))
    assert paths
    for path in paths:
        check_tree(tally, path.name, api.load(path).model, rng, 4 * SEQUENCES)
    print(tally.report())
    assert tally.models == len(paths) and not tally.mismatches, tally.mismatches[:5]


def test_corpus_bts() -> None:
    folder = CORPUS / "bt"
    if not folder.exists():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    tally = Tally("corpus bt")
    rng = random.Random(SEED)
    unreadable = 0
    for path in sorted(folder.rglob("*.xml")):
        try:
            doc = api.load(path).model
        except FsmbtError:
            unreadable += 1
            continue
        if isinstance(doc, BTDocument):
            check_tree(tally, str(path.relative_to(CORPUS)), doc, rng, 4 * SEQUENCES)
    print(tally.report() + f"; unreadable {unreadable}")
    assert tally.models >= 10 and not tally.mismatches, tally.mismatches[:5]


def test_generated_bts() -> None:
    tally = Tally("generated bt")
    rng = random.Random(SEED)
    for index in range(GENERATED):
        doc = random_bt(
            seed=SEED * 100_000 + index,
            depth=rng.randint(2, 5),
            breadth=rng.randint(2, 4),
            extended=index % 2 == 1,
            max_nodes=40,
        )
        check_tree(tally, f"gen{index}", doc, rng, SEQUENCES, loop=index % 4 == 3)
    print(tally.report())
    refused = sum(tally.refused.values())
    assert all(k.startswith(UnsupportedError.__name__) for k in tally.refused), tally.refused
    assert tally.models + refused == GENERATED and tally.models >= 0.9 * GENERATED
    assert not tally.mismatches and not tally.departures, tally.mismatches[:5]


def test_generated_hfsms_written_by_fsmbt() -> None:
    """Beyond BT->FSM: seeded hierarchical FSMs (nested composites, completion transitions,
    events shared between levels, parallel states whose regions fsmbt wraps) written by fsmbt
    run in the engine as fsmbt's flattening says."""
    tally = Tally("generated hfsm")
    rng = random.Random(SEED)
    for index in range(HFSMS):
        hfsm = random_hfsm(SEED * 1000 + index, parallel=index % 2 == 1)
        text = dumps(hfsm, "scxml")
        machine = FSMMachine(hfsm)
        tally.models += 1
        for _ in range(SEQUENCES):
            tally.add(f"hfsm{index}", replay(text, hfsm, rng, length=LENGTH, machine=machine))
    print(tally.report())
    assert not tally.mismatches, tally.mismatches[:5]
    assert set(tally.departures) <= {PARALLEL_STOPS}


def test_mismatch_is_reported_on_a_wrong_model() -> None:
    """The oracle can fail: the robot SCXML against an HFSM whose pick unit's completion
    transitions are swapped disagrees with the engine (so zero mismatches above means
    something)."""
    doc = api.load(REPO / "examples" / "robot_bt.xml").model
    hfsm = bt_to_hfsm(doc).model
    text = dumps(hfsm, "scxml")
    for machine_fsm in [hfsm, *(s.regions[0] for s in hfsm.states.values() if s.regions)]:
        for t in machine_fsm.transitions:
            if t.exit == "SUCCESS":
                t.exit = "FAILURE"
            elif t.exit == "FAILURE":
                t.exit = "SUCCESS"
    found: list[Mismatch] = []
    rng = random.Random(SEED)
    for _ in range(40):
        result = replay(text, hfsm, rng, length=LENGTH, alphabet=("success", "failure", "running"))
        if result.mismatch is not None:
            found.append(result.mismatch)
    assert found


# -- the compact conversion (memory as data) against the tree in BehaviorTree.CPP ------------
#: Trees whose regions explore past this many states are not converted here (the test stays
#: fast; ``FSMBT_COMPACT_MAX_STATES=200000`` runs every corpus tree).
COMPACT_MAX_STATES = int(os.environ.get("FSMBT_COMPACT_MAX_STATES", "2500"))
COMPACT_SEQUENCES = int(os.environ.get("FSMBT_COMPACT_SEQUENCES", "3"))
COMPACT_LEAF_STEPS = int(os.environ.get("FSMBT_COMPACT_STEPS", "60"))
F_ACTION = "{https://fsmbt.dev/ns/scxml}action"


@dataclass
class Lockstep:
    """The environment of one run: each leaf the tree ticks must be the leaf the SCXML engine
    is in (the action of its active atomic state); the outcome, drawn at random, goes to both."""

    engine: Engine
    actions: dict[str, str]
    rng: random.Random
    steps: int = 0
    mismatch: str | None = None

    def active_leaf(self) -> str:
        """The actions of the active atomic states, joined; empty ones dropped, as fsmbt's W3C
        reading does (a ``<parallel>`` region waiting for its turn has no action)."""
        doc = self.engine.doc
        active = {s.id for s in self.engine.machine.configuration}
        atoms = [s for s in active if not doc.children.get(s)]
        return "+".join(sorted(a for s in atoms if (a := self.actions.get(s, doc.name[s]))))

    def __call__(self, node, _path: str) -> str:  # noqa: ANN001 - the tree's BTNode
        label = node.name or node.type
        seen = self.active_leaf()
        if self.mismatch is None and seen != label:
            self.mismatch = f"leaf {self.steps}: tree ticks {label}, SCXML engine is in {seen}"
        condition = node.kind is NodeKind.CONDITION
        choices = ["success", "failure"] + ([] if condition else ["running"])
        outcome = self.rng.choice(choices)
        self.engine.send(outcome)
        self.steps += 1
        return outcome


def _actions(text: str) -> dict[str, str]:
    """State id -> its action (fsmbt:action, else its model name, else its id)."""
    from lxml import etree

    root = etree.fromstring(text.encode())
    out = {}
    for element in root.iter():
        if isinstance(element.tag, str) and element.get("id") is not None:
            name = element.get("{https://fsmbt.dev/ns/scxml}name", element.get("id"))
            out[element.get("id")] = element.get(F_ACTION, name)
    return out


def run_compact(
    doc: BTDocument, rng: random.Random, tally: Tally, label: str
) -> tuple[str, bool] | None:
    """Convert ``doc`` compactly, then run it ``COMPACT_SEQUENCES`` times in python-statemachine
    and in BehaviorTree.CPP (fsmbt's interpreter when BehaviorTree.CPP has no such node: Nav2,
    MoveIt Pro and gated nodes) with the same random leaf outcomes. Returns the engine used
    and whether the SCXML has a data model (``None``: not converted)."""
    from fsmbt.semantics.bt_interpreter import BTRunner
    from fsmbt.semantics.engines.btcpp_engine import BTCppRunner

    try:
        hfsm = bt_to_hfsm(doc, max_states=COMPACT_MAX_STATES).model
    except FsmbtError as exc:
        tally.refused[f"{type(exc).__name__}: {getattr(exc, 'message', str(exc))[:50]}"] += 1
        return None
    text = dumps(hfsm, "scxml")
    spelled = python_spelled(text) or text
    actions = _actions(text)
    tally.models += 1
    used = "btcpp"
    for _ in range(COMPACT_SEQUENCES):
        engine = Engine(spelled)
        env = Lockstep(engine, actions, rng)
        try:
            runner = BTCppRunner(doc, env)
        except Exception:  # noqa: BLE001 - BehaviorTree.CPP does not know a node type
            runner, used = BTRunner(doc, env), "interpreter"
        tally.sequences += 1
        result = "RUNNING"
        while env.steps < COMPACT_LEAF_STEPS and env.mismatch is None:
            before = env.steps
            result = runner.tick_once().result
            if result != "RUNNING" or env.steps == before:
                break
        tally.events += env.steps
        if env.mismatch is None and result in ("SUCCESS", "FAILURE"):
            end = env.active_leaf()
            if not engine.terminated or end != result:
                env.mismatch = f"tree returned {result}, engine in {end}"
        elif env.mismatch is None and engine.terminated:
            env.mismatch = f"engine terminated in {env.active_leaf()}, tree still {result}"
        if env.mismatch is not None:
            tally.mismatches.append(f"{label}: {env.mismatch}")
    return used, "<datamodel>" in text


def test_compact_runs_like_btcpp() -> None:
    """Issue 24: the compact SCXML of every example and corpus BT (profile options, regions up
    to ``COMPACT_MAX_STATES`` explored states) and of seeded extended trees runs in
    python-statemachine, data model included, leaf for leaf and result for result as the tree
    runs in BehaviorTree.CPP (behaviortreepy), or in fsmbt's interpreter for node types
    BehaviorTree.CPP does not have (the interpreter is cross-checked against it in
    tests/semantics)."""
    from support.corpus import profile_options

    tally = Tally("compact")
    rng = random.Random(SEED)
    engines: Counter[str] = Counter()
    with_data = 0
    trees: list[tuple[str, BTDocument]] = []
    for path in sorted((REPO / "examples").glob("*_bt.xml")):
        trees.append((path.name, api.load(path).model))
    folder = CORPUS / "bt"
    if folder.exists():
        for path in sorted(folder.rglob("*.xml")):
            if "models" in path.parts or any(p.startswith("_") for p in path.parts):
                continue
            try:
                doc = api.load(path, options=profile_options(path)).model
            except FsmbtError:
                continue
            if isinstance(doc, BTDocument):
                trees.append((str(path.relative_to(CORPUS)), doc))
    for index in range(40):
        trees.append(
            (
                f"gen{index}",
                random_bt(seed=SEED * 7_000 + index, depth=3, breadth=3, extended=True),
            )
        )
    for label, doc in trees:
        ran = run_compact(doc, rng, tally, label)
        if ran is not None:
            engines[ran[0]] += 1
            with_data += ran[1]
    print(tally.report() + f"; run against {dict(engines)}; {with_data} with a data model")
    assert not tally.mismatches, tally.mismatches[:5]
    assert engines["btcpp"] >= 20 and with_data >= 10
    assert tally.models >= 0.8 * len(trees)


def test_compact_parallels_run_like_btcpp() -> None:
    """Issue 24, ``<parallel>``: 40 seeded trees whose Parallel/ParallelAll heads its region
    (tests/support/parallel_trees.py; every other one with Retry/Repeat, SequenceWithMemory
    and reactive controls in its children) and the corpus trees of that shape, each written with one
    ``<parallel>`` whose regions take turns, run in python-statemachine leaf for leaf and
    result for result as in BehaviorTree.CPP (``COMPACT_SEQUENCES`` random runs each)."""
    from fsmbt.formats import loads
    from support.corpus import profile_options
    from support.parallel_trees import parallel_tree_xml

    trees: list[tuple[str, BTDocument]] = []
    for relative in (
        "kitchen_sim__write_text.xml",
        "dual_arm_sim__draw.xml",
        "hangar_sim__cartesian_draw_geometry_from_file.xml",
    ):
        path = CORPUS / "bt" / "moveit_pro" / relative
        if path.exists():
            trees.append((relative, api.load(path, options=profile_options(path)).model))
    for seed in range(40):
        text = parallel_tree_xml(SEED * 100 + seed, memory=seed % 2 == 1)
        trees.append((f"parallel{seed}", loads(text, "btcpp")))
    tally = Tally("compact parallel")
    rng = random.Random(SEED)
    engines: Counter[str] = Counter()
    with_parallel = 0
    for label, doc in trees:
        with_parallel += "<parallel" in dumps(bt_to_hfsm(doc).model, "scxml")
        ran = run_compact(doc, rng, tally, label)
        assert ran is not None, label
        engines[ran[0]] += 1
        # generated trees have only BehaviorTree.CPP's nodes (MoveIt Pro's run interpreted)
        assert ran[0] == "btcpp" or not label.startswith("parallel"), label
    print(tally.report() + f"; run against {dict(engines)}; {with_parallel} with <parallel>")
    assert not tally.mismatches, tally.mismatches[:5]
    assert with_parallel == len(trees) and engines["btcpp"] >= 40


def test_compact_lockstep_catches_a_wrong_guard() -> None:
    """The lockstep can fail: the Nav2 default tree's compact SCXML with one retry guard
    negated (a failing selector ends the run instead of recovering) disagrees with the tree."""
    from support.corpus import profile_options

    path = CORPUS / "bt" / "nav2" / "navigate_to_pose_w_replanning_and_recovery.xml"
    if not path.exists():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    doc = api.load(path, options=profile_options(path)).model
    hfsm = bt_to_hfsm(doc).model
    guarded = [
        t
        for m in hfsm.machines()
        for t in m.transitions
        if "retry_count ==" in t.attrs.get("cond", "")
    ]
    assert guarded
    guarded[0].attrs["cond"] = f"!({guarded[0].attrs['cond']})"
    text = dumps(hfsm, "scxml")
    spelled = (python_spelled(text) or text).replace('cond="!(', 'cond="not (')
    from fsmbt.semantics.bt_interpreter import BTRunner

    rng = random.Random(SEED)
    caught = 0
    for _ in range(20):
        env = Lockstep(Engine(spelled), _actions(text), rng)
        runner = BTRunner(doc, env)
        while env.steps < COMPACT_LEAF_STEPS and env.mismatch is None:
            before = env.steps
            if runner.tick_once().result != "RUNNING" or env.steps == before:
                break
        caught += env.mismatch is not None
    assert caught


def test_parallel_lockstep_catches_a_wrong_turn() -> None:
    """The lockstep can fail on ``<parallel>``: when the first region passes the turn back to
    itself instead of on (its ``running`` keeps the turn), python-statemachine ticks the first
    child again where BehaviorTree.CPP ticks the second."""
    from fsmbt.formats import loads

    doc = loads(
        '<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">'
        '<Parallel name="P" success_count="2" failure_count="2"><Action ID="A"/>'
        '<Action ID="B"/><Action ID="C"/></Parallel></BehaviorTree></root>',
        "btcpp",
    )
    text = dumps(bt_to_hfsm(doc).model, "scxml")
    wrong = '<transition event="running" target="wait_A">\n            <assign location="P_turn" expr="0"/>'
    right = wrong.replace('expr="0"', 'expr="1"')
    assert right in text
    text = text.replace(right, wrong)
    from fsmbt.semantics.engines.btcpp_engine import BTCppRunner

    rng = random.Random(SEED)
    caught = 0
    for _ in range(20):
        env = Lockstep(Engine(python_spelled(text) or text), _actions(text), rng)
        runner = BTCppRunner(doc, env)
        while env.steps < COMPACT_LEAF_STEPS and env.mismatch is None:
            before = env.steps
            if runner.tick_once().result != "RUNNING" or env.steps == before:
                break
        caught += env.mismatch is not None
    assert caught
