"""Differential test of the LEBT runtimes (issue 11): the FSM's own macro-step runner
(``FSMMachine``), the C++ runtime (``fsmbt/lebt.hpp`` in BehaviorTree.CPP 4.8.2, through the
driver), behaviortreepy (BehaviorTree.CPP through Python) and py_trees on the same event
sequences - plus the C++ runtime forced to ``tickOnce`` (its default ticks exactly once when no
node can emit a wake-up, docs/runtime.md) and the driver's plain transition table (the
benchmark's baseline).

Models: every example in examples/ that is an FSM, every corpus model (``FSMBT_CORPUS``) that is
an FSM converting to a BT, 200 generated FSMs (``fsmbt.generate.random_fsm``) and 150 generated
HFSMs (``conv_hfsm_gen.random_hfsm``; a third with parallel states). Each: the converted tree is
written as BehaviorTree.CPP XML and every runtime loads that file's text; 20 seeded random
sequences of 20 events over the FSM's alphabet plus one unknown event. After the start and after
every event all runtimes must report the same actions (in order) and the same termination.
Zero differences. The C++ runs use one driver process per model for all 20 sequences. Counts
and the C++ build and run times are printed (``pytest -s``).
"""

from __future__ import annotations

import os
import random
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.generate import random_fsm
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.runtime.cpp import DriverSession, library_prefix
from fsmbt.semantics.engines.btcpp_engine import BTCppLebtRunner
from fsmbt.semantics.engines.pytrees_engine import PyTreesLebtRunner
from fsmbt.semantics.machine import FINAL, FSMMachine
from support.conv_hfsm_gen import random_hfsm
from support.corpus import CORPUS

REPO = Path(__file__).resolve().parents[2]
SEQUENCES = 20
LENGTH = 20
GENERATED_FSMS = 200
GENERATED_HFSMS = 150
UNKNOWN_EVENT = "__no_such_event__"

#: One observation: the actions run and whether the run is terminated.
Observation = tuple[tuple[str, ...], bool]


@dataclass
class Tally:
    models: int = 0
    sequences: int = 0
    steps: int = 0
    refused: list[str] = field(default_factory=list)
    differences: list[str] = field(default_factory=list)
    cpp_seconds: float = 0.0

    def report(self, group: str) -> str:
        return (
            f"\n[runtime differential] {group}: {self.models} models, {self.sequences} "
            f"sequences, {self.steps} macro steps compared in 6 runs (FSM, C++ "
            f"BehaviorTree.CPP (auto tick, tickOnce), C++ table, behaviortreepy, py_trees); "
            f"C++ driver time (auto tick) "
            f"{self.cpp_seconds:.2f} s; refused by the converter: {len(self.refused)}; "
            f"differences: {len(self.differences)}"
        )


def _sequences(alphabet: tuple[str, ...], seed: str) -> list[list[str]]:
    rng = random.Random(seed)
    return [[rng.choice(alphabet) for _ in range(LENGTH)] for _ in range(SEQUENCES)]


def _fsm_runs(machine: FSMMachine, sequences: list[list[str]]) -> list[list[Observation]]:
    runs = []
    for events in sequences:
        state, out = machine.start()
        run = [(tuple(out), machine.status(state) == FINAL)]
        for event in events:
            state, out = machine.step(state, event)
            run.append((tuple(out), machine.status(state) == FINAL))
        runs.append(run)
    return runs


def _engine_runs(make, sequences: list[list[str]]) -> list[list[Observation]]:
    runs = []
    for events in sequences:
        runner = make()
        run = [(runner.initial(), runner.terminated)]
        for event in events:
            run.append((runner.macro_step(event), runner.terminated))
        runs.append(run)
    return runs


def _compare(label: str, fsm: FSM, tmp: Path, driver: Path, tally: Tally) -> None:
    """Convert ``fsm``, run every runtime on the same sequences, record differences."""
    try:
        result = convert(fsm, style="lebt")  # the LEBT runtimes run LEBTs (SMACH: not structured)
    except InputError as exc:  # UnsupportedError included: e.g. an eventless cycle
        tally.refused.append(f"{label}: {exc}")
        return
    text = dumps(result.model, "btcpp")
    tree_file = tmp / f"{len(os.listdir(tmp))}.xml"
    tree_file.write_text(text, encoding="utf-8")
    doc = loads(text, "btcpp")  # every runtime runs the written file
    machine = FSMMachine(fsm)
    alphabet = tuple(machine.alphabet) + (UNKNOWN_EVENT,)
    sequences = _sequences(alphabet, label)
    expected = _fsm_runs(machine, sequences)
    started = time.perf_counter()
    cpp = DriverSession(tree_file, driver=driver).run(sequences)
    tally.cpp_seconds += time.perf_counter() - started
    literal = DriverSession(tree_file, driver=driver, tick="once").run(sequences)
    table = DriverSession(tree_file, driver=driver, table=True).run(sequences)
    observed = {
        "C++ BehaviorTree.CPP": [[(s.actions, s.terminated) for s in run] for run in cpp],
        "C++ BehaviorTree.CPP tickOnce": [
            [(s.actions, s.terminated) for s in run] for run in literal
        ],
        "C++ table": [[(s.actions, s.terminated) for s in run] for run in table],
        "behaviortreepy": _engine_runs(lambda: BTCppLebtRunner(doc), sequences),
        "py_trees": _engine_runs(lambda: PyTreesLebtRunner(doc), sequences),
    }
    for runtime, runs in observed.items():
        for index, (want, got) in enumerate(zip(expected, runs)):
            if want != got:
                step = next(
                    (i for i, (w, g) in enumerate(zip(want, got)) if w != g),
                    min(len(want), len(got)),
                )
                event = "start" if step == 0 else sequences[index][step - 1]
                tally.differences.append(
                    f"{label} [{runtime}] sequence {index} step {step} ({event}): FSM "
                    f"{want[step] if step < len(want) else None} vs "
                    f"{got[step] if step < len(got) else None}"
                )
    tally.models += 1
    tally.sequences += SEQUENCES
    tally.steps += SEQUENCES * LENGTH


def _example_fsms() -> list[tuple[str, FSM]]:
    found = []
    for path in sorted((REPO / "examples").iterdir()):
        try:
            model = api.load(path).model
        except InputError:
            continue
        if isinstance(model, FSM):
            found.append((f"examples/{path.name}", model))
    return found


def _corpus_fsms() -> list[tuple[str, FSM]]:
    if not CORPUS.is_dir():
        return []
    found = []
    for path in sorted(CORPUS.rglob("*")):
        if (
            not path.is_file()
            or path.suffix in (".md", ".txt")
            or "_malformed" in path.parts
            or "LICENSES" in path.parts
        ):
            continue
        try:
            model = api.load(path).model
        except InputError:
            continue
        if isinstance(model, FSM):
            found.append((f"corpus/{path.relative_to(CORPUS)}", model))
    return found


def _build_times() -> str:
    record = library_prefix() / "build_times.txt"
    if not record.is_file():
        return "C++ build times: not recorded"
    return "C++ build times (scripts/build_btcpp.sh, this machine): " + ", ".join(
        record.read_text(encoding="utf-8").split()
    )


def test_rt_examples_and_corpus_run_alike_everywhere(driver: Path, tmp_path: Path) -> None:
    examples, corpus = _example_fsms(), _corpus_fsms()
    assert len(examples) >= 4  # paper XML/JSON, turnstile, NPC table, door HFSM
    tally = Tally()
    for label, fsm in examples + corpus:
        _compare(label, fsm, tmp_path, driver, tally)
    print(tally.report(f"{len(examples)} examples + {len(corpus)} corpus FSMs"))
    print(_build_times())
    assert tally.differences == []
    assert tally.refused == []  # every example and corpus FSM converts
    assert tally.models == len(examples) + len(corpus)


def test_rt_generated_fsms_run_alike_everywhere(driver: Path, tmp_path: Path) -> None:
    tally = Tally()
    for seed in range(GENERATED_FSMS):
        fsm = random_fsm(
            f"runtime-{seed}",
            scenario="basic" if seed % 2 else "robot",
            shape=("mixed", "chain", "tree", "loop")[seed % 4],
        )
        _compare(f"random_fsm(runtime-{seed})", fsm, tmp_path, driver, tally)
    print(tally.report("generated FSMs"))
    assert tally.differences == []
    assert tally.refused == []
    assert tally.models == GENERATED_FSMS


@pytest.mark.parametrize("parallel", [False, True])
def test_rt_generated_hfsms_run_alike_everywhere(
    driver: Path, tmp_path: Path, parallel: bool
) -> None:
    count = GENERATED_HFSMS * 2 // 3 if not parallel else GENERATED_HFSMS // 3
    tally = Tally()
    seed = 0
    while tally.models < count:
        fsm = random_hfsm(10_000 + seed, parallel=parallel)
        _compare(f"random_hfsm({10_000 + seed}, parallel={parallel})", fsm, tmp_path, driver, tally)
        seed += 1
        assert seed < 3 * count, "too many generated HFSMs refused"
    print(tally.report(f"generated HFSMs (parallel={parallel})"))
    assert tally.differences == []
    # the converter refuses e.g. cycles of completion transitions, clearly
    assert all("eventless" in reason or "completion" in reason for reason in tally.refused), (
        tally.refused[:3]
    )
    assert tally.models == count
