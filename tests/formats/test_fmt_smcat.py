"""state-machine-cat (.smcat): the reader, the writer, and state-machine-cat itself reading what
fsmbt writes (docs/formats/smcat.md)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

from fsmbt import api
from fsmbt.formats.registry import dumps, loads, read_text
from fsmbt.formats.translate import translate
from fsmbt.generate.generator import random_fsm
from fsmbt.model import Model
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM


def read_model(path: Path, warnings: list[str] | None = None) -> Model:
    """Read one file with the reader its content or extension selects (as ``api.load``)."""
    return loads(read_text(path), path=Path(path), warnings=warnings)


REPO = Path(__file__).resolve().parents[2]
SMCAT = REPO / "tools" / "smcat" / "node_modules" / ".bin" / "smcat"
PARSE_ALL = REPO / "tools" / "smcat" / "parse_all.mjs"
#: state-machine-cat is installed (scripts/install_smcat.sh): the tests check every text they write
PARSE_ALL_READY = SMCAT.exists() and shutil.which("node") is not None

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


def state_machine_cat(texts: list[str], tmp: Path) -> list[dict[str, Any]]:
    """state-machine-cat's own parse of each text (one node process: tools/smcat/parse_all.mjs)."""
    paths = []
    for index, text in enumerate(texts):
        path = tmp / f"written{index}.smcat"
        path.write_text(text, encoding="utf-8")
        paths.append(str(path))
    run = subprocess.run(
        ["node", str(PARSE_ALL)],
        input=json.dumps(paths),
        capture_output=True,
        text=True,
        timeout=120,
        cwd=PARSE_ALL.parent,
    )
    assert run.returncode == 0, run.stderr
    results: list[dict[str, Any]] = json.loads(run.stdout)
    return results


def smcat_view(ast: dict[str, Any]) -> tuple[dict[str, str], set[tuple[str, str, str | None]]]:
    """State types and transitions (from, to, event) of state-machine-cat's AST, all levels."""
    kinds: dict[str, str] = {}
    edges: set[tuple[str, str, str | None]] = set()
    stack = [ast]
    while stack:
        machine = stack.pop()
        for state in machine.get("states", []):
            kinds[state["name"]] = state["type"]
            if "statemachine" in state:
                stack.append(state["statemachine"])
        for t in machine.get("transitions", []):
            edges.add((t["from"], t["to"], t.get("event")))
    return kinds, edges


def fsmbt_view(fsm: FSM) -> tuple[dict[str, str], set[tuple[str, str, str | None]]]:
    kinds: dict[str, str] = {}
    edges: set[tuple[str, str, str | None]] = set()
    for machine in fsm.machines():
        for state in machine.states.values():
            kinds[state.name] = "final" if state.final else "regular"
        edges |= {(t.source, t.target, t.event) for t in machine.transitions}
    return kinds, edges


def assert_state_machine_cat_reads_the_same(models: list[FSM], tmp: Path) -> None:
    """Every text fsmbt writes for ``models`` is parsed by state-machine-cat into the same
    states (types) and transitions (the initial pseudo-states aside)."""
    texts = [dumps(model, "smcat") for model in models]
    if not PARSE_ALL_READY:
        return
    for model, text, parsed in zip(models, texts, state_machine_cat(texts, tmp)):
        assert parsed["ok"], (parsed.get("error"), text)
        kinds, edges = smcat_view(parsed["ast"])
        initials = {name for name, kind in kinds.items() if kind == "initial"}
        assert len(initials) == len(list(model.machines())), text
        ours_kinds, ours_edges = fsmbt_view(model)
        assert {n: k for n, k in kinds.items() if n not in initials} == ours_kinds, text
        assert {e for e in edges if e[0] not in initials} == ours_edges, text


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


def test_round_trip_of_random_machines_is_equivalent(tmp_path: Path) -> None:
    models = [random_fsm(seed=seed, max_states=10) for seed in range(25)]
    for seed, fsm in enumerate(models):
        back = loads(dumps(fsm, "smcat"), "smcat")
        assert api.verdict_word(api.verify_models(fsm, back)) == "EQUIVALENT", seed
    assert_state_machine_cat_reads_the_same(models, tmp_path)


def test_round_trip_of_a_hierarchical_machine_is_equivalent(tmp_path: Path) -> None:
    fsm = loads(EXAMPLE, "smcat")
    assert isinstance(fsm, FSM)
    result = translate(fsm, "smcat")
    assert result.checked is not None and result.read_back is not None
    assert api.verdict_word(api.verify_models(result.checked, result.read_back)) == "EQUIVALENT"
    assert result.losses == []  # the transition action and the exit condition are kept
    assert_state_machine_cat_reads_the_same([fsm], tmp_path)


@pytest.mark.skipif(
    not PARSE_ALL_READY, reason="state-machine-cat not installed (scripts/install_smcat.sh)"
)
def test_state_machine_cat_reads_awkward_names_as_fsmbt_means_them(tmp_path: Path) -> None:
    awkward = FSM(name="awkward")  # names state-machine-cat would misread unless written with care
    awkward.add_state("final_check")
    awkward.add_state("go home", action="drive")
    awkward.add_state("initialize", action="boot")
    awkward.add_state("done", final=True, action="report")
    awkward.add_transition("final_check", "ok", "go home")
    awkward.add_transition("go home", "arrived", "initialize")
    awkward.add_transition("initialize", "booted", "done")
    awkward.start_name, awkward.initial_event = "Start", "power"
    assert_state_machine_cat_reads_the_same([awkward], tmp_path)
    # and the smcat command line (what users run) parses it too
    source = tmp_path / "awkward.smcat"
    source.write_text(dumps(awkward, "smcat"), encoding="utf-8")
    run = subprocess.run(
        [str(SMCAT), "-T", "json", str(source), "-o", "-"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    back = loads(source.read_text(encoding="utf-8"), "smcat")
    assert api.verdict_word(api.verify_models(awkward, back)) == "EQUIVALENT"


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
