"""SMACH writer: what it writes reads back (through the SMACH reader) to an equivalent model -
equal up to the order of states and transitions where SMACH holds the model directly - on the
examples and on generated FSMs and HFSMs (checked with fsmbt.verify.verify), and the written
module runs against SMACH's container API and passes SMACH's consistency rules.

SMACH itself (ROS) is not installable here, so ``_RecordingSmach`` below plays its container
API (``with``-opened containers, static ``add``, ``set_initial_state``) and applies the rules
of SMACH's ``check_consistency`` as docs/formats/smach.md states them; it runs only code that
fsmbt wrote.
"""

from __future__ import annotations

import sys
import types
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import loads
from fsmbt.formats.pysm.smach_write import smach_losses, write_smach
from fsmbt.formats.translate import differences_between
from fsmbt.generate.generator import random_bt, random_fsm
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.verify import verify

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FSM_EXAMPLES = [
    "paper_fsm.xml",
    "paper_fsm.json",
    "guard_npc.csv",
    "turnstile.mmd",
    "door_hfsm.scxml",
    "delivery_smach.py",
]


def round_trip(model: FSM) -> FSM:
    back = loads(write_smach(model), "smach")
    assert isinstance(back, FSM)
    return back


@pytest.mark.parametrize("name", FSM_EXAMPLES)
def test_examples_round_trip_to_an_equivalent_model(name: str) -> None:
    model = api.load(EXAMPLES / name).model
    assert isinstance(model, FSM)
    back = round_trip(model)
    assert verify(model, back).equivalent
    if not model.is_hierarchical:  # nothing for the writer to restructure
        assert differences_between(model, back) == []


@pytest.mark.parametrize("seed", range(25))
def test_generated_fsms_round_trip_equivalent(seed: int) -> None:
    model = random_fsm(seed)
    back = round_trip(model)
    assert differences_between(model, back) == []
    assert verify(model, back).equivalent


@pytest.mark.parametrize("seed", range(25))
def test_generated_hfsms_round_trip_equivalent(seed: int) -> None:
    model = convert(random_bt(seed)).model
    assert isinstance(model, FSM)
    back = round_trip(model)
    assert verify(model, back).equivalent


def _parallel_model() -> FSM:
    left = FSM(name="left")
    left.add_state("L1")
    left.add_state("L2", final=True)
    left.add_transition("L1", "go", "L2")
    right = FSM(name="right")
    right.add_state("R1")
    right.add_state("R2", final=True)
    right.add_transition("R1", "go", "R2")
    right.add_transition("R1", "hop", "R2")
    top = FSM(name="par")
    top.add_state(State("P", action=None, regions=[left, right]))
    top.add_state("Done", final=True)
    top.add_state("Aborted", final=True)
    top.add_transition("P", None, "Done")
    top.add_transition("P", "abort", "Aborted")
    return top


def test_parallel_state_is_written_as_its_product_and_named_as_a_loss() -> None:
    model = _parallel_model()
    losses = smach_losses(model)
    assert any("parallel state 'P'" in loss for loss in losses)
    back = round_trip(model)
    assert verify(model, back).equivalent


def test_concurrence_read_from_smach_is_written_back_as_a_concurrence() -> None:
    text = "\n".join(
        [
            "import smach",
            "class Foo(smach.State):",
            "    def __init__(self):",
            "        smach.State.__init__(self, outcomes=['a', 'b'])",
            "def main():",
            "    top = smach.StateMachine(outcomes=['end'])",
            "    with top:",
            "        cc = smach.Concurrence(outcomes=['x', 'y'], default_outcome='y',",
            "                               outcome_map={'x': {'F1': 'a', 'F2': 'a'}})",
            "        with cc:",
            "            smach.Concurrence.add('F1', Foo())",
            "            smach.Concurrence.add('F2', Foo())",
            "        smach.StateMachine.add('CC', cc, transitions={'x': 'end', 'y': 'CC'})",
        ]
    )
    model = loads(text, "smach")
    written = write_smach(model)
    assert "smach.Concurrence(outcomes=['x', 'y'], default_outcome='y'" in written
    assert "smach.Concurrence.add('F1', Foo())" in written
    back = loads(written, "smach")
    assert differences_between(model, back) == []


def test_refusals_are_named() -> None:
    fsm = FSM(name="transient")
    fsm.add_state("A")
    fsm.add_state("B", final=True)
    fsm.add_transition("A", None, "B")
    with pytest.raises(UnsupportedError, match="eventless transition"):
        write_smach(fsm)
    bt = api.load(EXAMPLES / "robot_bt.xml").model
    with pytest.raises(InputError, match="not behavior trees"):
        write_smach(bt)


# -- the written module against SMACH's container API -------------------------------------------
class _ConsistencyError(Exception):
    pass


def _recording_smach() -> types.ModuleType:
    module = types.ModuleType("smach")
    opened: list = []

    class State:
        def __init__(self, outcomes):  # noqa: ANN001 - SMACH's signature
            self.outcomes = list(outcomes)

    class Container:
        def __init__(self, outcomes, **options):  # noqa: ANN001, ANN003
            self.outcomes = list(outcomes)
            self.options = options
            self.states: dict = {}
            self.transitions: dict = {}
            self.initial = None

        def __enter__(self):  # noqa: ANN204
            opened.append(self)
            return self

        def __exit__(self, *args):  # noqa: ANN002, ANN204
            opened.pop()

        def set_initial_state(self, labels):  # noqa: ANN001, ANN202
            self.initial = labels[0]

        def check(self) -> None:
            """SMACH's check_consistency: every registered outcome leads to a state or to a
            container outcome; transitions name registered outcomes only."""
            if self.initial not in self.states:
                raise _ConsistencyError(f"initial {self.initial!r}")
            for label, state in self.states.items():
                mapping = self.transitions[label]
                for outcome in mapping:
                    if outcome not in state.outcomes:
                        raise _ConsistencyError(f"{label}: unregistered outcome {outcome}")
                for outcome in state.outcomes:
                    target = mapping.get(outcome) or outcome
                    if target not in self.states and target not in self.outcomes:
                        raise _ConsistencyError(f"{label}: {outcome} -> {target}")

    class StateMachine(Container):
        @staticmethod
        def add(label, state, transitions=None):  # noqa: ANN001, ANN205
            container = opened[-1]
            if container.initial is None:
                container.initial = label
            container.states[label] = state
            container.transitions[label] = dict(transitions or {})
            return state

    class Concurrence(Container):
        @staticmethod
        def add(label, state):  # noqa: ANN001, ANN205
            container = opened[-1]
            container.states[label] = state
            container.transitions[label] = {
                o: container.options["default_outcome"] for o in state.outcomes
            }
            container.initial = next(iter(container.states))
            return state

    module.State = State  # type: ignore[attr-defined]
    module.StateMachine = StateMachine  # type: ignore[attr-defined]
    module.Concurrence = Concurrence  # type: ignore[attr-defined]
    return module


def _containers(root) -> list:  # noqa: ANN001
    out, stack = [], [root]
    while stack:
        container = stack.pop()
        out.append(container)
        stack.extend(s for s in container.states.values() if hasattr(s, "states"))
    return out


@pytest.mark.parametrize(
    "source", ["paper_fsm.xml", "door_hfsm.scxml", "hfsm:3", "hfsm:7", "parallel"]
)
def test_written_module_builds_a_consistent_smach_machine(
    source: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    if source == "parallel":
        model = _parallel_model()
    elif source.startswith("hfsm:"):
        model = convert(random_bt(int(source[5:]))).model
    else:
        model = api.load(EXAMPLES / source).model
    text = write_smach(model)
    monkeypatch.setitem(sys.modules, "smach", _recording_smach())
    namespace: dict = {"__name__": "written_by_fsmbt"}
    exec(compile(text, "<written by fsmbt>", "exec"), namespace)  # fsmbt's own output only
    root = namespace["build_state_machine"]()
    containers = _containers(root)
    for container in containers:
        container.check()
    labels = {label for c in containers for label in c.states}
    back = loads(text, "smach")
    assert labels == {state.name for _path, _machine, state in back.walk() if not state.final}


def test_an_initial_state_that_is_not_the_first_is_set_after_the_with_block() -> None:
    fsm = FSM(name="late_start")
    fsm.add_state("A")
    fsm.add_state("B")
    fsm.add_state("End", final=True)
    fsm.initial = "B"
    fsm.add_transition("A", "go", "End")
    fsm.add_transition("B", "go", "A")
    text = write_smach(fsm)
    lines = text.splitlines()
    with_line = next(i for i, line in enumerate(lines) if line.strip() == "with sm_0:")
    initial_line = next(i for i, line in enumerate(lines) if "set_initial_state(['B'])" in line)
    assert initial_line > with_line and not lines[initial_line].startswith(" " * 8)
    back = loads(text, "smach")
    assert back.initial == "B" and differences_between(fsm, back) == []


def test_states_sharing_an_action_but_not_their_events_get_one_class_each() -> None:
    fsm = FSM(name="shared")
    for name in ("A", "B", "C"):
        fsm.add_state(name, action="Move")
    fsm.add_state("End", final=True)
    fsm.add_transition("A", "x", "B")
    fsm.add_transition("B", "y", "C")
    fsm.add_transition("C", "z", "End")
    fsm.add_transition("A", "w", "End")
    text = write_smach(fsm)
    for cls in ("class Move(", "class Move_2(", "class Move_3("):
        assert text.count(cls) == 1
    back = loads(text, "smach")
    assert {s.action for s in back.states.values() if not s.final} == {"Move"}
    assert differences_between(fsm, back) == []


def test_a_transient_state_is_refused_but_translate_flatten_writes_it(tmp_path: Path) -> None:
    fsm = FSM(name="transient")
    fsm.add_state("A")
    fsm.add_state("Pass")
    fsm.add_state("B", final=True)
    fsm.add_transition("A", "go", "Pass")
    fsm.add_transition("Pass", None, "B")
    source = api.write(fsm, tmp_path / "transient.json")
    with pytest.raises(UnsupportedError, match="--flatten"):
        api.translate(source, to="smach")
    _loaded, result, report = api.translate(source, to="smach", flatten=True)
    assert (
        result.verified
        and report is not None
        and report.equivalent
        and any(loss.startswith("flattened:") for loss in result.losses)
    )
