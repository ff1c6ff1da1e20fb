"""YASMIN (ROS 2): the yasmin_factory XML and YASMIN Python, read statically; the XML writer
(docs/formats/yasmin.md). The corpus files are real files of uleroboticsgroup/yasmin."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats.registry import dumps, loads, read_text
from fsmbt.formats.translate import translate
from fsmbt.model import Model, state_info
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM, State
from support.corpus import CORPUS


def read_model(path: Path, warnings: list[str] | None = None) -> Model:
    """Read one file with the reader its content or extension selects (as ``api.load``)."""
    return loads(read_text(path), path=Path(path), warnings=warnings)


YASMIN = CORPUS / "fsm" / "yasmin"
FILES = sorted(YASMIN.glob("*.xml")) if YASMIN.is_dir() else []
needs_corpus = pytest.mark.skipif(not FILES, reason=f"corpus not present ({YASMIN})")


@needs_corpus
def test_every_corpus_file_converts_with_no_option_and_verifies() -> None:
    assert len(FILES) == 10
    for path in FILES:
        outcome = api.convert_file(path)
        assert outcome.source.format == "yasmin", path
        assert api.verdict_word(outcome.report) == "EQUIVALENT", path


@needs_corpus
def test_states_carry_their_declarations() -> None:
    fsm = read_model(YASMIN / "demo_1.xml")
    assert isinstance(fsm, FSM)
    foo = fsm.states["Foo"]
    assert foo.action == "yasmin_demos/FooState"
    assert state_info.declared_outcomes(foo) == ["outcome1", "outcome2"]
    # ParamRemap: the child's parameter takes the machine's (an expression, not a literal)
    assert state_info.parameters(foo)["counter_prefix"] == "shared_prefix"
    assert "counter_prefix" in state_info.expression_parameters(foo)
    bar = fsm.states["Bar"]
    assert bar.attrs["yasmin.module"] == "yasmin_demos.bar_state"
    assert bar.attrs["yasmin.position"] == "157.80 84.20"
    # the machine's Param declarations (with defaults) are on the machine
    assert state_info.parameters(State("m", attrs=fsm.attrs))["foo_max_count"] == "2"
    ser = read_model(YASMIN / "ros_serialization_cpp_to_py.xml")
    assert isinstance(ser, FSM)
    assert state_info.remapping(ser.states["SerializeCpp"]) == {"input": "input", "output": "bytes"}
    # the machine's own Key / Param elements are on the machine
    assert json.loads(ser.attrs[state_info.INPUT_KEYS]) == ["input", "bytes", "output"]


@needs_corpus
def test_nested_machine_is_a_composite_left_by_its_outcomes() -> None:
    fsm = read_model(YASMIN / "demo_fsm_metadata.xml")
    assert isinstance(fsm, FSM)
    nested = fsm.states["NestedSM"]
    assert nested.is_composite
    inner = nested.regions[0]
    assert inner.initial == "Bar" and inner.states["outcome3"].final
    (out,) = fsm.outgoing("NestedSM")
    assert (out.event, out.exit, out.target) == (None, "outcome3", "Foo")


@needs_corpus
def test_join_state_barrier_lets_regions_pass_together_only() -> None:
    fsm = read_model(YASMIN / "demo_orthogonal_sync.xml")
    assert isinstance(fsm, FSM)
    product = fsm.states["parallel"].regions[0]
    joined = [t for t in product.transitions if t.event is not None and t.event.endswith("joined")]
    assert joined, "the barrier is crossed somewhere"
    for t in joined:  # only from the combination where both regions wait at their JoinState
        assert t.source.startswith("A:sync_a,B:sync_b"), t
        assert t.target.startswith("A:work_a2,B:work_b2"), t
    # and a region at its join with the other still working has no 'joined' step
    waiting = [s for s in product.states if s.startswith("A:sync_a,B:work_b1")]
    assert waiting
    for name in waiting:
        assert all(not (t.event or "").endswith("joined") for t in product.outgoing(name))


@needs_corpus
def test_included_package_machine_is_read_from_beside_the_file_with_a_warning() -> None:
    warnings: list[str] = []
    fsm = read_model(YASMIN / "runtime_test.xml", warnings=warnings)
    assert isinstance(fsm, FSM)
    demo3 = fsm.states["Demo3"]
    assert set(demo3.regions[0].states) == {"PoseWriter", "PoseReader", "outcome4"}
    assert any("package 'yasmin_demos' cannot be resolved here" in w for w in warnings)
    assert any(":41:" in w and "demo_1.xml" in w for w in warnings)


def _write(tmp: Path, name: str, text: str) -> Path:
    path = tmp / name
    path.write_text(text, encoding="utf-8")
    return path


SIMPLE = """<StateMachine name="M" outcomes="done" start_state="A">
  <State name="A" type="cpp" class="pkg/A"><Transition from="ok" to="Sub"/></State>
  <StateMachine name="Sub" {include}><Transition from="end" to="done"/></StateMachine>
  <FinalOutcome name="done"/>
</StateMachine>
"""
INCLUDED = """<StateMachine name="S" outcomes="end" start_state="X">
  <State name="X" type="py" module="m" class="X"><Transition from="go" to="end"/></State>
</StateMachine>
"""


def test_file_path_include_is_relative_to_the_including_file(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    _write(tmp_path / "sub", "inner.xml", INCLUDED)
    main = _write(tmp_path, "main.xml", SIMPLE.format(include='file_path="sub/inner.xml"'))
    fsm = read_model(main)
    assert isinstance(fsm, FSM)
    assert set(fsm.states["Sub"].regions[0].states) == {"X", "end"}
    assert api.verdict_word(api.convert_file(main).report) == "EQUIVALENT"


def test_package_found_in_its_source_folder(tmp_path: Path) -> None:
    package = tmp_path / "ws" / "src" / "my_pkg"
    (package / "state_machines").mkdir(parents=True)
    (package / "package.xml").write_text("<package/>", encoding="utf-8")
    _write(package / "state_machines", "inner.xml", INCLUDED)
    main = _write(
        package / "state_machines",
        "main.xml",
        SIMPLE.format(include='package="my_pkg" file_name="inner.xml"'),
    )
    warnings: list[str] = []
    fsm = read_model(main, warnings=warnings)
    assert isinstance(fsm, FSM) and "X" in fsm.states["Sub"].regions[0].states
    assert not any("cannot be resolved" in w for w in warnings)


@pytest.mark.parametrize(
    ("include", "message"),
    [
        (
            'package="nowhere_pkg" file_name="absent.xml"',
            "package 'nowhere_pkg' cannot be resolved",
        ),
        ('file_path="../outside.xml"', "resolves outside the including file's folder"),
        ('file_path="main.xml"', "includes itself"),
        ('file_path="/etc/hostname"', "outside the folder of the file read"),
        ('package="../../etc" file_name="passwd"', "is not a ROS package name"),
        ('package="my_pkg" file_name="../outside.xml"', "is not a file name"),
    ],
)
def test_include_errors_are_located(tmp_path: Path, include: str, message: str) -> None:
    main = _write(tmp_path, "main.xml", SIMPLE.format(include=include))
    with pytest.raises(InputError) as info:
        read_model(main)
    assert message in str(info.value)
    assert f"{main}:3" in str(info.value)


def test_an_absolute_file_path_is_confined_to_the_folder_read_or_include_root(
    tmp_path: Path,
) -> None:
    """docs/security.md, rule 4: an absolute ``file_path`` out of the folder of the file read
    is refused, and read once ``include_root`` names a folder holding it."""
    (tmp_path / "shared").mkdir()
    inner = _write(tmp_path / "shared", "inner.xml", INCLUDED)
    (tmp_path / "main").mkdir()
    main = _write(tmp_path / "main", "main.xml", SIMPLE.format(include=f'file_path="{inner}"'))
    with pytest.raises(InputError, match="outside the folder of the file read"):
        read_model(main)
    fsm = loads(read_text(main), path=main, options={"include_root": str(tmp_path)})
    assert isinstance(fsm, FSM) and "X" in fsm.states["Sub"].regions[0].states


@pytest.mark.parametrize(
    "include", [f'file_path="{Path(__file__).resolve()}"', 'package="p" file_name="a.xml"']
)
def test_a_text_includes_no_file(include: str) -> None:
    """A text (a paste, a web upload) has no folder: no include is resolved, so no file of the
    host is read, whatever path it names."""
    with pytest.raises(InputError, match="needs the including file's path") as info:
        loads(SIMPLE.format(include=include), "yasmin")
    assert str(info.value).startswith("<input>:3:")


def test_unknown_element_is_one_located_line_exit_2(tmp_path: Path) -> None:
    bad = _write(
        tmp_path,
        "bad.xml",
        '<StateMachine name="M" outcomes="done" start_state="A">\n'
        '  <State name="A" type="cpp" class="p/A">\n'
        '    <Transition from="x" to="done"/>\n'
        '    <Timer period="1"/>\n'
        "  </State>\n"
        "</StateMachine>\n",
    )
    with pytest.raises(InputError, match=r"bad.xml:4: .*unknown YASMIN element <Timer>"):
        read_model(bad)
    run = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "convert", str(bad)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2
    lines = [line for line in run.stderr.splitlines() + run.stdout.splitlines() if line.strip()]
    assert len(lines) == 1 and f"{bad}:4" in lines[0], lines


def test_outcome_map_naming_an_unknown_state_is_refused(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "c.xml",
        '<StateMachine name="M" outcomes="ok" start_state="C">\n'
        '  <Concurrence name="C" default_outcome="ok">\n'
        '    <State name="A" type="cpp" class="p/A"/>\n'
        '    <OutcomeMap outcome="ok"><Item state="Z" outcome="x"/></OutcomeMap>\n'
        '    <Transition from="ok" to="ok"/>\n'
        "  </Concurrence>\n"
        "</StateMachine>\n",
    )
    with pytest.raises(InputError, match="names 'Z'"):
        read_model(path)


@needs_corpus
def test_written_yasmin_reads_back_equivalent() -> None:
    for path in FILES:
        fsm = read_model(path)
        back = loads(dumps(fsm, "yasmin"), "yasmin")
        assert api.verdict_word(api.verify_models(fsm, back)) == "EQUIVALENT", path


def test_bt_to_fsm_result_written_as_yasmin_is_equivalent() -> None:
    examples = Path(__file__).resolve().parents[2] / "examples"
    outcome = api.convert_file(examples / "robot_bt.xml")
    hfsm = outcome.result
    assert isinstance(hfsm, FSM)
    result = translate(hfsm, "yasmin")
    assert result.checked is not None and result.read_back is not None
    assert api.verdict_word(api.verify_models(result.checked, result.read_back)) == "EQUIVALENT"
    back = loads(result.text, "yasmin")
    assert api.verdict_word(api.verify_models(flatten(hfsm), flatten(back))) == "EQUIVALENT"
    # the root statuses are final states with actions: kept for fsmbt, named for YASMIN
    assert any("YASMIN runs none on reaching an outcome" in loss for loss in result.losses)


def test_what_yasmin_cannot_hold_is_named() -> None:
    fsm = FSM(name="m")
    fsm.add_state("A")
    fsm.add_state("B")
    fsm.states["end"] = State("end", action="report", final=True)
    fsm.add_transition("A", "go", "B")
    fsm.add_transition("B", "stop", "end", attrs={"note": "by hand"})
    fsm.start_name, fsm.initial_event = "start", "power"
    result = translate(fsm, "yasmin")
    assert result.checked is not None and result.read_back is not None
    assert api.verdict_word(api.verify_models(result.checked, result.read_back)) == "EQUIVALENT"
    back = loads(result.text, "yasmin")
    assert isinstance(back, FSM)  # the start pseudo-state and its event come back
    assert (back.start_name, back.initial_event, back.initial) == ("start", "power", "A")
    assert any("YASMIN runs none on reaching an outcome" in x for x in result.losses)
    assert any("note" in x and "is lost" in x for x in result.losses), result.losses
    parallel = FSM(name="p")
    parallel.add_state("P", regions=[FSM(name="r1"), FSM(name="r2")], action=None)
    parallel.states["end"] = fsm.states["end"]
    with pytest.raises(UnsupportedError, match="parallel state 'P'"):
        dumps(parallel, "yasmin")


PY = '''"""A YASMIN program."""
import rclpy
from yasmin import StateMachine, Concurrence
from yasmin_ros.basic_outcomes import SUCCEED, ABORT
from my_states import FooState, BarState


def main():
    rclpy.init()
    sm = StateMachine(outcomes=["done", ABORT])
    sm.add_state("FOO", FooState(speed=0.5), transitions={"outcome1": "BAR", "outcome2": "done"})
    sm.add_state("BAR", BarState(), transitions={SUCCEED: "FOO"}, remappings={"a": "b"})
    sm()


if __name__ == "__main__":
    main()
'''


def test_yasmin_python_is_read_statically(tmp_path: Path) -> None:
    path = _write(tmp_path, "demo.py", PY)
    fsm = read_model(path)
    assert isinstance(fsm, FSM)
    assert set(fsm.states) == {"FOO", "BAR", "done", "aborted"}
    assert {(t.source, t.event, t.target) for t in fsm.transitions} == {
        ("FOO", "outcome1", "BAR"),
        ("FOO", "outcome2", "done"),
        ("BAR", "succeeded", "FOO"),
    }
    assert state_info.parameters(fsm.states["FOO"]) == {"speed": "0.5"}
    assert state_info.remapping(fsm.states["BAR"]) == {"a": "b"}


def test_yasmin_python_code_at_import_is_refused_and_not_run(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    text = PY.replace("def main():", f"open({str(marker)!r}, 'w').write('x')\n\n\ndef main():")
    path = _write(tmp_path, "evil.py", text)
    line = text.splitlines().index(f"open({str(marker)!r}, 'w').write('x')") + 1
    with pytest.raises(InputError, match=rf"evil.py:{line}: code that runs when the file is"):
        read_model(path)
    run = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "info", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and f"{path}:{line}" in run.stderr + run.stdout
    assert not marker.exists()


ORTHOGONAL_PY = """from yasmin import JoinState, OrthogonalState, StateMachine
from my_states import Work


def build():
    a = StateMachine(outcomes=["done"])
    a.add_state("W1", Work(), transitions={"ok": "SYNC"})
    a.add_state("SYNC", JoinState("mid", "joined"), transitions={"joined": "W2"})
    a.add_state("W2", Work(), transitions={"ok": "done"})
    b = StateMachine(outcomes=["done"])
    b.add_state("SYNC", JoinState("mid"), transitions={"joined": "V"})
    b.add_state("V", Work(), transitions={"ok": "done"})
    ort = OrthogonalState("timeout", {"success": {"A": "done", "B": "done"}})
    ort.add_region("A", a)
    ort.add_region("B", b)
    sm = StateMachine(outcomes=["success", "timeout"])
    sm.add_state("PAR", ort, transitions={"success": "success", "timeout": "timeout"})
    return sm
"""


def test_yasmin_python_orthogonal_state_with_a_barrier(tmp_path: Path) -> None:
    fsm = read_model(_write(tmp_path, "ort.py", ORTHOGONAL_PY))
    assert isinstance(fsm, FSM)
    product = fsm.states["PAR"].regions[0]
    joined = [t for t in product.transitions if (t.event or "").endswith("joined")]
    assert [t.source.split(" ")[0] for t in joined] == ["A:SYNC,B:SYNC"]
    assert all(t.target.startswith("A:W2,B:V") for t in joined)
    assert api.verdict_word(api.verify_models(fsm, api.convert_model(fsm).model)) == "EQUIVALENT"


def test_a_region_may_be_an_included_machine(tmp_path: Path) -> None:
    _write(tmp_path, "inner.xml", INCLUDED)
    main = _write(
        tmp_path,
        "main.xml",
        '<StateMachine name="M" outcomes="ok" start_state="O">\n'
        '  <OrthogonalState name="O" default_outcome="ok">\n'
        '    <Region name="A" file_path="inner.xml"/>\n'
        '    <Region name="B" outcomes="done" start_state="Y">\n'
        '      <State name="Y" type="cpp" class="p/Y"><Transition from="y" to="done"/></State>\n'
        "    </Region>\n"
        '    <Transition from="ok" to="ok"/>\n'
        "  </OrthogonalState>\n"
        "</StateMachine>\n",
    )
    fsm = read_model(main)
    assert isinstance(fsm, FSM)
    product = fsm.states["O"].regions[0]
    assert {(t.source, t.event, t.target) for t in product.transitions} == {
        ("A:X,B:Y", "go", "A=end,B:Y"),
        ("A:X,B:Y", "y", "A:X,B=done"),
        ("A=end,B:Y", "y", "ok"),
        ("A:X,B=done", "go", "ok"),
    }
