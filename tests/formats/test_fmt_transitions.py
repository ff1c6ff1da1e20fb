"""pytransitions MarkupMachine configurations: the reader against the real library on random
event sequences (a differential test), the writer, located errors
(docs/formats/transitions.md)."""

from __future__ import annotations

import json
import logging
import random
from typing import Any

import pytest
import yaml

from fsmbt import api
from fsmbt.formats.registry import dumps, loads
from fsmbt.generate.generator import random_fsm
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM

transitions = pytest.importorskip("transitions")
from transitions.extensions import HierarchicalMachine  # noqa: E402

logging.getLogger("transitions").setLevel(logging.ERROR)  # "Can't trigger" is expected here


def random_config(rng: random.Random) -> dict[str, Any]:
    """A configuration as people write them: names and dicts, list and dict transitions,
    ``*`` and list sources, ``=`` destinations, several transitions on one trigger."""
    names = [f"s{i}" for i in range(rng.randint(2, 7))]
    finals = {n for n in names[1:] if rng.random() < 0.2}
    states: list[Any] = [
        {"name": n, "final": True} if n in finals else (n if rng.random() < 0.6 else {"name": n})
        for n in names
    ]
    triggers = [f"t{i}" for i in range(rng.randint(1, 4))]
    live = [n for n in names if n not in finals]
    entries: list[Any] = []
    for _ in range(rng.randint(1, 12)):
        trigger = rng.choice(triggers)
        roll = rng.random()
        source: Any = (
            "*"
            if roll < 0.1
            else rng.sample(live, min(2, len(live)))
            if roll < 0.3
            else rng.choice(live)
        )
        dest = "=" if rng.random() < 0.1 else rng.choice(names)
        if rng.random() < 0.4:
            entries.append([trigger, source, dest])
        else:
            entries.append({"trigger": trigger, "source": source, "dest": dest})
    return {
        "name": "m",
        "states": states,
        "transitions": entries,
        "initial": names[0],
        "auto_transitions": False,
        "ignore_invalid_triggers": True,
    }


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


def without_callbacks(config: dict[str, Any]) -> dict[str, Any]:
    """The configuration without on_enter / on_exit: their names are the user's methods."""
    copy = json.loads(json.dumps(config))
    stack = [copy]
    while stack:
        level = stack.pop()
        for state in level.get("states", level.get("children", [])):
            if isinstance(state, dict):
                state.pop("on_enter", None)
                state.pop("on_exit", None)
                stack.append(state)
    return copy


def run_library(config: dict[str, Any], events: list[str], nested: bool = False) -> list[str]:
    machine_class = HierarchicalMachine if nested else transitions.Machine
    machine = machine_class(**without_callbacks(config))
    seen = [str(machine.state)]
    for event in events:
        if not (nested is False and machine.get_state(machine.state).final):
            machine.trigger(event)
        seen.append(str(machine.state))
    return seen


def test_reader_behaves_like_pytransitions_on_random_configurations() -> None:
    rng = random.Random(2026)
    compared = 0
    for _ in range(120):
        config = random_config(rng)
        text = json.dumps(config) if rng.random() < 0.5 else yaml.safe_dump(config)
        fsm = loads(text, "transitions")
        assert isinstance(fsm, FSM)
        triggers = sorted(
            {e[0] if isinstance(e, list) else e["trigger"] for e in config["transitions"]}
        )
        for _ in range(5):
            events = [rng.choice(triggers) for _ in range(rng.randint(1, 15))]
            assert run_fsmbt(fsm, events) == run_library(config, events), (config, events)
            compared += 1
    assert compared == 600


NESTED = {
    "name": "door",
    "states": [
        "closed",
        {
            "name": "moving",
            "children": ["opening", "paused"],
            "initial": "opening",
            "transitions": [["pause", "opening", "paused"], ["resume", "paused", "opening"]],
        },
        "open",
    ],
    "transitions": [
        {"trigger": "button", "source": "closed", "dest": "moving"},
        {"trigger": "arrived", "source": "moving", "dest": "open"},
        {"trigger": "button", "source": "open", "dest": "closed"},
    ],
    "initial": "closed",
    "auto_transitions": False,
    "ignore_invalid_triggers": True,
}


def test_nested_states_behave_like_the_hierarchical_machine() -> None:
    fsm = loads(json.dumps(NESTED), "transitions")
    assert isinstance(fsm, FSM) and fsm.states["moving"].is_composite
    rng = random.Random(7)
    events = ["button", "pause", "resume", "arrived"]
    for _ in range(50):
        sequence = [rng.choice(events) for _ in range(rng.randint(1, 12))]
        ours = [s.replace("/", "_") for s in run_fsmbt(fsm, sequence)]
        assert ours == run_library(dict(NESTED), sequence, nested=True), sequence


def test_written_configuration_runs_in_pytransitions_as_the_model() -> None:
    rng = random.Random(11)
    for seed in range(20):
        fsm = random_fsm(seed=seed, max_states=9, start_event=False)
        text = dumps(fsm, "transitions")
        config = json.loads(text)
        events = fsm.events()
        for _ in range(4):
            sequence = [rng.choice(events) for _ in range(rng.randint(1, 12))]
            assert run_fsmbt(fsm, sequence) == run_library(config, sequence), seed
        back = loads(text, "transitions")
        assert api.verdict_word(api.verify_models(fsm, back)) == "EQUIVALENT"


@pytest.mark.parametrize(
    ("config", "error", "message"),
    [
        (
            {"states": ["a"], "transitions": [], "initial": "a", "color": 1},
            InputError,
            "unknown key",
        ),
        (
            {
                "states": ["a", "b"],
                "transitions": [{"trigger": "t", "source": "a", "dest": "b", "conditions": "ok"}],
                "initial": "a",
            },
            UnsupportedError,
            r"\$.transitions\[0\]: conditions/unless are guards",
        ),
        (
            {
                "states": ["a"],
                "transitions": [{"trigger": "t", "source": "a", "dest": None}],
                "initial": "a",
            },
            UnsupportedError,
            "internal transition",
        ),
        (
            {
                "states": ["a", {"name": "b", "children": ["c"]}],
                "transitions": [["t", "a", "b_c"]],
                "initial": "a",
            },
            UnsupportedError,
            "not a state of this level",
        ),
        ({"states": ["a"], "transitions": [], "initial": "z"}, InputError, "'z' is not a state"),
    ],
)
def test_bad_configurations_are_named(
    config: dict[str, Any], error: type[Exception], message: str
) -> None:
    with pytest.raises(error, match=message):
        loads(json.dumps(config), "transitions")


def test_missing_initial_is_pytransitions_own_initial_state() -> None:
    warnings: list[str] = []
    fsm = loads(
        json.dumps({"states": ["a"], "transitions": [["go", "initial", "a"]]}),
        "transitions",
        warnings=warnings,
    )
    assert isinstance(fsm, FSM) and fsm.initial == "initial"
    assert any("pytransitions adds the state 'initial'" in w for w in warnings)


@pytest.mark.parametrize("fmt", ["transitions", "yasmin", "pystatemachine"])
def test_content_sniffing_picks_the_new_writers_formats(fmt: str) -> None:
    from fsmbt.formats.registry import detect_format

    fsm = random_fsm(seed=4, max_states=6, start_event=False)
    assert detect_format(dumps(fsm, fmt)).name == fmt
    # and fsmbt's own JSON / YAML are still theirs
    assert detect_format(dumps(fsm, "json")).name == "json"
    assert detect_format(dumps(fsm, "yaml")).name == "yaml"
