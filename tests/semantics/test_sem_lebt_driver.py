"""The one LEBT macro-step driver (``fsmbt.semantics.lebt.driver``) against scripted tick
functions: the second-tick rule, the dropped event, the start tick and termination as
docs/semantics.md §5 states them, independent of any tree. The runtimes that plug real tick
functions in are compared with each other and with the FSM in test_sem_lebt_fast.py and
test_sem_lebt_engines.py."""

from __future__ import annotations

from typing import NamedTuple

import pytest

from fsmbt.semantics.lebt.driver import MacroStepDriver
from fsmbt.semantics.lebt.leaves import LebtBlackboard, LebtLeaves, PlainBlackboard
from fsmbt.semantics.lebt.spec import NO_EVENT
from fsmbt.semantics.status import NodeStatus

START = "__start__"


class ScriptState(NamedTuple):
    memory: int  # how many ticks ran so far
    bb_state: str
    last_result: NodeStatus | None


class ScriptedTick:
    """Returns the scripted statuses in turn; each tick may consume the event or move on."""

    def __init__(self, script: list[tuple[NodeStatus, bool, str | None]]) -> None:
        self.script = list(script)  # (status, consume the event, new bb.state or None)
        self.seen: list[tuple[int, str, str]] = []  # (memory, state, event) at each tick

    def __call__(
        self, memory: int, bb: LebtBlackboard, actions: list[str]
    ) -> tuple[int, NodeStatus]:
        self.seen.append((memory, bb.state, bb.event))
        status, consume, new_state = self.script.pop(0)
        if new_state is not None:
            bb.state = new_state
            actions.append(f"enter {new_state}")
        if consume:
            bb.event = NO_EVENT
        return memory + 1, status


def driver(
    script: list[tuple[NodeStatus, bool, str | None]],
    *,
    init: bool = False,
    blackboard: PlainBlackboard | None = None,
) -> tuple[MacroStepDriver[int, ScriptState], ScriptedTick]:
    tick = ScriptedTick(script)
    leaves = LebtLeaves({}, {}, START, init)
    if blackboard is None:
        return MacroStepDriver(leaves, tick, 0, ScriptState), tick
    persistent = blackboard

    def same_blackboard(state: str, event: str) -> LebtBlackboard:
        persistent.state, persistent.event = state, event
        return persistent

    return MacroStepDriver(leaves, tick, 0, ScriptState, same_blackboard), tick


def test_sem_lebt_driver_start_ticks_only_with_the_initialisation_pair() -> None:
    quiet, quiet_tick = driver([])
    assert quiet.initial() == (ScriptState(0, START, None), ())
    assert quiet_tick.seen == []
    eager, eager_tick = driver([(NodeStatus.RUNNING, False, "A")], init=True)
    state, out = eager.initial()
    assert eager_tick.seen == [(0, START, NO_EVENT)]
    assert (state, out) == (ScriptState(1, "A", NodeStatus.RUNNING), ("enter A",))


def test_sem_lebt_driver_ticks_twice_only_on_success_with_the_event_pending() -> None:
    # SUCCESS, event still pending: the second tick runs with the same event
    run, tick = driver([(NodeStatus.SUCCESS, False, None), (NodeStatus.RUNNING, True, "B")])
    state, out = run.macro_step(ScriptState(5, "A", NodeStatus.RUNNING), "go")
    assert tick.seen == [(5, "A", "go"), (6, "A", "go")]
    assert (state, out) == (ScriptState(7, "B", NodeStatus.RUNNING), ("enter B",))
    # SUCCESS with the event consumed, or RUNNING with it pending: one tick
    for first in [(NodeStatus.SUCCESS, True, None), (NodeStatus.RUNNING, False, None)]:
        run, tick = driver([first])
        state, _ = run.macro_step(ScriptState(0, "A", None), "go")
        assert len(tick.seen) == 1 and state.memory == 1 and state.last_result == first[0]


def test_sem_lebt_driver_never_ticks_a_third_time() -> None:
    run, tick = driver(
        [
            (NodeStatus.SUCCESS, False, None),
            (NodeStatus.SUCCESS, False, None),
            (NodeStatus.SUCCESS, False, None),
        ]
    )
    state, _ = run.macro_step(ScriptState(0, "A", None), "go")
    assert len(tick.seen) == 2 and state == ScriptState(2, "A", NodeStatus.SUCCESS)


@pytest.mark.parametrize("status", [NodeStatus.SUCCESS, NodeStatus.RUNNING])
def test_sem_lebt_driver_drops_an_event_still_pending(status: NodeStatus) -> None:
    bb = PlainBlackboard(START)
    run, tick = driver([(status, False, None)] * 2, blackboard=bb)
    run.macro_step(ScriptState(0, "A", None), "ignored")
    assert bb.event == NO_EVENT and bb.state == "A"
    assert {event for _, _, event in tick.seen} == {"ignored"}


def test_sem_lebt_driver_terminates_on_success_once_the_start_is_left() -> None:
    run, _ = driver([])
    assert run.terminated(ScriptState(0, "Done", NodeStatus.SUCCESS))
    assert not run.terminated(ScriptState(0, START, NodeStatus.SUCCESS))  # no guard fired
    assert not run.terminated(ScriptState(0, "A", NodeStatus.RUNNING))
    assert not run.terminated(ScriptState(0, "A", None))
