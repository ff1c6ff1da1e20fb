"""state-machine-cat (.smcat): the reader, the writer, and state-machine-cat itself reading what
fsmbt writes (docs/formats/smcat.md)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats.registry import dumps, loads, read_model
from fsmbt.formats.translate import translate
from fsmbt.generate.generator import random_fsm
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM

REPO = Path(__file__).resolve().parents[2]
SMCAT = REPO / "tools" / "smcat" / "node_modules" / ".bin" / "smcat"

EXAMPLE = """# the door of a lab
initial,
closed: entry/ lock,
"opening door" {
  door.initial,
  moving,
  door_final [type=final];
  door.initial => moving;
  moving => door_final: arrived;
},
open,
final;
initial => closed;
closed => "opening door": button;
"opening door" => open: [in door_final];
open => closed: timeout / beep;
open => final: shutdown;
"""


def _smcat_json(text: str, tmp: Path) -> dict[str, object]:
    """What state-machine-cat itself parses ``text`` into (its JSON AST)."""
    source = tmp / "m.smcat"
    source.write_text(text, encoding="utf-8")
    run = subprocess.run(
        [str(SMCAT), "-I", "smcat", "-T", "json", str(source), "-o", "-"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    data: dict[str, object] = json.loads(run.stdout)
    return data


def test_reads_composite_initial_final_events_and_completion() -> None:
    warnings: list[str] = []
    fsm = loads(EXAMPLE, "smcat", warnings=warnings)
    assert isinstance(fsm, FSM)
    assert fsm.initial == "closed" and fsm.states["closed"].action == "lock"
    assert fsm.states["final"].final
    inner = fsm.states["opening door"].regions[0]
    assert inner.initial == "moving" and inner.states["door_final"].final
    exits = [(t.source, t.event, t.exit, t.target) for t in fsm.transitions if t.event is None]
    assert exits == [("opening door", None, "door_final", "open")]
    beep = [t for t in fsm.transitions if t.event == "timeout"]
    assert beep[0].attrs["smcat.action"] == "beep"
    assert any("its action 'beep' is kept as an annotation" in w for w in warnings)


def test_round_trip_of_random_machines_is_equivalent() -> None:
    for seed in range(25):
        fsm = random_fsm(seed=seed, max_states=10)
        back = loads(dumps(fsm, "smcat"), "smcat")
        assert api.verdict_word(api.verify_models(fsm, back)) == "EQUIVALENT", seed


def test_round_trip_of_a_hierarchical_machine_is_equivalent() -> None:
    fsm = loads(EXAMPLE, "smcat")
    result = translate(fsm, "smcat", check=api.verify_models)
    assert result.verified
    assert result.losses == []  # the transition action and the exit condition are kept


@pytest.mark.skipif(
    not SMCAT.exists(), reason="state-machine-cat not installed (scripts/install_smcat.sh)"
)
def test_state_machine_cat_reads_every_file_fsmbt_writes(tmp_path: Path) -> None:
    models: list[FSM] = [random_fsm(seed=s, max_states=8) for s in range(4)]
    hierarchical = loads(EXAMPLE, "smcat")
    assert isinstance(hierarchical, FSM)
    models.append(hierarchical)
    awkward = FSM(name="awkward")  # names state-machine-cat would misread unless written with care
    awkward.add_state("final_check")
    awkward.add_state("go home", action="drive")
    awkward.add_state("done", final=True, action="report")
    awkward.add_transition("final_check", "ok", "go home")
    awkward.add_transition("go home", "arrived", "done")
    models.append(awkward)
    for model in models:
        text = dumps(model, "smcat")
        ast = _smcat_json(text, tmp_path)
        states = ast["states"]
        assert isinstance(states, list)
        kinds = {s["name"]: s["type"] for s in states}
        for state in model.states.values():
            expected = "final" if state.final else "regular"
            assert kinds[state.name] == expected, (state.name, text)
        assert sum(kind == "initial" for kind in kinds.values()) == 1
        back = loads(text, "smcat")
        assert api.verdict_word(api.verify_models(model, back)) == "EQUIVALENT"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a, b;\na => b: go;\nc;\n", r"3:1: state 'c' is declared after a transition"),
        ("a => b: go\n", r"2:1: expected ';' at the end of a transition"),
        ('a [colour="red"];\n', r"1:4: unknown state attribute 'colour'"),
        ("a { b;\n", r"state 'a' opens '\{' that is never closed"),
        (
            "a, deep.history;\na => deep.history: x;\n",
            r"1: unsupported: state 'deep.history': deep",
        ),
        ("a, ^choice;\na => ^choice: x;\n", r"unsupported: state '\^choice': choice"),
        ("a, b;\na => b: go [ready];\n", r"2: unsupported: .* guards are not in fsmbt"),
        ("a { b; }, c;\nb => c: x;\n", r"2: unsupported: transition b => c crosses machine levels"),
    ],
)
def test_bad_input_is_located(text: str, message: str) -> None:
    with pytest.raises((InputError, UnsupportedError), match=message):
        loads(text, "smcat")


def test_bad_file_is_one_located_line_and_exit_2(tmp_path: Path) -> None:
    bad = tmp_path / "bad.smcat"
    bad.write_text("idle, busy;\nidle => busy: go;\nbusy => idle: [x > 1];\n", encoding="utf-8")
    run = subprocess.run(
        [str(REPO / ".venv" / "bin" / "fsmbt"), "info", str(bad)]
        if (REPO / ".venv" / "bin" / "fsmbt").exists()
        else [shutil.which("fsmbt") or "fsmbt", "info", str(bad)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2
    lines = [line for line in (run.stdout + run.stderr).splitlines() if line.strip()]
    assert len(lines) == 1 and f"{bad}:3" in lines[0], lines


def test_the_extension_selects_the_format(tmp_path: Path) -> None:
    path = tmp_path / "m.smcat"
    path.write_text("a, b;\na => b: go;\n", encoding="utf-8")
    fsm = read_model(path)
    assert isinstance(fsm, FSM) and fsm.name == "m"
    assert [(t.source, t.event, t.target) for t in fsm.transitions] == [("a", "go", "b")]


def test_parallel_state_regions_and_atomic_regions() -> None:
    text = (
        "p [type=parallel] {\n  a,\n  b {\n    b.initial, x, y;\n    b.initial => x;\n"
        "    x => y: go;\n  };\n},\ndone [type=final];\ninitial => p;\np => done: stop;\n"
    )
    fsm = loads(text, "smcat")
    assert isinstance(fsm, FSM)
    regions = fsm.states["p"].regions
    assert [sorted(r.states) for r in regions] == [["a"], ["x", "y"]]
    assert regions[1].initial == "x"
    result = api.convert_model(fsm)
    assert api.verdict_word(api.verify_models(fsm, result.model)) == "EQUIVALENT"
    with pytest.raises(UnsupportedError, match="parallel state 'p'"):
        dumps(fsm, "smcat")
