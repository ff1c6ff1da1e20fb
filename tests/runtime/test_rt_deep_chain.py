"""A 1 000-state chain converts (``fsmbt convert``, load check on) into a depth-bounded LEBT that
BehaviorTree.CPP 4.8.2 loads and that the C++ runtime ticks to its last state - the paper's
shape nests 2 001 levels there and tinyxml2 refused it (docs/semantics.md §5, "Depth-bounded
LEBT"). The 100 000-state chain's figures are printed by benchmarks/bench_deep_chain.py."""

from __future__ import annotations

from pathlib import Path

from fsmbt import api
from fsmbt.formats import dumps
from fsmbt.runtime.cpp import DriverSession
from support.chains import chain

STATES = 1000


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
