"""A 1 000-state chain converts (``fsmbt convert``, load check on) into a depth-bounded LEBT that
BehaviorTree.CPP 4.8.2 loads and that the C++ runtime ticks to its last state - the paper's
shape nests 2 001 levels there and tinyxml2 refused it (docs/semantics.md §5, "Depth-bounded
LEBT"). The 100 000-state chain's figures are printed by benchmarks/bench_deep_chain.py."""

from __future__ import annotations

from pathlib import Path

from fsmbt import api
from fsmbt.formats import dumps
from fsmbt.model.fsm import FSM
from fsmbt.runtime.cpp import DriverSession

STATES = 1000


def chain(n: int) -> FSM:
    fsm = FSM(name="chain")
    for i in range(n):
        fsm.add_state(f"S{i}", action=f"a{i}", final=i == n - 1)
    fsm.initial = "S0"
    for i in range(n - 1):
        fsm.add_transition(f"S{i}", "next", f"S{i + 1}")
    return fsm


def test_a_1000_state_chain_loads_in_btcpp_and_ticks_to_its_last_state(
    tmp_path: Path, driver: Path
) -> None:
    source = tmp_path / "chain.scxml"
    source.write_text(dumps(chain(STATES), "scxml"), encoding="utf-8")
    tree = tmp_path / "chain.xml"
    outcome = api.convert_file(source, tree, style="lebt")
    assert outcome.equivalent and outcome.written
    assert outcome.load is not None and outcome.load.summary() == (
        "loads in BehaviorTree.CPP 4.8.2: yes"
    )
    [run] = DriverSession(tree, driver=driver).run([["next"] * (STATES - 1)])
    assert [step.state for step in run] == [f"S{i}" for i in range(STATES)]
    assert [step.actions for step in run] == [(f"a{i}",) for i in range(STATES)]
    assert [step.terminated for step in run] == [False] * (STATES - 1) + [True]
