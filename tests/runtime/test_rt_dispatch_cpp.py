"""The dispatch form (docs/semantics.md section 12) in BehaviorTree.CPP 4.8.2 through the
driver's ``--dispatch`` mode: the same actions and termination as the FSM on random walks."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.generate import random_fsm
from fsmbt.runtime.cpp import DriverSession
from fsmbt.semantics.machine import FINAL, FSMMachine
from support.event_walks import event_walks


@pytest.mark.parametrize(("shape", "n"), [("tree", 30), ("chain", 40), ("tree", 8)])
def test_dispatch_runs_like_the_fsm(driver: Path, tmp_path: Path, shape: str, n: int) -> None:
    extra = {"extra_edges": 0} if shape == "chain" else {}
    fsm = random_fsm(f"rt{n}", n, start_event=n == 8, shape=shape, **extra)  # type: ignore[arg-type]
    tree = tmp_path / "dispatch.xml"
    tree.write_text(dumps(convert(fsm, style="dispatch").model, "btcpp"), encoding="utf-8")
    machine = FSMMachine(fsm)
    sequences = event_walks(machine, random.Random(n), runs=5, length=60)
    runs = DriverSession(tree, driver=driver, dispatch=True).run(sequences)
    assert len(runs) == len(sequences)
    for events, run in zip(sequences, runs, strict=True):
        state, outputs = machine.start()
        assert run[0].actions == tuple(outputs)
        for event, got in zip(events, run[1:], strict=True):
            state, outputs = machine.step(state, event)
            assert got.actions == tuple(outputs), event
            assert got.terminated == (machine.status(state) == FINAL)
