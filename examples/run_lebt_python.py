"""Convert the paper's FSM (examples/paper_fsm.xml) to its behavior tree and run the tree with
your own Python actions, on py_trees and on BehaviorTree.CPP (behaviortreepy).

Run from the repository root:  .venv/bin/python examples/run_lebt_python.py
Each state's action prints a line; the FSM's own runner is printed next to both engines, so the
three columns must agree (docs/runtime-python.md).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from fsmbt import api
from fsmbt.convert.engines import converter_for
from fsmbt.formats import dumps
from fsmbt.runtime.python_runtime import ENGINES, load_tree
from fsmbt.semantics.machine import FSMMachine

HERE = Path(__file__).resolve().parent
EVENTS = [
    "eventSA",
    "eventAB",
    "eventBD",
    "eventDE",
    "eventEC",
    "eventCD",
    "eventXX",
    "eventDE",
    "eventEG",
    "eventGH",
]


def main() -> None:
    fsm = api.load(HERE / "paper_fsm.xml").model
    lebt = converter_for("rules", fsm)(fsm, style="lebt").model  # = fsmbt convert --style lebt
    tree_xml = dumps(lebt, "btcpp")

    machine = FSMMachine(fsm)
    state, _ = machine.start()
    expected = []
    for event in EVENTS:
        state, outputs = machine.step(state, event)
        expected.append(outputs)

    log: list[str] = []  # the actions run in one macro step

    def action(name: str) -> Callable[[], None]:
        def run() -> None:  # your robot's code goes here
            log.append(name)
            print(f"   running action {name}")

        return run

    actions = {name: action(name) for name in "ABCDEFGHIJ"}
    for engine in ENGINES:
        print(f"== {engine}")
        runner = load_tree(tree_xml, actions, engine=engine)
        runner.start()
        for event, fsm_outputs in zip(EVENTS, expected):
            log.clear()
            print(f"-> {event}")
            runner.post(event)
            print(
                f"   state {runner.state}, terminated {runner.terminated}; "
                f"FSM runs {list(fsm_outputs)}"
            )
            assert tuple(log) == fsm_outputs, (engine, event, log, fsm_outputs)
        assert runner.terminated
    print("both engines ran the FSM's actions")


if __name__ == "__main__":
    main()
