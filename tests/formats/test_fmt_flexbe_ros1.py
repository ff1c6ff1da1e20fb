"""FlexBE as people wrote it for ROS 1 (issue 26 item 2): Python 2 syntax and mixed tabs read
without running anything, ConcurrencyContainer product names that cannot clash, and the bad
input rules (a file that would run code at import is never run; what cannot be read is one
located line, exit 2).

The behaviour files are small synthetic ones written here in the ROS 1 editor's shape.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import loads
from fsmbt.formats.pysm.py2 import normalise
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify

ROOT = Path(__file__).resolve().parents[2]

# Python 2: print statements, except X, e, raise E, v, backticks, ur'', 0777, 10L, <>, and
# indentation mixing tabs (8 columns in Python 2) with spaces.
ROS1 = (
    "#!/usr/bin/env python\n"
    "import roslib; roslib.load_manifest('behavior_old')\n"
    "from flexbe_core import Behavior, Autonomy, OperatableStateMachine, Logger\n"
    "from flexbe_states.log_state import LogState\n"
    "from flexbe_states.wait_state import WaitState\n"
    "\n"
    "class OldSM(Behavior):\n"
    "\tdef __init__(self):\n"
    "\t\tsuper(OldSM, self).__init__()\n"
    "\t\tself.name = ur'Old'\n"
    "\n"
    "\tdef create(self):\n"
    "\t\t_sm = OperatableStateMachine(outcomes=['finished', 'failed'])\n"
    "\t\t_sm.userdata.mode = 0755 + 10L\n"
    "\t\ttry:\n"
    "\t\t    note = `self.name`\n"  # tab then spaces: 12 columns in Python 2
    "\t\texcept Exception, e:\n"
    "\t\t\tprint 'failed:', e\n"
    "\t\t\traise ValueError, 'bad'\n"
    "\t\tif 1 <> 2: print >>sys.stderr, 'x',\n"
    "\t\twith _sm:\n"
    "\t\t\t# x:30 y:40\n"
    "\t\t\tOperatableStateMachine.add('Log', LogState(text='hi', severity=Logger.REPORT_HINT),\n"
    "\t\t\t\ttransitions={'done': 'Wait'}, autonomy={'done': Autonomy.Off})\n"
    "\t\t\tOperatableStateMachine.add('Wait', WaitState(wait_time=2),\n"
    "\t\t\t\ttransitions={'done': 'finished'}, autonomy={'done': Autonomy.Off})\n"
    "\t\treturn _sm\n"
    "\n"
    "\tdef helper(self, x):\n"
    "\t\tprint x\n"
    "\t\texec 'y = 1'\n"
)


def test_ros1_python2_behaviour_reads_with_one_warning() -> None:
    warnings: list[str] = []
    model = loads(ROS1, "flexbe", warnings=warnings)
    assert isinstance(model, FSM) and model.name == "OldSM"
    assert {(t.source, t.event, t.target) for t in model.transitions} == {
        ("Log", "done", "Wait"),
        ("Wait", "done", "finished"),
    }
    notes = [w for w in warnings if "read as Python 2 source (nothing run)" in w]
    assert len(notes) == 1
    for rewrite in ("tabs", "'print'", "'except X, e'", "'raise E, value'", "backticks", "ur''"):
        assert rewrite in notes[0], rewrite
    assert model.states["Log"].attrs["position"] == "[30, 40]"
    assert model.attrs["userdata.values"] == '{"mode": "0o755 + 10"}'  # an expression: as read


def test_python3_text_is_never_rewritten() -> None:
    python3 = (
        ROS1.replace("\t", "    ")
        .replace("ur'Old'", "'Old'")
        .replace("0755 + 10L", "0o755 + 10")
        .replace("`self.name`", "repr(self.name)")
        .replace("Exception, e", "Exception as e")
        .replace("print 'failed:', e", "print('failed:', e)")
        .replace("ValueError, 'bad'", "ValueError('bad')")
        .replace("1 <> 2: print >>sys.stderr, 'x',", "1 != 2: print('x', file=sys.stderr)")
        .replace("print x", "print(x)")
        .replace("exec 'y = 1'", "exec('y = 1')")
    )
    warnings: list[str] = []
    model = loads(python3, "flexbe", warnings=warnings)
    assert not any("Python 2" in w for w in warnings)
    assert model.attrs["userdata.values"] == '{"mode": "0o755 + 10"}'


def test_normalised_text_keeps_every_line() -> None:
    out = normalise(ROS1)
    assert out.text.count("\n") == ROS1.count("\n")
    lines = out.text.splitlines()
    assert lines[17].strip() == "print('failed:', e)"
    assert lines[19].strip() == "if 1 != 2: print ( 'x', file=sys.stderr)"
    assert lines[-1].strip() == "exec('y = 1')"


def test_an_error_after_a_rewrite_names_the_original_line() -> None:
    broken = ROS1.replace("transitions={'done': 'finished'}", "transitions={'done': 'nowhere'}")
    with pytest.raises(InputError) as caught:
        loads(broken, "flexbe")
    assert caught.value.location is not None and caught.value.location.line == 25
    assert "nowhere" in str(caught.value)


CONCURRENCY = """\
from flexbe_core import Behavior, OperatableStateMachine, ConcurrencyContainer
from my_states.a import StepState, WatchState

class LoopSM(Behavior):
    def create(self):
        _sm = OperatableStateMachine(outcomes=['finished'])
        _cc = ConcurrencyContainer(outcomes=['finished'],
                                   conditions=[('finished', [('Watch', 'seen')])])
        with _cc:
            _loop = OperatableStateMachine(outcomes=['finished'])
            with _loop:
                OperatableStateMachine.add('First', StepState(), transitions={'next': 'Second'})
                OperatableStateMachine.add('Second', StepState(), transitions={'next': 'First'})
            OperatableStateMachine.add('Loop', _loop, transitions={'finished': 'finished'})
            OperatableStateMachine.add('Watch', WatchState(), transitions={'seen': 'finished'})
        with _sm:
            OperatableStateMachine.add('Both', _cc, transitions={'finished': 'finished'})
        return _sm
"""


def test_concurrency_product_names_never_clash() -> None:
    # the loop child comes back to its first state with only its own action running: the
    # same positions as the start, another action - a distinct product state
    model = loads(CONCURRENCY, "flexbe")
    assert isinstance(model, FSM)
    inner = model.states["Both"].regions[0]
    names = list(inner.states)
    assert len(names) == len(set(names))
    start = inner.initial
    assert start is not None and inner.states[start].action == "StepState+WatchState"
    assert any(n.startswith(start) and n != start for n in names)
    from fsmbt.convert import convert

    assert verify(model, convert(model).model).equivalent


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", *args],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        cwd=cwd,
        check=False,
    )


MALICIOUS = """\
import os
os.system('touch RAN_SYSTEM')
open('RAN_OPEN', 'w').write('x')
__import__('subprocess').call(['touch', 'RAN_SUBPROCESS'])
from flexbe_core import Behavior, OperatableStateMachine
from flexbe_states.log_state import LogState

class EvilSM(Behavior):
    def create(self):
        exec("open('RAN_EXEC', 'w')")
        _sm = OperatableStateMachine(outcomes=['finished'])
        with _sm:
            OperatableStateMachine.add('Log', LogState(text=open('RAN_ARG', 'w')),
                                       transitions={'done': 'finished'})
        return _sm

print 'and Python 2 too'
"""


def test_a_file_that_runs_code_at_import_is_never_run(tmp_path: Path) -> None:
    source = tmp_path / "evil_sm.py"
    source.write_text(MALICIOUS, encoding="utf-8")
    done = _cli("convert", str(source), "-o", str(tmp_path / "out.xml"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert not list(tmp_path.glob("RAN_*"))
    model = api.load(source).model
    log = model.states["Log"]
    assert log.attrs["params.expr"] == '["text"]'  # the call is kept as text, not made
    assert "open('RAN_ARG', 'w')" in log.attrs["params"]


@pytest.mark.parametrize(
    ("text", "line", "cause"),
    [
        ("from flexbe_core import Behavior\nclass X(Behavior:\n    pass\n", 2, "syntax error"),
        ("from flexbe_core import Behavior\nx = 'never closed\n", 2, "syntax error"),
        ("from flexbe_core import Behavior\n\tx = 1\n", 2, "syntax error"),
    ],
)
def test_what_cannot_be_read_is_one_located_line_exit_2(
    tmp_path: Path, text: str, line: int, cause: str
) -> None:
    source = tmp_path / "bad_sm.py"
    source.write_text(text, encoding="utf-8")
    done = _cli("convert", str(source), "-o", str(tmp_path / "out.xml"), cwd=tmp_path)
    assert done.returncode == 2
    lines = [x for x in done.stderr.splitlines() if x.strip()]
    assert lines and lines[0].startswith(f"error: {source}:{line}"), done.stderr
    assert cause in lines[0]
    assert "Traceback" not in done.stderr


EMBEDDING = """\
from flexbe_core import Behavior, OperatableStateMachine
from gone_behaviors.gone_sm import GoneSM

class OuterSM(Behavior):
    def create(self):
        _sm = OperatableStateMachine(outcomes=['finished', 'failed'])
        with _sm:
            OperatableStateMachine.add('Gone', self.use_behavior(GoneSM, 'Gone'),
                                       transitions={'finished': 'finished', 'failed': 'failed'})
        return _sm
"""


def test_convert_strict_refuses_an_embedded_behaviour_not_found(tmp_path: Path) -> None:
    source = tmp_path / "outer_sm.py"
    source.write_text(EMBEDDING, encoding="utf-8")
    done = _cli("convert", str(source), "-o", str(tmp_path / "out.xml"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    said = done.stdout + done.stderr
    assert "embedded behaviour 'GoneSM' not found" in said
    assert "opaque state 'Gone'" in said and "verdict: EQUIVALENT" in said
    strict = _cli("convert", str(source), "-o", str(tmp_path / "o2.xml"), "--strict", cwd=tmp_path)
    assert strict.returncode == 2
    assert f"{source}:8" in strict.stderr and "strict reading refuses" in strict.stderr


def test_mangled_python2_sources_fail_only_with_located_input_errors() -> None:
    """Seeded mutations of the ROS 1 file (quotes, backticks, tabs, brackets, keywords): the
    normaliser and the reader end in a model or a located ``InputError``/``UnsupportedError``,
    never another exception."""
    import random

    from fsmbt.model.errors import FsmbtError

    rng = random.Random(26)
    outcomes = {"read": 0, "refused": 0}
    pieces = list("`'\"\t ,()[]{}:<>\\\n#") + [
        "print ",
        "exec ",
        "except ",
        "raise ",
        "ur",
        "0",
        "L",
    ]
    for _ in range(150):
        text = list(ROS1)
        for _ in range(rng.randint(1, 6)):
            where = rng.randrange(len(text))
            choice = rng.random()
            if choice < 0.4:
                text.insert(where, rng.choice(pieces))
            elif choice < 0.7:
                del text[where]
            else:
                text[where] = rng.choice(pieces)
        try:
            loads("".join(text), "flexbe")
            outcomes["read"] += 1
        except FsmbtError as exc:
            outcomes["refused"] += 1
            assert exc.location is not None and str(exc).startswith("<input>")
    assert outcomes["read"] > 0 and outcomes["refused"] > 0, outcomes
