"""python-statemachine classes read statically: the reader against the real library on random
event sequences (a differential test), the writer, refusals, nothing executed
(docs/formats/pystatemachine.md)."""

from __future__ import annotations

import random
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats.registry import dumps, loads, read_text
from fsmbt.generate.generator import random_fsm
from fsmbt.model import Model
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM


def read_model(path: Path, warnings: list[str] | None = None) -> Model:
    """Read one file with the reader its content or extension selects (as ``api.load``)."""
    return loads(read_text(path), path=Path(path), warnings=warnings)


statemachine = pytest.importorskip("statemachine")


def random_class(rng: random.Random) -> tuple[str, list[str]]:
    """Source text of a python-statemachine class using every form the reader knows."""
    names = [f"s{i}" for i in range(rng.randint(2, 6))]
    finals = {n for n in names[1:] if rng.random() < 0.2}
    start = rng.choice([n for n in names if n not in finals])
    live = [n for n in names if n not in finals]
    lines = [
        "from statemachine import State, StateMachine",
        "",
        "",
        "class Random(StateMachine):",
        "    allow_event_without_transition = True",
        "    validate_trap_states = False",
        "    validate_final_reachability = False",
        "    validate_disconnected_states = False",
    ]
    for name in names:
        flags = []
        if name == start:
            flags.append("initial=True")
        if name in finals:
            flags.append("final=True")
        lines.append(f"    {name} = State({', '.join(flags)})")
    events = [f"e{i}" for i in range(rng.randint(1, 4))]
    for event in events:
        parts = []
        for _ in range(rng.randint(1, 4)):
            source = rng.choice(live)
            roll = rng.random()
            if roll < 0.15:
                parts.append(f"{source}.to.itself()")
            elif roll < 0.3:
                parts.append(f"{rng.choice(names)}.from_({source})")
            elif roll < 0.4:
                parts.append(f"{source}.to({rng.choice(names)}, {rng.choice(names)})")
            else:
                parts.append(f"{source}.to({rng.choice(names)})")
        lines.append(f"    {event} = {' | '.join(parts)}")
    return "\n".join(lines) + "\n", events


def run_fsmbt(fsm: FSM, events: list[str]) -> list[str]:
    flat = flatten(fsm)
    table = flat.transition_map()
    state = str(flat.initial)
    seen = [state]
    for event in events:
        step = table[state].get(event)
        if step is not None and not flat.states[state].final:
            state = step.target
        seen.append(state)
    return seen


def run_library(source: str, events: list[str]) -> list[str]:
    namespace: dict[str, object] = {}
    exec(compile(source, "<generated>", "exec"), namespace)  # noqa: S102 - the test's own text
    machine_class = next(
        v
        for k, v in namespace.items()
        if isinstance(v, type) and k not in ("State", "StateMachine")
    )
    machine = machine_class()  # type: ignore[operator]
    seen = [next(iter(machine.configuration)).id]
    for event in events:
        machine.send(event)
        seen.append(next(iter(machine.configuration)).id)
    return seen


def test_reader_behaves_like_python_statemachine_on_random_classes(tmp_path: Path) -> None:
    rng = random.Random(2026)
    compared = 0
    for index in range(60):
        source, events = random_class(rng)
        path = tmp_path / f"m{index}.py"
        path.write_text(source, encoding="utf-8")
        fsm = read_model(path)
        assert isinstance(fsm, FSM)
        for _ in range(5):
            sequence = [rng.choice(events) for _ in range(rng.randint(1, 12))]
            assert run_fsmbt(fsm, sequence) == run_library(source, sequence), (source, sequence)
            compared += 1
    assert compared == 300


def test_written_class_runs_in_python_statemachine_as_the_model() -> None:
    rng = random.Random(5)
    for seed in range(15):
        fsm = random_fsm(seed=seed, max_states=8, start_event=False)
        source = dumps(fsm, "pystatemachine")
        for _ in range(4):
            events = fsm.events()
            sequence = [rng.choice(events) for _ in range(rng.randint(1, 12))]
            assert run_fsmbt(fsm, sequence) == run_library(source, sequence), seed
        back = loads(source, "pystatemachine")
        assert api.verdict_word(api.verify_models(fsm, back)) == "EQUIVALENT", seed


HEADER = "from statemachine import State, StateMachine\n\n\nclass M(StateMachine):\n"


@pytest.mark.parametrize(
    ("body", "error", "message"),
    [
        (
            "    a = State(initial=True)\n    b = State()\n    go = a.to(b, cond='ready')\n",
            UnsupportedError,
            r":7: .*cond=: guards",
        ),
        (
            "    a = State(initial=True)\n    go = a.to.itself(internal=True)\n",
            UnsupportedError,
            "internal=True",
        ),
        (
            "    a = State(initial=True)\n    class Inner(State.Compound):\n        x = State()\n",
            UnsupportedError,
            "nested class 'Inner'",
        ),
        (
            "    a = State(initial=True)\n    print('defining')\n",
            InputError,
            r":6: code that runs when the file is imported: print",
        ),
    ],
)
def test_refusals_are_located(body: str, error: type[Exception], message: str) -> None:
    with pytest.raises(error, match=message):
        loads(HEADER + body, "pystatemachine")


def test_code_at_import_is_refused_exit_2_and_never_run(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    path = tmp_path / "machine.py"
    path.write_text(
        "import os\nfrom statemachine import State, StateMachine\n\n"
        f"os.system('touch {marker}')\n\n\n"
        "class M(StateMachine):\n    a = State(initial=True)\n    b = State()\n    go = a.to(b)\n",
        encoding="utf-8",
    )
    run = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "info", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2
    lines = [line for line in (run.stdout + run.stderr).splitlines() if line.strip()]
    assert len(lines) == 1 and f"{path}:4" in lines[0], lines
    assert not marker.exists()


def test_eventless_transition_is_a_completion_transition() -> None:
    fsm = loads(
        HEADER + "    a = State(initial=True)\n    b = State()\n    c = State(final=True)\n"
        "    a.to(b)\n    go = b.to(c)\n",
        "pystatemachine",
    )
    assert isinstance(fsm, FSM)
    assert [(t.source, t.event, t.target) for t in fsm.transitions] == [
        ("a", None, "b"),
        ("b", "go", "c"),
    ]
    assert run_fsmbt(fsm, ["go"]) == ["b", "c"]


def test_entry_callback_is_the_action_and_is_written_back() -> None:
    fsm = loads(
        HEADER + "    a = State(initial=True, enter='beep')\n    b = State()\n    go = a.to(b)\n",
        "pystatemachine",
    )
    assert isinstance(fsm, FSM) and fsm.states["a"].action == "beep"
    assert fsm.states["b"].action == "b"
    text = dumps(fsm, "pystatemachine")
    assert "enter='beep'" in text
    assert api.verdict_word(api.verify_models(fsm, loads(text, "pystatemachine"))) == "EQUIVALENT"
