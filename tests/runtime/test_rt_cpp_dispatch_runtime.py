"""The C++ runtime (``fsmbt/lebt.hpp``'s ``LebtRunner``) runs the dispatch form (docs/semantics.md
section 12) through the same API as an LEBT, and refuses a hand-broken dispatch tree at load time.

The driver loads each tree WITHOUT ``--dispatch``: ``LebtRunner`` must tell the form from the
leaves. Differential: the C++ run of the written tree, fsmbt's own FSM interpreter
(``FSMMachine``) and python-statemachine (the FSM written as SCXML, ``scxml_oracle.Engine``) get
the same seeded event sequences (mostly events the state handles, some it ignores, one no
machine knows); after the start and every event the C++ run must name the state the other two
are in, run the entry actions ``FSMMachine`` runs, and terminate when they do. Machines: the
paper's A-J machine (``examples/paper_fsm.json``, an initial event), generated ones (four
shapes, with and without an initial event, 8 to 400 states: one to four index digits) and a
seeded batch of 30 FSMs and 10 HFSMs (flattened by the converter).
"""

from __future__ import annotations

import random
import re
import subprocess
from pathlib import Path

import pytest
from scxml_oracle import Engine

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.generate import random_fsm
from fsmbt.model.fsm import FSM
from fsmbt.runtime.cpp import DriverSession
from fsmbt.semantics.machine import FINAL, FSMMachine
from support.event_walks import event_walks

REPO = Path(__file__).resolve().parents[2]


def _write_dispatch(fsm: FSM, tmp_path: Path) -> Path:
    result = convert(fsm)  # the default style: the dispatch form for an event-driven machine
    assert result.stats["style"] == "dispatch", result.stats
    path = tmp_path / f"{fsm.name}_dispatch.xml"
    path.write_text(dumps(result.model, "btcpp"), encoding="utf-8")
    return path


def _differential(fsm: FSM, tmp_path: Path, driver: Path, seed: int, count: int = 6) -> int:
    """Run the three sides; return the number of macro steps compared."""
    tree = _write_dispatch(fsm, tmp_path)
    machine = FSMMachine(fsm)
    start_name = machine.start()[0] if fsm.initial_event is not None else None
    sequences = event_walks(machine, random.Random(seed), count, 40)
    session = DriverSession(tree, driver=driver, start=start_name)
    runs = session.run(sequences)
    scxml = dumps(fsm, "scxml")
    compared = 0
    for events, run in zip(sequences, runs, strict=True):
        engine = Engine(scxml)
        state, outputs = machine.start()
        assert len(run) == len(events) + 1
        for k, got in enumerate(run):
            if k:
                event = events[k - 1]
                state, outputs = machine.step(state, event)
                if event in machine.alphabet and not engine.terminated:
                    engine.send(event)
            where = f"{fsm.name} after {events[:k]}"
            assert got.actions == tuple(outputs), where
            assert got.state == state, where
            assert got.terminated == (machine.status(state) == FINAL), where
            assert engine.configuration() == got.state, where
            assert engine.terminated == got.terminated, where
            compared += 1
    return compared


def test_paper_machine_runs_alike_in_cpp_fsmbt_and_python_statemachine(
    driver: Path, tmp_path: Path
) -> None:
    fsm = api.load(REPO / "examples" / "paper_fsm.json").model
    assert isinstance(fsm, FSM) and fsm.initial_event is not None
    steps = _differential(fsm, tmp_path, driver, seed=7, count=20)
    assert steps == 20 * 41


@pytest.mark.parametrize(
    ("shape", "n", "start_event"),
    [
        ("tree", 8, True),
        ("tree", 30, False),
        ("chain", 60, False),
        ("loop", 12, True),
        ("mixed", 49, False),
        ("tree", 50, True),
        ("chain", 400, False),
    ],
)
def test_generated_machines_run_alike(
    driver: Path, tmp_path: Path, shape: str, n: int, start_event: bool
) -> None:
    extra = {"extra_edges": 0} if shape == "chain" else {}
    fsm = random_fsm(f"g{shape}{n}", n, start_event=start_event, shape=shape, **extra)  # type: ignore[arg-type]
    assert _differential(fsm, tmp_path, driver, seed=n) == 6 * 41


# -- a tree broken by hand is refused at load time, the node named ----------------------------
def _door_dispatch(tmp_path: Path) -> str:
    """The door's flat dispatch form (§12; the hierarchical form's hand edits are
    test_rt_dispatch_hier_check.py's)."""
    fsm = api.load(REPO / "examples" / "door_hfsm.scxml").model
    assert isinstance(fsm, FSM)
    result = convert(fsm, style="dispatch", hierarchy="flatten")
    assert result.stats.get("form") is None, result.stats  # the flat form
    return dumps(result.model, "btcpp")


def _load_error(driver: Path, tmp_path: Path, text: str) -> str:
    path = tmp_path / "broken.xml"
    path.write_text(text, encoding="utf-8")
    proc = subprocess.run(
        [str(driver), str(path)], input="", capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 1 and proc.stdout == "", proc.stdout
    [line] = proc.stderr.strip().splitlines()
    return line


def _line_of(text: str, fragment: str) -> int:
    return 1 + text[: text.index(fragment)].count("\n")


# (what is broken, the edit (old, new) applied once, what the one-line error must say)
BROKEN = [
    (
        "an entry writes an index no state has (lands on the start case)",
        ("fsm_d0:='e'", "fsm_d0:='g'"),
        "writes the state index 'g', which no state has",
    ),
    (
        "a malformed digit in _onSuccess",
        ("fsm_d0:='e'", "fsm_d0:='h'"),
        "malformed index digit 'h'",
    ),
    (
        "a digit the index has not",
        ("fsm_d0:='e'", "fsm_d0:='e'; fsm_d1:='a'"),
        "writes fsm_d1, but no Switch reads that digit",
    ),
    (
        "a key that is no index digit",
        ("fsm_d0:='e'", "fsm_dx:='e'"),
        "'fsm_dx', which is no state index digit",
    ),
    (
        "another script than assignments",
        ("fsm_d0:='e'", "fsm_d0 = fsm_d0"),
        "assigns no quoted literal",
    ),
]


@pytest.mark.parametrize(("what", "edit", "message"), BROKEN, ids=[b[0] for b in BROKEN])
def test_broken_entry_annotation_is_a_load_error_naming_the_leaf(
    driver: Path, tmp_path: Path, what: str, edit: tuple[str, str], message: str
) -> None:
    text = _door_dispatch(tmp_path)
    assert text.count(edit[0]) == 1, what
    broken = text.replace(*edit)
    line = _load_error(driver, tmp_path, broken)
    assert message in line, line
    assert '<DispatchEntry name="Operating/Open">' in line, line
    assert f"line {_line_of(broken, edit[1])}" in line, line


def test_malformed_index_case_is_a_load_error_naming_the_switch(
    driver: Path, tmp_path: Path
) -> None:
    text = _door_dispatch(tmp_path)
    broken = text.replace('case_3="c"', 'case_3="7"', 1)
    line = _load_error(driver, tmp_path, broken)
    assert '<Switch6 name="dispatch">' in line and "line 3" in line, line
    assert "case_3 is the malformed index digit '7'" in line, line


def test_index_of_another_state_is_a_load_error_naming_both(driver: Path, tmp_path: Path) -> None:
    text = _door_dispatch(tmp_path)
    # the first transition into Operating/Closed now writes Emergency's index
    match = re.search(r'<DispatchEntry name="Operating/Closed"[^>]*fsm_d0:=\'a\'', text)
    assert match is not None
    broken = text[: match.start()] + match.group(0).replace("'a'", "'b'") + text[match.end() :]
    line = _load_error(driver, tmp_path, broken)
    assert "it enters 'Operating/Closed' but writes the state index 'b' of 'Emergency'" in line
    assert f"line {_line_of(broken, match.group(0)[:40])}" in line, line


def test_partial_start_index_and_foreign_post_condition_are_refused(
    driver: Path, tmp_path: Path
) -> None:
    fsm = random_fsm("g60", 60, shape="tree", start_event=False)
    text = _write_dispatch(fsm, tmp_path).read_text(encoding="utf-8")
    start = re.search(
        r'(<KeepRunningUntilFailure name="start">\s*<DispatchEntry [^>]*_onSuccess=")([^"]*)"', text
    )
    assert start is not None and ";" in start.group(2)  # 60 states: three digits
    kept = start.group(2).split(";")[0]
    broken = text[: start.start(2)] + kept + text[start.end(2) :]
    line = _load_error(driver, tmp_path, broken)
    assert "from the start, _onSuccess leaves fsm_d" in line and "unset" in line, line
    foreign = re.sub(r"<(Switch\d) ", "<\\1 _onFailure=\"fsm_d0:='a'\" ", text, count=1)
    line = _load_error(driver, tmp_path, foreign)
    assert "only a DispatchEntry carries a post-condition" in line and "line 3" in line, line
    guarded = re.sub(r"<(Switch\d) ", "<\\1 _skipIf=\"fsm_d0=='a'\" ", text, count=1)
    line = _load_error(driver, tmp_path, guarded)
    assert "a pre-condition" in line and "line 3" in line, line


def test_lebt_and_dispatch_leaves_in_one_tree_are_refused(driver: Path, tmp_path: Path) -> None:
    text = _door_dispatch(tmp_path)
    broken = text.replace(
        '<AlwaysSuccess name="Off_final"/>',
        '<LebtState name="Off" state="Off" action="Off" final="true" exits=""/>',
    )
    line = _load_error(driver, tmp_path, broken)
    assert "is an LEBT (LebtGuard/LebtState) or the dispatch form (DispatchEntry), not both" in line


def test_dispatch_flag_refuses_an_lebt(driver: Path, tmp_path: Path) -> None:
    fsm = api.load(REPO / "examples" / "door_hfsm.scxml").model
    path = tmp_path / "door_lebt.xml"
    path.write_text(dumps(convert(fsm, style="lebt").model, "btcpp"), encoding="utf-8")
    proc = subprocess.run(
        [str(driver), str(path), "--dispatch"], input="", capture_output=True, text=True
    )
    assert proc.returncode == 1 and "is an LEBT, not the dispatch form" in proc.stderr


def test_callbacks_get_the_state_label_and_its_parameters(driver: Path, tmp_path: Path) -> None:
    text = _door_dispatch(tmp_path).replace(
        'state="Emergency" action="Emergency"',
        'state="Emergency" action="Emergency" params="speed=0;reason=fire\\;smoke"',
    )
    path = tmp_path / "params.xml"
    path.write_text(text, encoding="utf-8")
    proc = subprocess.run(
        [
            str(driver),
            str(path),
            "--entries",
            "--register",
            "Closed,Closing,Emergency,Off,Open,Opening",
        ],
        input="fire_alarm\nreset\nopen_cmd\n",
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    entered = [line for line in proc.stdout.splitlines() if line.startswith('{"entered"')]
    assert entered == [
        '{"entered":"Operating/Closed","params":{}}',
        '{"entered":"Emergency","params":{"reason":"fire;smoke","speed":"0"}}',
        '{"entered":"Operating/Closed","params":{}}',
        '{"entered":"Operating/Opening","params":{}}',
    ]
    # an action without a callback is the LEBT's load error, naming it and its state
    proc = subprocess.run(
        [str(driver), str(path), "--register", "Closed"], input="", capture_output=True, text=True
    )
    assert proc.returncode == 1
    assert proc.stderr.startswith(
        "error: no callback registered for action(s): 'Closing' (state Operating/Closing), "
        "'Emergency' (state Emergency), "
    ), proc.stderr


def test_dispatch_leaves_without_an_index_are_refused(driver: Path, tmp_path: Path) -> None:
    tree = (
        '<root BTCPP_format="4"><BehaviorTree ID="M">\n<KeepRunningUntilFailure>\n'
        '<DispatchEntry name="A" state="A" action="a"/>\n</KeepRunningUntilFailure>\n'
        "</BehaviorTree></root>"
    )
    line = _load_error(driver, tmp_path, tree)
    assert "no Switch reads a state index digit" in line and "line 3" in line, line


def test_a_seeded_batch_of_machines_and_hierarchical_machines_runs_alike(
    driver: Path, tmp_path: Path
) -> None:
    """30 generated FSMs of every shape (2-80 states, an initial event or not) and 10 generated
    HFSMs (flattened by the converter; states named by their flat paths), 3 sequences each."""
    from support.conv_hfsm_gen import random_hfsm

    rng = random.Random(2026)
    machines: list[FSM] = []
    for k in range(30):
        shape = ("mixed", "chain", "tree", "loop")[k % 4]
        n = rng.randint(2, 80)
        machines.append(random_fsm(f"b{k}", n, shape=shape, start_event=k % 3 == 0))
    machines += [random_hfsm(seed, parallel=False) for seed in range(10)]
    steps = sum(
        _differential(fsm, tmp_path, driver, seed=k, count=3) for k, fsm in enumerate(machines)
    )
    assert steps == len(machines) * 3 * 41
