"""FlexBE reader (static): behaviours, ConcurrencyContainer conditions, embedded behaviours.

Hand-written behaviours in the FlexBE editor's shape; embedded behaviours are separate files
under tmp_path, resolved beside the including file by module name.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import detect_format, loads
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import FSMMachine

HEAD = """\
from flexbe_core import Autonomy, Behavior, ConcurrencyContainer, OperatableStateMachine
from flexbe_core import PriorityContainer
from flexbe_states.log_state import LogState
from flexbe_states.wait_state import WaitState
from my_states.work_state import WorkState as my_states__WorkState
{imports}

class {name}(Behavior):
    def __init__(self, node):
        super().__init__()
        self.name = '{name}'

    def create(self):
"""


def behaviour(body: str, name: str = "DemoSM", imports: str = "") -> str:
    return HEAD.format(name=name, imports=imports) + textwrap.indent(
        textwrap.dedent(body), "        "
    )


def edges(machine: FSM) -> set[tuple[str, str | None, str, str | None]]:
    return {(t.source, t.event, t.target, t.exit) for t in machine.transitions}


def outputs(model: FSM, events: list[str]) -> tuple[list[list[str]], str]:
    machine = FSMMachine(model)
    state, _ = machine.start()
    out = []
    for event in events:
        state, produced = machine.step(state, event)
        out.append(list(produced))
    return out, machine.status(state)


SIMPLE = """
_state_machine = OperatableStateMachine(outcomes=['finished', 'failed'])
with _state_machine:
    OperatableStateMachine.add('Start', LogState(text='hi'),
                               transitions={'done': 'Wait'},
                               autonomy={'done': Autonomy.Off})
    OperatableStateMachine.add('Wait', WaitState(wait_time=1.0),
                               transitions={'done': 'finished'},
                               autonomy={'done': Autonomy.Low})
return _state_machine
"""


def test_behaviour_create_returns_the_model() -> None:
    text = behaviour(SIMPLE)
    assert detect_format(text).name == "flexbe"
    warnings: list[str] = []
    model = loads(text, warnings=warnings)
    assert isinstance(model, FSM) and model.name == "DemoSM"
    assert model.initial == "Start"
    assert model.states["Start"].action == "LogState"
    assert edges(model) == {("Start", "done", "Wait", None), ("Wait", "done", "finished", None)}
    autonomy = {t.source: t.attrs.get("autonomy") for t in model.transitions}
    assert autonomy == {"Start": "Autonomy.Off", "Wait": "Autonomy.Low"}
    assert any("declares outcome 'failed' that no transition reaches" in w for w in warnings)


def test_concurrency_container_first_satisfied_condition_ends_it() -> None:
    text = behaviour("""
        _sm = OperatableStateMachine(outcomes=['finished', 'failed'])
        _cc = ConcurrencyContainer(outcomes=['finished', 'failed'],
                                   conditions=[('finished', [('A', 'done'), ('B', 'done')]),
                                               ('failed', [('A', 'failed')]),
                                               ('failed', [('B', 'failed')])])
        with _cc:
            OperatableStateMachine.add('A', my_states__WorkState(),
                                       transitions={'done': 'finished', 'failed': 'failed'})
            OperatableStateMachine.add('B', my_states__WorkState(),
                                       transitions={'done': 'finished', 'failed': 'failed'})
        with _sm:
            OperatableStateMachine.add('Both', _cc,
                                       transitions={'finished': 'finished', 'failed': 'failed'})
        return _sm
    """)
    model = loads(text)
    inner = model.states["Both"].regions[0]
    assert inner.states["A,B"].action == "WorkState+WorkState"  # the class, not the alias
    # one child failing ends the container at once (the other is stopped)
    assert ("A,B", "A.failed", "failed", None) in edges(inner)
    out, status = outputs(model, ["A.done", "B.done"])
    assert status == "final" and out == [[], []]
    out, status = outputs(model, ["A.done"])
    assert status == "running"


def test_priority_container_is_read_as_a_state_machine() -> None:
    model = loads(
        behaviour("""
        _sm = OperatableStateMachine(outcomes=['finished'])
        _p = PriorityContainer(outcomes=['finished'])
        with _p:
            OperatableStateMachine.add('Log', LogState(text='x'), transitions={'done': 'finished'})
        with _sm:
            OperatableStateMachine.add('Prio', _p, transitions={'finished': 'finished'})
        return _sm
    """)
    )
    assert edges(model.states["Prio"].regions[0]) == {("Log", "done", "finished", None)}


EMBEDDED = """
_sm = OperatableStateMachine(outcomes=['finished', 'failed'])
with _sm:
    OperatableStateMachine.add('Inner', self.use_behavior(InnerSM, 'Inner'),
                               transitions={'finished': 'finished', 'failed': 'failed'},
                               autonomy={'finished': Autonomy.Inherit,
                                         'failed': Autonomy.Inherit})
return _sm
"""


def test_embedded_behaviour_is_read_from_its_file_beside(tmp_path: Path) -> None:
    (tmp_path / "inner_sm.py").write_text(
        behaviour(
            """
        _sm = OperatableStateMachine(outcomes=['finished', 'failed'])
        with _sm:
            OperatableStateMachine.add('Work', my_states__WorkState(),
                                       transitions={'done': 'finished', 'failed': 'failed'})
        return _sm
    """,
            name="InnerSM",
        ),
        encoding="utf-8",
    )
    outer = tmp_path / "outer_sm.py"
    outer.write_text(
        behaviour(EMBEDDED, name="OuterSM", imports="from my_behaviors.inner_sm import InnerSM"),
        encoding="utf-8",
    )
    model = api.load(outer).model
    inner = model.states["Inner"]
    assert inner.attrs["flexbe.behaviour"] == "InnerSM"
    assert edges(inner.regions[0]) == {
        ("Work", "done", "finished", None),
        ("Work", "failed", "failed", None),
    }
    assert ("Inner", None, "failed", "failed") in edges(model)


def test_missing_embedded_behaviour_is_an_opaque_state_or_refused_when_strict(
    tmp_path: Path,
) -> None:
    outer = tmp_path / "outer_sm.py"
    outer.write_text(
        behaviour(EMBEDDED, name="OuterSM", imports="from my_behaviors.inner_sm import InnerSM"),
        encoding="utf-8",
    )
    warnings: list[str] = []
    loaded = api.load(outer)
    model = loaded.model
    warnings.extend(loaded.warnings)
    inner = model.states["Inner"]
    assert inner.is_atomic and inner.action == "InnerSM"
    assert inner.attrs["flexbe.opaque"] == "true"
    # its outcomes are those its transitions name, each leading where the behaviour says
    assert {(t.event, t.target) for t in model.transitions if t.source == "Inner"} == {
        ("finished", "finished"),
        ("failed", "failed"),
    }
    assert any(
        "embedded behaviour 'InnerSM' not found (module my_behaviors.inner_sm" in w
        and "opaque state 'Inner'" in w
        for w in warnings
    )
    with pytest.raises(UnsupportedError, match="my_behaviors.inner_sm") as caught:
        api.load(outer, options={"strict": True})
    assert caught.value.location is not None and caught.value.location.line is not None
    warnings = []
    loads(outer.read_text(encoding="utf-8"), "flexbe", warnings=warnings)
    assert any("read from a text, not a file" in w for w in warnings)


def test_behaviours_embedding_each_other_are_refused(tmp_path: Path) -> None:
    (tmp_path / "a_sm.py").write_text(
        behaviour(
            EMBEDDED.replace("InnerSM", "BSM"), name="ASM", imports="from pkg.b_sm import BSM"
        ),
        encoding="utf-8",
    )
    (tmp_path / "b_sm.py").write_text(
        behaviour(
            EMBEDDED.replace("InnerSM", "ASM"), name="BSM", imports="from pkg.a_sm import ASM"
        ),
        encoding="utf-8",
    )
    with pytest.raises(InputError, match="embeds itself"):
        api.load(tmp_path / "a_sm.py")


def test_create_that_returns_nothing_readable_is_an_error() -> None:
    with pytest.raises(InputError, match="create"):
        loads(behaviour("return make_machine()\n"), "flexbe")


def test_priority_container_inside_a_concurrency_container_is_named() -> None:
    warnings: list[str] = []
    model = loads(
        behaviour("""
        _sm = OperatableStateMachine(outcomes=['finished'])
        _cc = ConcurrencyContainer(outcomes=['finished'],
                                   conditions=[('finished', [('P', 'finished'), ('W', 'done')])])
        with _cc:
            _p = PriorityContainer(outcomes=['finished'])
            with _p:
                OperatableStateMachine.add('Log', LogState(text='x'),
                                           transitions={'done': 'finished'})
            OperatableStateMachine.add('P', _p, transitions={'finished': 'finished'})
            OperatableStateMachine.add('W', WaitState(wait_time=1.0),
                                       transitions={'done': 'finished'})
        with _sm:
            OperatableStateMachine.add('Both', _cc, transitions={'finished': 'finished'})
        return _sm
    """),
        "flexbe",
        warnings=warnings,
    )
    assert any("PriorityContainer 'P' inside a concurrency container" in w for w in warnings)
    out, status = outputs(model, ["P.done", "W.done"])
    assert status == "final"
