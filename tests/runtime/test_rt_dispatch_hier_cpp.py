"""The hierarchical dispatch form (docs/semantics.md §12a) ticked in BehaviorTree.CPP 4.8.2
through the driver's ``--dispatch`` mode: the same actions and termination as the source
machine (flattened by ``FSMMachine``, the reference) on seeded event sequences, for seeded
generated hierarchical machines and the corpus' hierarchical SCXML files."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.generate.hierarchical import random_hfsm
from fsmbt.model.fsm import FSM
from fsmbt.runtime.cpp import DriverSession
from fsmbt.semantics.machine import FINAL, FSMMachine
from support.corpus import CORPUS
from support.event_walks import event_walks

KEPT = (
    "fsm/commons_scxml/state-01.scxml",
    "fsm/scion_tests/hierarchy__hier0.scxml",
    "fsm/scion_tests/hierarchy__hier1.scxml",
    "fsm/scion_tests/hierarchy_documentOrder__test0.scxml",
)


def _runs_like_the_source(fsm: FSM, driver: Path, tmp_path: Path, seed: int) -> None:
    result = convert(fsm, style="dispatch")
    assert result.stats.get("form") == "hierarchical", result.warnings
    tree = tmp_path / "hier_dispatch.xml"
    tree.write_text(dumps(result.model, "btcpp"), encoding="utf-8")
    machine = FSMMachine(fsm)
    sequences = event_walks(machine, random.Random(seed), runs=6, length=50)
    runs = DriverSession(tree, driver=driver, dispatch=True).run(sequences)
    assert len(runs) == len(sequences)
    for events, run in zip(sequences, runs, strict=True):
        state, outputs = machine.start()
        assert run[0].actions == tuple(outputs)
        for event, got in zip(events, run[1:], strict=True):
            state, outputs = machine.step(state, event)
            assert got.actions == tuple(outputs), event
            assert got.terminated == (machine.status(state) == FINAL), event


@pytest.mark.parametrize("seed", range(8))
def test_generated_hierarchical_machines_run_like_their_source(
    driver: Path, tmp_path: Path, seed: int
) -> None:
    _runs_like_the_source(random_hfsm(seed, 24), driver, tmp_path, seed)


@pytest.mark.parametrize("name", KEPT)
def test_corpus_hierarchical_scxml_runs_like_its_source(
    driver: Path, tmp_path: Path, name: str
) -> None:
    path = CORPUS / name
    if not path.exists():
        pytest.skip(f"corpus file {name} not here (FSMBT_CORPUS)")
    fsm = api.load(path).model
    assert isinstance(fsm, FSM)
    _runs_like_the_source(fsm, driver, tmp_path, len(name))
