"""What a SMACH / FlexBE state was configured with travels with it (issue 23 item 1, reading
side; issue 26 item 4): parameters, userdata keys, remappings, container userdata, ROS
interfaces and editor positions are read into ``state_info``, carried by JSON / SCXML / SMACH,
and named as losses by targets that have no place for them.

Corpus files (SMACH tutorial ``user_data2.py``, the FlexBE turtlesim demo) and small files
written here.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import loads
from fsmbt.formats.translate import differences_between, translate
from fsmbt.model import state_info
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify
from support.corpus import CORPUS

ROOT = Path(__file__).resolve().parents[2]
USER_DATA2 = CORPUS / "fsm" / "smach_tutorials" / "user_data2.py"
DEMO = CORPUS / "fsm" / "flexbe_turtlesim_demo" / "flexbe_turtlesim_demo_sm.py"
needs_corpus = pytest.mark.skipif(not (CORPUS / "fsm").exists(), reason="corpus not present")


def _translated(model, target):  # type: ignore[no-untyped-def]
    """``formats.translate`` and the proof ``api.translate`` adds: the read-back is equivalent."""
    result = translate(model, target)
    if result.read_back is not None and result.checked is not None:
        assert verify(result.checked, result.read_back).equivalent
        result.verified = True
    return result


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", *args],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )


@needs_corpus
def test_user_data2_keeps_its_userdata_and_remappings() -> None:
    model = api.load(USER_DATA2).model
    assert isinstance(model, FSM)
    foo, bar = model.states["FOO"], model.states["BAR"]
    assert state_info.declared_outcomes(foo) == ["outcome1", "outcome2"]
    assert state_info.input_keys(foo) == ["foo_counter_in"]
    assert state_info.output_keys(foo) == ["foo_counter_out"]
    assert state_info.remapping(foo) == {
        "foo_counter_in": "sm_counter",
        "foo_counter_out": "sm_counter",
    }
    assert state_info.input_keys(bar) == ["bar_counter_in"]
    assert state_info.output_keys(bar) == []
    assert state_info.remapping(bar) == {"bar_counter_in": "sm_counter"}
    assert state_info.userdata_values(model) == {"sm_counter": "0"}


@needs_corpus
def test_translate_user_data2_names_what_mermaid_loses_and_json_scxml_smach_carry() -> None:
    model = api.load(USER_DATA2).model
    lost = _translated(model, "mermaid").losses
    assert any(line.startswith("userdata remappings of 2 state(s)") for line in lost), lost
    assert any(line.startswith("input userdata keys of 2 state(s)") for line in lost), lost
    assert any(line.startswith("userdata initial values of 1 state(s)") for line in lost), lost
    for target in ("json", "scxml", "smach"):
        result = _translated(model, target)
        assert result.verified and result.losses == [], (target, result.losses)
        back = loads(result.text, target)
        assert differences_between(model, back) == []
    scxml = translate(model, "scxml").text
    assert 'fsmbt:remapping="{&quot;foo_counter_in&quot;' in scxml
    smach = translate(model, "smach").text
    assert "input_keys=['foo_counter_in'], output_keys=['foo_counter_out']" in smach
    assert "remapping={'bar_counter_in': 'sm_counter'}" in smach
    assert "sm_0.userdata.sm_counter = 0" in smach


@needs_corpus
def test_translate_cli_no_longer_says_zero_losses_for_user_data2(tmp_path: Path) -> None:
    done = cli("translate", str(USER_DATA2), "-o", str(tmp_path / "out.mmd"), "--to", "mermaid")
    assert done.returncode == 0, done.stderr
    assert "0 loss(es)" not in done.stderr
    assert "mermaid: userdata remappings of 2 state(s) have no place in mermaid" in done.stderr


@needs_corpus
def test_flexbe_demo_parameters_positions_and_remappings() -> None:
    model = api.load(DEMO).model
    assert isinstance(model, FSM)
    eight = model.states["EightMove"].regions[0]
    forward = eight.states["Forward0"]
    assert state_info.parameters(forward) == {
        "target_time": "3.99",
        "velocity": "0.5",
        "rotation_rate": "0.0",
        "cmd_topic": "/turtle1/cmd_vel",  # the variable bound to a literal in create()
        "desired_rate": "50",
    }
    assert state_info.expression_parameters(forward) == []
    assert state_info.position(forward) == (130, 43)
    log = model.states["GoHome"]
    assert state_info.parameters(log)["text"] == "Go to home position"
    assert state_info.parameters(log)["severity"] == "Logger.REPORT_HINT"
    assert state_info.expression_parameters(log) == ["severity"]
    assert state_info.remapping(model.states["Home"]) == {"pose": "home"}
    operator = model.states["Operator"]
    assert state_info.declared_outcomes(operator) == [
        "Home",
        "Eight",
        "Quit",
        "Clear",
        "Rotate",
        "Pose",
    ]
    assert "outcomes" not in state_info.parameters(operator)
    assert state_info.userdata_values(model) == {"home": "[5.5, 5.5, 0.0]"}
    # every state the editor placed has its position
    placed = [s for _p, _m, s in model.walk() if not s.final]
    assert placed and all(state_info.position(s) is not None for s in placed)


@needs_corpus
def test_flexbe_demo_to_smach_writes_parameters_and_names_the_rest() -> None:
    model = api.load(DEMO).model
    result = _translated(model, "smach")
    assert result.verified
    assert "TimedCmdVelState(target_time=3.99, velocity=0.5, rotation_rate=0.0" in result.text
    assert "severity=Logger.REPORT_HINT" in result.text  # an expression, written as itself
    assert "            # x:130 y:43\n" in result.text  # the editor's position comment
    assert any("autonomy" in line for line in result.losses)
    assert any(
        "embedded the FlexBE behaviour 'TurtlesimInputStateBehaviorSM'" in line
        for line in result.losses
    )
    back = loads(result.text, "smach")
    forward = back.states["EightMove"].regions[0].states["Forward0"]
    assert state_info.parameters(forward)["velocity"] == "0.5"
    assert state_info.position(forward) == (130, 43)
    # every parameter, key, remapping and position read back as it was
    before = {p: s.attrs for p, _m, s in model.walk()}
    after = {p: s.attrs for p, _m, s in back.walk()}
    for key in (
        state_info.PARAMETERS,
        state_info.EXPRESSION_PARAMETERS,
        state_info.REMAPPING,
        state_info.POSITION,
    ):
        assert {p: a[key] for p, a in before.items() if key in a} == {
            p: a[key] for p, a in after.items() if key in a
        }, key


SMACH_ROS = """\
import smach
import smach_ros
from move_base_msgs.msg import MoveBaseAction
from std_srvs.srv import Empty

class Wait(smach.State):
    def __init__(self, seconds, label='x'):
        smach.State.__init__(self, outcomes=['done'], output_keys=['waited'])

def build(name_var):
    sm = smach.StateMachine(outcomes=['ok', 'failed'], input_keys=['target'])
    sm.userdata.speed = 0.25
    with sm:
        smach.StateMachine.add('MOVE',
            smach_ros.SimpleActionState('move_base', MoveBaseAction,
                                        goal_key='goal', result_key='res'),
            transitions={'succeeded': 'WAIT', 'aborted': 'failed', 'preempted': 'failed'},
            remapping={'goal': 'target'})
        smach.StateMachine.add('WAIT', Wait(2.5, label=name_var),
                               transitions={'done': 'CLEAR'})
        smach.StateMachine.add('CLEAR', smach_ros.ServiceState('/clear', Empty),
                               transitions={'succeeded': 'ok', 'aborted': 'failed',
                                            'preempted': 'failed'})
    return sm
"""


def test_smach_ros_states_and_positional_parameters() -> None:
    model = loads(SMACH_ROS, "smach")
    assert isinstance(model, FSM)
    move = model.states["MOVE"]
    assert state_info.ros_interface(move) == (
        "action",
        "move_base_msgs/msg/MoveBaseAction",
        "move_base",
    )
    assert state_info.input_keys(move) == ["goal"]
    assert state_info.output_keys(move) == ["res"]
    assert state_info.remapping(move) == {"goal": "target"}
    assert state_info.parameters(move) == {"goal_key": "goal", "result_key": "res"}
    assert state_info.declared_outcomes(move) == ["succeeded", "aborted", "preempted"]
    clear = model.states["CLEAR"]
    assert state_info.ros_interface(clear) == ("service", "std_srvs/srv/Empty", "/clear")
    wait = model.states["WAIT"]
    assert state_info.parameters(wait) == {"seconds": "2.5", "label": "name_var"}
    assert state_info.expression_parameters(wait) == ["label"]
    assert state_info.output_keys(wait) == ["waited"]
    assert state_info.input_keys(model) == ["target"]
    assert state_info.userdata_values(model) == {"speed": "0.25"}
    # SMACH keeps the parameters and keys; the ROS interfaces are named as losses
    result = _translated(model, "smach")
    (ros_loss,) = [x for x in result.losses if "ROS action/service state(s)" in x]
    assert ros_loss.startswith("2 ROS action/service state(s) written as stub state classes")
    assert "'MOVE' (action move_base_msgs/msg/MoveBaseAction on 'move_base')" in ros_loss
    assert "'CLEAR' (service std_srvs/srv/Empty on '/clear')" in ros_loss
    assert "Wait(seconds=2.5, label=name_var)" in result.text


@needs_corpus
def test_ros2_simple_action_state_with_its_node_argument() -> None:
    model = api.load(CORPUS / "fsm" / "smach_tests" / "simple_action.py").model
    assert isinstance(model, FSM)
    found = {
        name: state
        for _p, _m, state in model.walk()
        for name in [state.name]
        if state_info.ros_interface(state) is not None
    }
    goal_key = found["GOAL_KEY"]
    assert state_info.ros_interface(goal_key) == (
        "action",
        "action_tutorials_interfaces/action/Fibonacci",
        "fibonacci",
    )
    assert state_info.input_keys(goal_key) == ["g1"]
    assert "node" not in state_info.parameters(goal_key)  # the ROS 2 node is not a parameter
    assert state_info.remapping(found["GOAL_SLOTS_REMAP"]) == {"order": "goal_alias"}


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


BEHAVIOUR = """\
from flexbe_core import Behavior, Autonomy, OperatableStateMachine
from my_states.work_state import WorkState
from inner_behavior.inner_sm import InnerSM

class DemoSM(Behavior):
    def __init__(self):
        super(DemoSM, self).__init__()
        self.add_behavior(InnerSM, 'Inner')

    def create(self):
        _sm = OperatableStateMachine(outcomes=['finished', 'failed'])
        with _sm:
            # x:30 y:40
            OperatableStateMachine.add('Work', WorkState(3, speed=0.5),
                                       transitions={'done': 'Inner', 'failed': 'failed'},
                                       autonomy={'done': Autonomy.Off, 'failed': Autonomy.Off})
            OperatableStateMachine.add('Inner', self.use_behavior(InnerSM, 'Inner'),
                                       transitions={'finished': 'finished', 'failed': 'failed'},
                                       autonomy={'finished': Autonomy.Inherit,
                                                 'failed': Autonomy.Inherit})
        return _sm
"""

INNER = """\
from flexbe_core import Behavior, OperatableStateMachine
from my_states.work_state import WorkState

class InnerSM(Behavior):
    def create(self):
        _sm = OperatableStateMachine(outcomes=['finished', 'failed'])
        with _sm:
            OperatableStateMachine.add('{label}', WorkState(1),
                                       transitions={{'done': 'finished', 'failed': 'failed'}})
        return _sm
"""

STATE = """\
from flexbe_core import EventState

class WorkState(EventState):
    def __init__(self, count, speed=1.0):
        super(WorkState, self).__init__(outcomes=['done', 'failed'], input_keys=['target'])
"""


def test_ros1_workspace_lookup_in_the_packages_the_imports_name(tmp_path: Path) -> None:
    ws = tmp_path / "ws" / "src"
    outer = _write(
        ws / "project" / "my_behaviors" / "src" / "my_behaviors" / "demo_sm.py", BEHAVIOUR
    )
    _write(ws / "project" / "my_states" / "src" / "my_states" / "work_state.py", STATE)
    _write(
        ws / "project" / "inner_behavior" / "src" / "inner_behavior" / "inner_sm.py",
        INNER.format(label="RightInner"),
    )
    # the same module name beside the behaviour, from another package: never read instead
    _write(outer.parent / "inner_sm.py", INNER.format(label="WrongInner"))
    warnings: list[str] = []
    loaded = api.load(outer)
    model = loaded.model
    warnings.extend(loaded.warnings)
    assert isinstance(model, FSM)
    assert set(model.states["Inner"].regions[0].states) == {"RightInner", "finished", "failed"}
    work = model.states["Work"]
    # declared by the state class in its own package, read statically
    assert state_info.declared_outcomes(work) == ["done", "failed"]
    assert state_info.input_keys(work) == ["target"]
    assert state_info.parameters(work) == {"count": "3", "speed": "0.5"}
    assert state_info.position(work) == (30, 40)
    assert not any("opaque" in w for w in warnings)


CORPUS_FILES = sorted(
    [
        *(CORPUS / "fsm").glob("smach_tutorials/*.py"),
        *(CORPUS / "fsm").glob("smach_tests/*.py"),
        *(CORPUS / "fsm").glob("flexbe_turtlesim_demo/*_sm.py"),
    ]
)


def _annotated(model: FSM) -> dict[str, set[str]]:
    """Annotation kind -> paths of the states carrying it (the top machine as "")."""
    out: dict[str, set[str]] = {}
    for key in state_info.KEYS:
        if key in model.attrs:
            out.setdefault(key, set()).add("")
    for path, _machine, state in model.walk():
        for key in state.attrs:
            if key in state_info.KEYS:
                out.setdefault(key, set()).add(path)
    return out


@needs_corpus
@pytest.mark.parametrize("path", CORPUS_FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_every_corpus_annotation_is_carried_or_named(path: Path) -> None:
    model = api.load(path).model
    assert isinstance(model, FSM)
    annotated = _annotated(model)
    # fsmbt JSON and SCXML carry every annotation: read back, the same states hold the same
    for target in ("json", "scxml"):
        result = translate(model, target)
        back = loads(result.text, target)
        if target == "json":
            assert result.losses == [] and differences_between(model, back) == []
        else:
            renamed = any("not SCXML ids" in line for line in result.losses)
            if not renamed:
                assert _annotated(back) == annotated, target
            assert not any("have no place" in line for line in result.losses)
    # Mermaid (flattened where it must be) has no place: each kind present is named once
    hierarchical = model.is_hierarchical
    lost = translate(model, "mermaid", flatten=hierarchical).losses
    for key in annotated:
        what = state_info.DESCRIPTIONS[key]
        named = [line for line in lost if line.startswith(f"{what} of ")]
        assert len(named) == 1, (key, lost)
