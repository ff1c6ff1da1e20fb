"""The load-time check of the hierarchical dispatch form (docs/semantics.md §12, "Checked at load
time", and §12a), in both runtimes: fsmbt's Python runtime (``load_tree``, through
``fsmbt.semantics.dispatch_check``) and the C++ runtime (``LebtRunner::checkDispatch``, through
the driver). A tree ``fsmbt convert`` wrote loads in both; each hand edit below - a corrupted
digit of a composite's level (``fsm_d_A_0``), an index no state has inside the composite, two
states on one joint index, a level left unset by the start - is refused by both with the edited
node named and its line.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.runtime.python_runtime import load_tree
from fsmbt.semantics.machine import FSMMachine

# A composite A (children a1, a2, final a3; its own transition `out`) beside an atomic B.
SCXML = """<scxml initial="A" version="1.0" xmlns="http://www.w3.org/2005/07/scxml" name="hc">
  <state id="A" initial="a1">
    <state id="a1"><transition event="next" target="a2"/></state>
    <state id="a2">
      <transition event="next" target="a1"/><transition event="stop" target="a3"/>
    </state>
    <final id="a3"/>
    <transition event="out" target="B"/>
  </state>
  <state id="B"><transition event="in" target="A"/></state>
</scxml>"""

ACTIONS = ("a1", "a2", "a3", "B")

# (what, the written fragment, its replacement (edited once), what the error says in both
# runtimes, the edited element's opening text as the C++ runtime names it)
A1_NEXT = '<DispatchEntry name="A/a2" state="A/a2" action="a2" _onSuccess="fsm_d_A_0:=\'b\'"'
EDITS = [
    (
        "a level digit no Switch case has (the composite's padding default)",
        A1_NEXT,
        A1_NEXT.replace("'b'", "'d'"),
        "_onSuccess writes the state index fsm_d='a', fsm_d_A_='d', which no state has",
        '<DispatchEntry name="A/a2">',
    ),
    (
        "a level index whose case is another state's (the final sub-state a3)",
        A1_NEXT,
        A1_NEXT.replace("'b'", "'c'"),
        "writes the state index fsm_d='a', fsm_d_A_='c', which no state has (the index Switches "
        "lead it to <AlwaysFailure",
        '<DispatchEntry name="A/a2">',
    ),
    (
        "a malformed level digit",
        A1_NEXT,
        A1_NEXT.replace("'b'", "'h'"),
        "writes the malformed index digit 'h'",
        '<DispatchEntry name="A/a2">',
    ),
    (
        "a level digit no Switch reads",
        A1_NEXT,
        A1_NEXT.replace("fsm_d_A_0", "fsm_d_A_1"),
        "writes fsm_d_A_1, but no Switch reads that digit (the level fsm_d_A_.. has 1)",
        '<DispatchEntry name="A/a2">',
    ),
    (
        "a level no Switch reads",
        A1_NEXT,
        A1_NEXT.replace("fsm_d_A_0", "fsm_d_Z_0"),
        "no Switch reads a digit of the level fsm_d_Z_..",
        '<DispatchEntry name="A/a2">',
    ),
    (
        "a key that is no digit entry",
        A1_NEXT,
        A1_NEXT.replace("fsm_d_A_0", "fsm_dA_0"),
        "which is no state index digit",
        '<DispatchEntry name="A/a2">',
    ),
    (
        "a composite's own transition writing another state's joint index",
        "_onSuccess=\"fsm_d0:='b'; fsm_d_A_0:='a'\"",
        "_onSuccess=\"fsm_d0:='a'; fsm_d_A_0:='a'\"",
        "it enters 'B' but writes the state index fsm_d='a', fsm_d_A_='a' of 'A/a1'",
        '<DispatchEntry name="B">',
    ),
    (
        "the start leaving the composite's level unset",
        "_onSuccess=\"fsm_d0:='a'; fsm_d_A_0:='a'\"",
        "_onSuccess=\"fsm_d0:='a'\"",
        "from the start, _onSuccess leaves fsm_d_A_0 unset",
        '<DispatchEntry name="A/a1">',
    ),
    (
        "a malformed case of the level's index Switch",
        '<Switch3 name="A" variable="{fsm_d_A_0}" case_1="a" case_2="b"',
        '<Switch3 name="A" variable="{fsm_d_A_0}" case_1="a" case_2="q"',
        "case_2 is the malformed index digit 'q'",
        '<Switch3 name="A">',
    ),
]


def _tree() -> str:
    fsm = loads(SCXML, "scxml")
    assert isinstance(fsm, FSM)
    result = convert(fsm, style="dispatch")
    assert result.stats.get("form") == "hierarchical", result.warnings
    return dumps(result.model, "btcpp")


def _edited(what: str, old: str, new: str) -> tuple[str, int]:
    """The tree with ``old`` replaced by ``new`` (the last occurrence for the start transition,
    which follows the index switches), and the edited line."""
    text = _tree()
    assert old in text, what
    at = text.rindex(old) if "unset" in what else text.index(old)
    if "own transition" in what:
        at = text.index(old, text.index('name="A/out"'))
    broken = text[:at] + new + text[at + len(old) :]
    return broken, 1 + broken[:at].count("\n")


def _actions() -> dict[str, object]:
    return {name: (lambda state, params: None) for name in ACTIONS}


def test_the_written_tree_loads_in_both_runtimes(driver: Path, tmp_path: Path) -> None:
    """The tree as written (a final sub-state's named ``AlwaysFailure`` included) loads, and
    the C++ runtime then takes the source machine's steps (``FSMMachine``, the reference)."""
    text = _tree()
    assert "fsm_d_A_0" in text and '<AlwaysFailure name="A/a3"/>' in text
    load_tree(text, _actions())
    path = tmp_path / "hier.xml"
    path.write_text(text, encoding="utf-8")
    events = ["next", "stop", "next", "out", "in", "next"]
    proc = subprocess.run(
        [str(driver), str(path), "--dispatch"],
        input="\n".join(events) + "\n",
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    steps = [json.loads(line) for line in proc.stdout.splitlines()]
    fsm = loads(SCXML, "scxml")
    assert isinstance(fsm, FSM)
    machine = FSMMachine(fsm)
    state, outputs = machine.start()
    expected = [list(outputs)]
    for event in events:
        state, outputs = machine.step(state, event)
        expected.append(list(outputs))
    assert [step["actions"] for step in steps] == expected


@pytest.mark.parametrize(
    ("what", "old", "new", "message", "node"), EDITS, ids=[e[0] for e in EDITS]
)
def test_python_runtime_refuses_the_edit_naming_the_node(
    what: str, old: str, new: str, message: str, node: str
) -> None:
    broken, line = _edited(what, old, new)
    with pytest.raises(InputError) as info:
        load_tree(broken, _actions())
    text = str(info.value)
    assert message in text, text
    assert info.value.location is not None and info.value.location.line == line, text


@pytest.mark.parametrize(
    ("what", "old", "new", "message", "node"), EDITS, ids=[e[0] for e in EDITS]
)
def test_cpp_runtime_refuses_the_edit_naming_the_node(
    driver: Path, tmp_path: Path, what: str, old: str, new: str, message: str, node: str
) -> None:
    broken, line = _edited(what, old, new)
    path = tmp_path / "broken.xml"
    path.write_text(broken, encoding="utf-8")
    proc = subprocess.run(
        [str(driver), str(path), "--dispatch"], input="", capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 1 and proc.stdout == "", (proc.stdout, proc.stderr)
    [error] = proc.stderr.strip().splitlines()
    assert message in error, error
    assert node in error and f"line {line})" in error, error
