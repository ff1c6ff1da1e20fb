"""fsmbt.runtime.python_runtime: a converted tree run with the user's callables (issue 11, 4).

- equivalence: for every example FSM, ``FSMBT_RUNTIME_FSMS`` generated FSMs (default 60) and
  ``FSMBT_RUNTIME_HFSMS`` generated HFSMs (default 30) converted by the rules engine, seeded
  random event sequences (``FSMBT_RUNTIME_SEQUENCES`` x ``FSMBT_RUNTIME_LENGTH``, default 4 x
  20) give, on py_trees and on BehaviorTree.CPP, the FSM's actions in the FSM's order (the
  callables really called, not the runner's report), the same state and the same termination
  after every event;
- load-time errors: a foreign node (named, with its line), an action without callable, a
  callable without action, an unknown engine, a file that is no tree;
- ``write_files`` (refuses to overwrite; the script runs) and examples/run_lebt_python.py.
"""

from __future__ import annotations

import os
import random
import re
import subprocess
import sys
from pathlib import Path

import pytest
from lxml import etree

from fsmbt import api
from fsmbt.convert.engines import converter_for
from fsmbt.formats import dumps
from fsmbt.generate import random_fsm
from fsmbt.model.errors import FsmbtError, InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.runtime.python_runtime import ENGINES, TreeRunner, load_tree, write_files
from fsmbt.semantics.machine import FINAL, FSMMachine
from support import hand_lebt

REPO = Path(__file__).resolve().parents[2]
FSMS = int(os.environ.get("FSMBT_RUNTIME_FSMS", "60"))
HFSMS = int(os.environ.get("FSMBT_RUNTIME_HFSMS", "30"))
SEQUENCES = int(os.environ.get("FSMBT_RUNTIME_SEQUENCES", "4"))
LENGTH = int(os.environ.get("FSMBT_RUNTIME_LENGTH", "20"))
SEED = int(os.environ.get("FSMBT_RUNTIME_SEED", "4"))

DOOR = REPO / "examples" / "door_hfsm.scxml"


def tree_of(fsm: FSM) -> str:
    # the LEBT runtimes run LEBTs (an outcome-driven example would be structured by default)
    return dumps(converter_for("rules", fsm)(fsm, style="lebt").model, "btcpp")


class Recorder:
    """One callable per action name; ``calls`` is what really ran."""

    def __init__(self, names: set[str]) -> None:
        self.calls: list[str] = []
        self.actions = {name: self._make(name) for name in names}

    def _make(self, name: str):
        return lambda: self.calls.append(name)


def fsm_actions(fsm: FSM) -> set[str]:
    machine = FSMMachine(fsm)
    return {s.action for s in machine.fsm.states.values() if s.action is not None}


def compare(fsm: FSM, tree: str, rng: random.Random) -> list[str]:
    """Differences between the FSM and both engines on ``SEQUENCES`` random sequences."""
    machine = FSMMachine(fsm)
    alphabet = list(machine.alphabet) + ["__not_an_event__"]
    problems: list[str] = []
    for _ in range(SEQUENCES):
        state, outputs = machine.start()
        events: list[str] = []
        steps = [(state, outputs, machine.status(state))]
        for _ in range(LENGTH):
            active = list(machine.active_inputs(state))
            event = rng.choice(active) if active and rng.random() < 0.85 else rng.choice(alphabet)
            state, outputs = machine.step(state, event)
            events.append(event)
            steps.append((state, outputs, machine.status(state)))
        for engine in ENGINES:
            recorder = Recorder(fsm_actions(fsm))
            runner = load_tree(tree, recorder.actions, engine=engine, allow_unused=True)
            seen = [runner.start()]
            got = [(tuple(recorder.calls), runner.state, runner.terminated)]
            for event in events:
                recorder.calls.clear()
                seen.append(runner.post(event))
                got.append((tuple(recorder.calls), runner.state, runner.terminated))
            want = [(outs, state, status == FINAL) for state, outs, status in steps]
            if got != want or [g[0] for g in got] != seen:
                index = (
                    next(i for i, (g, w) in enumerate(zip(got, want)) if g != w)
                    if got != want
                    else -1
                )
                problems.append(
                    f"{engine}: after {events[:index]} got {got[index]}, FSM {want[index]}"
                )
    return problems


def example_fsms() -> list[tuple[str, FSM]]:
    out = []
    for path in sorted((REPO / "examples").iterdir()):
        try:
            model = api.load(path).model
        except FsmbtError:
            continue
        if isinstance(model, FSM):
            out.append((path.name, model))
    return out


def test_examples_run_the_fsms_actions_on_both_engines() -> None:
    fsms = example_fsms()
    assert len(fsms) >= 5
    rng = random.Random(SEED)
    problems = {name: p for name, fsm in fsms if (p := compare(fsm, tree_of(fsm), rng))}
    assert not problems, problems


def test_generated_fsms_and_hfsms_run_the_fsms_actions_on_both_engines() -> None:
    rng = random.Random(SEED)
    from support.conv_hfsm_gen import random_hfsm

    models = [(f"fsm{i}", random_fsm(seed=SEED * 1000 + i, max_states=15)) for i in range(FSMS)]
    models += [
        (f"hfsm{i}", random_hfsm(SEED * 1000 + i, parallel=i % 3 == 2)) for i in range(HFSMS)
    ]
    compared, refused, problems = 0, 0, {}
    for name, fsm in models:
        try:
            tree = tree_of(fsm)
        except UnsupportedError:
            refused += 1
            continue
        compared += 1
        if found := compare(fsm, tree, rng):
            problems[name] = found[:2]
    print(
        f"\n[python runtime] {compared} models x {SEQUENCES} sequences x {LENGTH} events x "
        f"{len(ENGINES)} engines: {len(problems)} with differences; {refused} not converted"
    )
    assert compared >= 0.9 * len(models) and not problems, problems


def test_the_runtime_reports_what_the_callables_did() -> None:
    """Actions run once per entry and in order; the state and termination are readable."""
    calls: list[str] = []
    actions = {
        name: (lambda n=name: calls.append(n))
        for name in ("Closed", "Opening", "Open", "Closing", "Emergency", "Off")
    }
    for engine in ENGINES:
        calls.clear()
        runner = load_tree(tree_of(api.load(DOOR).model), actions, engine=engine)
        assert not runner.started and runner.start() == ("Closed",) and calls == ["Closed"]
        assert runner.state == "Operating/Closed"
        assert runner.post("fully_open") == () and calls == ["Closed"]  # ignored event
        assert runner.post("open_cmd") == ("Opening",)
        assert runner.post("fire_alarm") == ("Emergency",) and runner.state == "Emergency"
        assert runner.post("reset") == ("Closed",) and not runner.terminated
        assert runner.post("fire_alarm") == ("Emergency",)
        assert runner.post("shutdown") == ("Off",) and runner.terminated
        assert calls == ["Closed", "Opening", "Emergency", "Closed", "Emergency", "Off"]


# -- errors at load time --------------------------------------------------------------------------
DOOR_ACTIONS = {
    name: (lambda: None) for name in ("Closed", "Opening", "Open", "Closing", "Emergency", "Off")
}


def door_tree() -> str:
    return tree_of(api.load(DOOR).model)


def test_missing_callable_is_a_load_error_naming_the_action() -> None:
    partial = {k: v for k, v in DOOR_ACTIONS.items() if k != "Emergency"}
    for engine in ENGINES:
        with pytest.raises(
            InputError,
            match=r"no callable for the action\(s\) 'Emergency' "
            r"\(state 'Emergency'\)",
        ):
            load_tree(door_tree(), partial, engine=engine)


def test_unused_or_uncallable_actions_are_load_errors() -> None:
    with pytest.raises(InputError, match="'Emergncy'.*a typo"):
        load_tree(door_tree(), {**DOOR_ACTIONS, "Emergncy": lambda: None})
    assert load_tree(
        door_tree(), {**DOOR_ACTIONS, "Spare": lambda: None}, allow_unused=True
    ).used_actions == frozenset(DOOR_ACTIONS)
    with pytest.raises(InputError, match="'Off' are not callable"):
        load_tree(door_tree(), {**DOOR_ACTIONS, "Off": "print('x')"})  # type: ignore[dict-item]


@pytest.mark.parametrize(
    "tag, attrs, wrap",
    [
        ("MoveBase", {}, False),  # a foreign leaf in place of a state leaf
        ("Parallel", {"success_count": "1", "failure_count": "1"}, True),  # a foreign control
        ("ReactiveSequence", {}, True),
        ("Inverter", {}, True),  # a decorator
    ],
)
def test_a_foreign_node_is_named_with_its_line(tag: str, attrs: dict[str, str], wrap: bool) -> None:
    root = etree.fromstring(door_tree().encode())
    leaf = root.find(".//LebtState[@name='Emergency']")
    assert leaf is not None
    if wrap:
        wrapper = etree.Element(tag, attrs)
        leaf.addprevious(wrapper)
        wrapper.append(leaf)
    else:
        leaf.tag = tag
    bad = etree.tostring(root, pretty_print=True, encoding="unicode")
    line = next(i for i, text in enumerate(bad.splitlines(), 1) if f"<{tag}" in text)
    for engine in ENGINES:
        with pytest.raises(InputError) as info:
            load_tree(bad, DOOR_ACTIONS, engine=engine)
        assert f"<{tag}>" in str(info.value) and "not a node of a converted tree" in str(info.value)
        assert info.value.location is not None and info.value.location.line == line


def test_a_dispatch_tree_runs_on_fsmbt_and_the_lebt_engines_refuse_it() -> None:
    door = api.load(DOOR).model
    text = dumps(converter_for("rules", door)(door).model, "btcpp")  # auto: the dispatch form
    assert "<DispatchEntry" in text
    for engine in ENGINES:
        with pytest.raises(InputError, match=f"dispatch tree.*runs on fsmbt, not on '{engine}'"):
            load_tree(text, DOOR_ACTIONS, engine=engine)
    recorder = Recorder(set(DOOR_ACTIONS))
    runner = load_tree(text, recorder.actions)
    assert runner.engine == "fsmbt"
    runner.start()
    for event in ["open_cmd", "fully_open", "fire_alarm", "open_cmd", "shutdown"]:
        runner.post(event)
    assert recorder.calls == ["Closed", "Opening", "Open", "Emergency", "Off"]
    assert runner.state == "Off" and runner.terminated


def test_bad_sources_and_engines_are_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="unknown engine 'ros'"):
        load_tree(door_tree(), DOOR_ACTIONS, engine="ros")
    with pytest.raises(InputError, match="not a behavior tree"):
        load_tree(DOOR, DOOR_ACTIONS)
    broken = tmp_path / "broken.xml"
    broken.write_text("<root BTCPP_format='4'><BehaviorTree ID='M'>", encoding="utf-8")
    with pytest.raises(InputError):
        load_tree(broken, DOOR_ACTIONS)
    with pytest.raises(InputError):
        load_tree(tmp_path / "missing.xml", DOOR_ACTIONS)
    tree_file = tmp_path / "door_bt.xml"
    tree_file.write_text(door_tree(), encoding="utf-8")
    assert load_tree(str(tree_file), DOOR_ACTIONS).used_actions == frozenset(DOOR_ACTIONS)


def test_call_order_errors_and_action_exceptions() -> None:
    runner = load_tree(door_tree(), DOOR_ACTIONS)
    with pytest.raises(RuntimeError, match="start"):
        runner.post("open_cmd")
    runner.start()
    with pytest.raises(RuntimeError, match="already started"):
        runner.start()

    def broken() -> None:
        raise ValueError("motor driver offline")

    runner = load_tree(door_tree(), {**DOOR_ACTIONS, "Opening": broken})
    runner.start()
    with pytest.raises(ValueError, match="motor driver offline"):
        runner.post("open_cmd")


def test_runner_class_is_the_loaded_type() -> None:
    assert isinstance(load_tree(door_tree(), DOOR_ACTIONS), TreeRunner)


# -- the example folder and the example script -----------------------------------------------------
def test_write_files_refuses_to_overwrite_and_the_script_runs(tmp_path: Path) -> None:
    folder = tmp_path / "example"
    written = write_files(folder, overwrite=False)
    assert sorted(p.name for p in written) == ["lebt_tree.xml", "run_lebt.py"]
    assert all(p.parent == folder and p.stat().st_size > 0 for p in written)
    script = folder / "run_lebt.py"
    script.write_text(script.read_text(encoding="utf-8") + "\n# mine\n", encoding="utf-8")
    with pytest.raises(InputError, match="already exist"):
        write_files(folder, overwrite=False)
    assert script.read_text(encoding="utf-8").endswith("# mine\n")  # nothing was touched
    assert write_files(folder, overwrite=True) == written
    assert not script.read_text(encoding="utf-8").endswith("# mine\n")
    (tmp_path / "file").write_text("x", encoding="utf-8")
    with pytest.raises(InputError, match="not a folder"):
        write_files(tmp_path / "file", overwrite=True)
    done = subprocess.run(
        [sys.executable, "run_lebt.py"],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env={**os.environ, "PYTHONPATH": str(REPO / "src")},
    )
    assert done.returncode == 0, done.stderr
    for engine in ENGINES:
        assert f"engine {engine}" in done.stdout
    assert done.stdout.count("action: motor forward") == 3 * 2  # open, obstacle, open
    assert done.stdout.count("state Stopped, terminated True") == 2


def test_example_script_runs() -> None:
    done = subprocess.run(
        [sys.executable, str(REPO / "examples" / "run_lebt_python.py")],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env={**os.environ, "PYTHONPATH": str(REPO / "src")},
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().endswith("both engines ran the FSM's actions")
    assert done.stdout.count("running action H") == 2


def test_the_docs_snippet_runs_as_written(tmp_path: Path) -> None:
    """docs/runtime-python.md's shell line and Python block, run as written (the examples
    path made absolute, the files written in a scratch folder), print what the page shows."""
    page = (REPO / "docs" / "runtime-python.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```(\w*)\n(.*?)```", page, flags=re.S)
    shell = next(body for lang, body in blocks if lang == "sh").strip()
    python = next(body for lang, body in blocks if lang == "python")
    shown = next(body for lang, body in blocks if lang == "" and "motor off" in body)
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    args = shell.replace("examples/", f"{REPO / 'examples'}/").split()
    assert args[0] == "fsmbt"
    done = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", *args[1:]],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env=env,
    )
    assert done.returncode == 0, done.stderr
    (tmp_path / "snippet.py").write_text(python, encoding="utf-8")
    for engine in ENGINES:
        script = python.replace('engine="py_trees")', f'engine="{engine}")')
        (tmp_path / "snippet.py").write_text(script, encoding="utf-8")
        done = subprocess.run(
            [sys.executable, "snippet.py"],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
            env=env,
        )
        assert done.returncode == 0, done.stderr
        assert done.stdout == shown, (engine, done.stdout)


# -- callbacks get the state's label and parameters; annotations checked at load -------------
def test_callbacks_get_the_state_label_and_its_parameters() -> None:
    seen: list[tuple[str, str, dict[str, str]]] = []
    for engine in ENGINES:
        seen.clear()
        actions = {
            "TimedCmdVelState": lambda state, params: seen.append(
                ("TimedCmdVelState", state, params)
            ),
            "LogState": lambda state, params: seen.append(("LogState", state, params)),
        }
        runner = load_tree(hand_lebt.TREE, actions, engine=engine)
        assert runner.start() == ("TimedCmdVelState",)
        assert runner.post("go") == ("TimedCmdVelState",)
        assert runner.post("stop") == ("LogState",) and runner.terminated
        assert seen == hand_lebt.ENTRIES, engine
    with pytest.raises(InputError, match="must take \\(state, params\\) or no argument"):
        load_tree(hand_lebt.TREE, {"TimedCmdVelState": lambda state: None, "LogState": print})


@pytest.mark.parametrize("case", [c[0] for c in hand_lebt.BROKEN])
def test_hand_broken_annotations_are_load_errors_naming_the_node(case: str) -> None:
    _, replaced, replacement, node, line = next(c for c in hand_lebt.BROKEN if c[0] == case)
    actions = {"TimedCmdVelState": lambda: None, "LogState": lambda: None}
    for engine in ENGINES:
        with pytest.raises(InputError) as info:
            load_tree(hand_lebt.broken(replaced, replacement), actions, engine=engine)
        assert f"'{node}'" in str(info.value), str(info.value)
        assert info.value.location is not None and info.value.location.line == line
