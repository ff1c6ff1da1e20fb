"""``fsmbt runtime cpp DIR MODEL`` for the tree of an event-driven machine (the dispatch form or
an LEBT): fsmbt's runtime header, a base class with one method per state action, the user's
``Actions`` and a main (``fsmbt.runtime.skeleton.machine``; docs/runtime.md, "An event-driven
machine").

Compiled once per module against the BehaviorTree.CPP 4.8.2 build, with ``actions.hpp`` filled
in as a user would (one action overridden): the binary runs the paper's A-J machine's dispatch
tree on seeded event sequences and must enter the states, run the actions and terminate as
fsmbt's FSM interpreter does; the same binary refuses a tree whose actions it has no method for
and a hand-broken dispatch tree, with one line naming the cause.
"""

from __future__ import annotations

import json
import random
import shutil
import subprocess
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.model.fsm import FSM
from fsmbt.runtime.cpp import library_built, library_prefix
from fsmbt.semantics.machine import FINAL, FSMMachine
from support.event_walks import event_walks

REPO = Path(__file__).resolve().parents[2]
PAPER = REPO / "examples" / "paper_fsm.json"
USER_ACTIONS = """#pragma once
#include "actions_base.hpp"

namespace fsmbt_actions {

class Actions : public generated::ActionsBase
{
public:
  void on_D(const std::string& state, const fsmbt::lebt::Parameters&) override
  {
    std::cout << "  user D in " << state << "\\n";
  }
};

}  // namespace fsmbt_actions
"""


def _cli(capsys, *args: str) -> tuple[int, str, str]:
    try:
        code = main(list(args))
    except SystemExit as exc:
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def _tree(fsm: FSM, path: Path, style: str = "auto") -> Path:
    path.write_text(dumps(convert(fsm, style=style).model, "btcpp"), encoding="utf-8")
    return path


def _paper() -> FSM:
    fsm = api.load(PAPER).model
    assert isinstance(fsm, FSM)
    return fsm


def test_writes_runtime_actions_and_main_and_keeps_user_files(tmp_path: Path, capsys) -> None:
    tree = _tree(_paper(), tmp_path / "paper_bt.xml")
    out = tmp_path / "sk"
    code, text, err = _cli(capsys, "runtime", "cpp", str(out), str(tree))
    assert code == 0, err
    for name in (
        "tree.xml",
        "generated/include/fsmbt/lebt.hpp",
        "generated/actions_base.hpp",
        "actions.hpp",
        "main.cpp",
        "CMakeLists.txt",
    ):
        assert (out / name).is_file(), name
    base = (out / "generated" / "actions_base.hpp").read_text(encoding="utf-8")
    for action in "ABCDEFGHIJ":
        assert f"virtual void on_{action}(const std::string& state" in base
        assert f'registry.add("{action}",' in base
    record = json.loads((out / "generated" / "skeleton.json").read_text(encoding="utf-8"))
    assert record["form"] == "dispatch" and sorted(record["actions"]) == list("ABCDEFGHIJ")
    # the machine changes: action J renamed K; the user's files are kept, the change reported
    (out / "actions.hpp").write_text(USER_ACTIONS, encoding="utf-8")
    changed = tree.read_text(encoding="utf-8").replace('action="J"', 'action="K"')
    tree.write_text(changed, encoding="utf-8")
    code, text, err = _cli(capsys, "runtime", "cpp", str(out), str(tree))
    assert code == 0, err
    assert (out / "actions.hpp").read_text(encoding="utf-8") == USER_ACTIONS
    assert "(yours: kept)" in text
    assert "changed: action K: new; generated::ActionsBase::on_K" in text
    assert "changed: action J: no longer in the tree" in text and "on_J" in text
    assert "on_K" in (out / "generated" / "actions_base.hpp").read_text(encoding="utf-8")


def test_lebt_tree_gets_the_same_skeleton(tmp_path: Path, capsys) -> None:
    tree = _tree(_paper(), tmp_path / "paper_lebt.xml", style="lebt")
    code, _, err = _cli(capsys, "runtime", "cpp", str(tmp_path / "sk"), str(tree))
    assert code == 0, err
    record = json.loads((tmp_path / "sk" / "generated" / "skeleton.json").read_text())
    assert record["form"] == "lebt" and sorted(record["actions"]) == list("ABCDEFGHIJ")
    main_cpp = (tmp_path / "sk" / "main.cpp").read_text(encoding="utf-8")
    assert "Events the tree reacts to: eventAB, eventAC" in main_cpp


def test_python_skeleton_of_a_dispatch_tree_is_refused(tmp_path: Path, capsys) -> None:
    tree = _tree(_paper(), tmp_path / "paper_bt.xml")
    code, _, err = _cli(capsys, "runtime", "python", str(tmp_path / "sk"), str(tree))
    assert code == 2 and "is the leaf of the dispatch form" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "sk").exists()


# -- built and run -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def binary(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    if shutil.which("cmake") is None or not library_built():
        pytest.skip("BehaviorTree.CPP 4.8.2 build or cmake missing (scripts/build_btcpp.sh)")
    root = tmp_path_factory.mktemp("machine_skeleton")
    tree = _tree(_paper(), root / "paper_bt.xml")
    out = root / "sk"
    assert main(["runtime", "cpp", str(out), str(tree)]) in (0, None)
    (out / "actions.hpp").write_text(USER_ACTIONS, encoding="utf-8")
    build = out / "build"
    for command in (
        ["cmake", "-S", str(out), "-B", str(build), f"-DCMAKE_PREFIX_PATH={library_prefix()}"],
        ["cmake", "--build", str(build)],
    ):
        proc = subprocess.run(
            ["nice", "-n", "10", *command], capture_output=True, text=True, timeout=600
        )
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return build / "paper_bt", root


def _expected(machine: FSMMachine, events: list[str]) -> list[str]:
    """What main.cpp prints for ``events``, from fsmbt's FSM interpreter."""
    lines: list[str] = []

    def entered(outputs: tuple[str, ...], state: str) -> None:
        for action in outputs:
            lines.append(
                f"  user D in {state}" if action == "D" else f"  action {action} (entered {state})"
            )

    state, outputs = machine.start()
    entered(tuple(outputs), state)
    lines.append("start: state start")  # the dispatch form names the start "start"
    for event in events:
        state, outputs = machine.step(state, event)
        entered(tuple(outputs), state)
        shown = state if state != machine.start()[0] else "start"
        quiet = "" if outputs else " (nothing entered)"
        done = ", terminated" if machine.status(state) == FINAL else ""
        lines.append(f"event {event}{quiet}: state {shown}{done}")
    return lines


def test_built_skeleton_runs_the_paper_machine_like_the_fsm(binary: tuple[Path, Path]) -> None:
    program, _root = binary
    machine = FSMMachine(_paper())
    for events in event_walks(machine, random.Random(23), runs=15, length=25):
        proc = subprocess.run(
            [str(program)], input="\n".join(events) + "\n", capture_output=True, text=True
        )
        assert proc.returncode == 0, proc.stderr
        assert proc.stdout.splitlines() == _expected(machine, events), events


def test_built_skeleton_refuses_foreign_and_broken_trees(binary: tuple[Path, Path]) -> None:
    program, root = binary
    door = api.load(REPO / "examples" / "door_hfsm.scxml").model
    foreign = _tree(door, root / "door_bt.xml")
    proc = subprocess.run([str(program), "--tree", str(foreign)], capture_output=True, text=True)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.startswith("error: no callback registered for action(s): 'Closed'")
    broken = root / "broken.xml"
    broken.write_text(
        (root / "paper_bt.xml")
        .read_text(encoding="utf-8")
        .replace("fsm_d0:='b'", "fsm_d0:='q'", 1),
        encoding="utf-8",
    )
    proc = subprocess.run([str(program), "--tree", str(broken)], capture_output=True, text=True)
    assert proc.returncode == 1 and proc.stdout == ""
    [line] = proc.stderr.strip().splitlines()
    assert "<DispatchEntry name=" in line and "malformed index digit 'q'" in line, line


def test_docs_show_what_the_built_skeleton_prints(binary: tuple[Path, Path]) -> None:
    """docs/runtime.md, "An event-driven machine": the command and its output (the test's
    binary overrides on_D; the documented one prints every action by default)."""
    program, _root = binary
    docs = (REPO / "docs" / "runtime.md").read_text(encoding="utf-8")
    section = docs[docs.index("## An event-driven machine") :]
    command = next(
        line for line in section.splitlines() if line.startswith("out/paper_cpp/build/paper_bt")
    )
    shown = section[section.index("```text\n") + 8 :]
    shown = shown[: shown.index("```")]
    run = subprocess.run([str(program), *command.split()[1:]], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout == shown.replace("  action D (entered D)", "  user D in D")
