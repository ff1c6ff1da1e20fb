"""SMACH reader (static, never executed): each construct, each refusal, hostile inputs.

Sources are written here by hand; each test asserts the model (states, transitions, actions)
or the located error. Behaviour is checked on the flattened machine with ``FSMMachine`` where
the construct is about behaviour (Concurrence outcome maps, Iterator unrolling).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import detect_format, loads
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import FSMMachine

HEAD = """\
import smach
import smach_ros


class Foo(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=['outcome1', 'outcome2'])

    def execute(self, userdata):
        return 'outcome1'


class Bar(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=['outcome1'])
"""


def smach(body: str, head: str = HEAD) -> str:
    return head + "\n\ndef main():\n" + textwrap.indent(textwrap.dedent(body), "    ")


def read(text: str, **options: object) -> tuple[FSM, list[str]]:
    warnings: list[str] = []
    model = loads(text, "smach", options=options, warnings=warnings)
    assert isinstance(model, FSM)
    return model, warnings


def edges(machine: FSM) -> set[tuple[str, str | None, str, str | None]]:
    return {(t.source, t.event, t.target, t.exit) for t in machine.transitions}


class Runner:
    """Steps the flattened macro-step machine (docs/semantics.md §6) one event at a time."""

    def __init__(self, model: FSM) -> None:
        self.machine = FSMMachine(model)
        self.state, self.started = self.machine.start()

    def step(self, event: str) -> list[str]:
        self.state, outputs = self.machine.step(self.state, event)
        return list(outputs)

    @property
    def status(self) -> str:
        return self.machine.status(self.state)


def run(model: FSM, events: list[str]) -> list[str]:
    """Actions output along ``events`` (one entry per event; '' = nothing ran)."""
    runner = Runner(model)
    return ["+".join(runner.step(event)) for event in events]


# -- constructs -------------------------------------------------------------------------------
def test_state_machine_positional_and_keyword_transitions() -> None:
    model, warnings = read(
        smach("""
        sm = smach.StateMachine(outcomes=['outcome4', 'outcome5'])
        with sm:
            smach.StateMachine.add('FOO', Foo(), {'outcome1': 'BAR', 'outcome2': 'outcome4'})
            smach.StateMachine.add(label='BAR', state=Bar(), transitions={'outcome1': 'FOO'})
        sm.execute()
    """)
    )
    assert model.name == "sm"
    assert model.initial == "FOO"
    assert [s.name for s in model.states.values()] == ["FOO", "BAR", "outcome4", "outcome5"]
    assert model.states["FOO"].action == "Foo" and model.states["BAR"].action == "Bar"
    assert model.states["outcome4"].final and model.states["outcome5"].final
    assert edges(model) == {
        ("FOO", "outcome1", "BAR", None),
        ("FOO", "outcome2", "outcome4", None),
        ("BAR", "outcome1", "FOO", None),
    }
    assert any("declares outcome 'outcome5' that no transition reaches" in w for w in warnings)
    assert detect_format(smach("sm = smach.StateMachine(outcomes=['a'])")).name == "smach"


def test_set_initial_state_overrides_the_first_added() -> None:
    model, _ = read(
        smach("""
        sm = smach.StateMachine(['done'])
        with sm:
            smach.StateMachine.add('FOO', Foo(), {'outcome1': 'done', 'outcome2': 'BAR'})
            smach.StateMachine.add('BAR', Bar(), {'outcome1': 'FOO'})
        sm.set_initial_state(['BAR'])
    """)
    )
    assert model.initial == "BAR"


def test_nested_state_machine_is_a_composite_with_completion_transitions() -> None:
    model, _ = read(
        smach("""
        top = smach.StateMachine(outcomes=['end'])
        with top:
            smach.StateMachine.add('BAR', Bar(), transitions={'outcome1': 'SUB'})
            sub = smach.StateMachine(outcomes=['ok', 'bad'])
            with sub:
                smach.StateMachine.add('FOO', Foo(), {'outcome1': 'ok', 'outcome2': 'bad'})
            smach.StateMachine.add('SUB', sub, transitions={'ok': 'end', 'bad': 'BAR'})
    """)
    )
    composite = model.states["SUB"]
    assert composite.is_composite and composite.action is None
    assert edges(composite.regions[0]) == {
        ("FOO", "outcome1", "ok", None),
        ("FOO", "outcome2", "bad", None),
    }
    assert edges(model) == {
        ("BAR", "outcome1", "SUB", None),
        ("SUB", None, "end", "ok"),
        ("SUB", None, "BAR", "bad"),
    }
    assert run(model, ["outcome1", "outcome2", "outcome1", "outcome1"]) == ["Foo", "Bar", "Foo", ""]


def test_sequence_links_the_connector_outcome_to_the_next_state() -> None:
    model, _ = read(
        smach("""
        sq = smach.Sequence(outcomes=['outcome1', 'outcome2'], connector_outcome='outcome1')
        with sq:
            smach.Sequence.add('A', Foo())
            smach.Sequence.add('B', Foo(), transitions={'outcome1': 'A'})
            smach.Sequence.add('C', Bar())
    """)
    )
    assert edges(model) == {
        ("A", "outcome1", "B", None),
        ("A", "outcome2", "outcome2", None),
        ("B", "outcome1", "A", None),
        ("B", "outcome2", "outcome2", None),
        ("C", "outcome1", "outcome1", None),
    }


def test_add_auto_connects_to_the_next_added_state() -> None:
    model, _ = read(
        smach("""
        sm = smach.StateMachine(outcomes=['outcome2', 'end'])
        with sm:
            smach.StateMachine.add_auto('A', Foo(), ['outcome1'])
            smach.StateMachine.add_auto('B', Foo(), connector_outcomes=['outcome1'],
                                        transitions={'outcome1': 'end'})
            smach.StateMachine.add('C', Bar(), {'outcome1': 'end'})
    """)
    )
    assert ("A", "outcome1", "B", None) in edges(model)
    assert ("B", "outcome1", "C", None) in edges(model)  # SMACH's code overrides the mapping


def test_unmapped_outcome_falls_through_to_the_container_outcome_of_that_name() -> None:
    model, _ = read(
        smach("""
        sm = smach.StateMachine(outcomes=['outcome2', 'done'])
        with sm:
            smach.StateMachine.add('A', Foo(), {'outcome1': 'done'})
    """)
    )
    assert ("A", "outcome2", "outcome2", None) in edges(model)


def test_concurrence_is_the_product_of_its_children_with_the_outcome_map() -> None:
    model, _ = read(
        smach("""
        top = smach.StateMachine(outcomes=['outcome6'])
        with top:
            cc = smach.Concurrence(outcomes=['outcome4', 'outcome5'], default_outcome='outcome4',
                                   outcome_map={'outcome5': {'FOO': 'outcome2', 'BAR': 'outcome1'}})
            with cc:
                smach.Concurrence.add('FOO', Foo())
                smach.Concurrence.add('BAR', Bar())
            smach.StateMachine.add('CON', cc, transitions={'outcome4': 'CON',
                                                           'outcome5': 'outcome6'})
    """)
    )
    con = model.states["CON"]
    assert con.attrs["smach.container"] == "Concurrence"
    inner = con.regions[0]
    assert inner.initial == "FOO,BAR" and inner.states["FOO,BAR"].action == "Foo+Bar"
    # FOO and BAR share 'outcome1': each child's outcome is its own event
    assert {"FOO.outcome1", "FOO.outcome2", "BAR.outcome1"} <= set(inner.events())
    # both done with the mapped outcomes -> outcome5 -> the machine ends
    assert run(model, ["FOO.outcome2", "BAR.outcome1"]) == ["", ""]
    runner = Runner(model)
    assert runner.started == ("Foo+Bar",)  # entering CON starts both children
    runner.step("BAR.outcome1")
    runner.step("FOO.outcome2")
    assert runner.status == "final"
    # FOO's other outcome -> default outcome4 -> CON again (its children start again)
    runner = Runner(model)
    runner.step("FOO.outcome1")
    assert runner.step("BAR.outcome1") == ["Foo+Bar"]


def test_concurrence_last_matching_outcome_map_entry_wins() -> None:
    model, _ = read(
        smach("""
        cc = smach.Concurrence(outcomes=['x', 'y', 'd'], default_outcome='d',
                               outcome_map={'x': {'FOO': 'outcome1'}, 'y': {'BAR': 'outcome1'}})
        with cc:
            smach.Concurrence.add('FOO', Foo())
            smach.Concurrence.add('BAR', Bar())
    """)
    )
    assert ("FOO=outcome1,BAR", "BAR.outcome1", "y", None) in edges(model)
    assert ("FOO=outcome2,BAR", "BAR.outcome1", "y", None) in edges(model)


def test_concurrence_of_a_container_child_runs_it_alongside_the_leaf() -> None:
    model, _ = read(
        smach("""
        cc = smach.Concurrence(outcomes=['ok', 'ko'], default_outcome='ko',
                               outcome_map={'ok': {'SUB': 'fine', 'BAR': 'outcome1'}})
        with cc:
            sub = smach.StateMachine(outcomes=['fine', 'bad'])
            with sub:
                smach.StateMachine.add('F', Foo(), {'outcome1': 'G', 'outcome2': 'bad'})
                smach.StateMachine.add('G', Bar(), {'outcome1': 'fine'})
            smach.Concurrence.add('SUB', sub)
            smach.Concurrence.add('BAR', Bar())
    """)
    )
    assert model.states[model.initial].action == "Foo+Bar"
    # SUB's F and BAR share 'outcome1': every child event is qualified by its child
    runner = Runner(model)
    assert runner.step("SUB.outcome1") == ["Bar"]  # SUB moves on to G (class Bar)
    assert runner.step("BAR.outcome1") == []  # BAR is done, nothing starts
    assert runner.step("SUB.outcome1") == [] and runner.status == "final"
    ending = {t.target for t in model.transitions if model.states[t.target].final}
    assert ending == {"ok", "ko"}
    runner = Runner(model)
    runner.step("SUB.outcome2")  # SUB ends 'bad'
    runner.step("BAR.outcome1")
    assert runner.status == "final" and runner.state == "ko"


def test_iterator_with_static_items_is_unrolled() -> None:
    model, warnings = read(
        smach("""
        sm = smach.StateMachine(outcomes=['succeeded', 'aborted'])
        with sm:
            it = smach.Iterator(outcomes=['succeeded', 'aborted'], input_keys=[], output_keys=[],
                                it=range(3), it_label='i', exhausted_outcome='succeeded')
            with it:
                smach.Iterator.set_contained_state('BODY', Foo(), loop_outcomes=['outcome1'],
                                                   final_outcome_map={'outcome2': 'aborted'})
            smach.StateMachine.add('IT', it, {'succeeded': 'succeeded', 'aborted': 'aborted'})
    """)
    )
    inner = model.states["IT"].regions[0]
    assert [n for n in inner.states if not inner.states[n].final] == ["BODY#1", "BODY#2", "BODY#3"]
    assert ("BODY#3", "outcome1", "succeeded", None) in edges(inner)
    assert ("BODY#2", "outcome2", "aborted", None) in edges(inner)
    assert run(model, ["outcome1", "outcome1", "outcome1"]) == ["Foo", "Foo", ""]
    assert not any("Iterator" in w for w in warnings)


def test_iterator_with_computed_items_reads_their_number_as_an_environment_choice() -> None:
    model, warnings = read(
        smach("""
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            it = smach.Iterator(['done'], [], [], it=lambda: range(len(items)), it_label='i',
                                exhausted_outcome='done')
            with it:
                smach.Iterator.set_contained_state('BODY', Bar(), loop_outcomes=['outcome1'])
            smach.StateMachine.add('IT', it, {'done': 'done'})
    """)
    )
    assert any("known only at run time" in w and "'IT.exhausted'" in w for w in warnings)
    assert run(model, ["outcome1", "IT.next", "outcome1", "IT.exhausted"]) == ["", "Bar", "", ""]
    runner = Runner(model)
    for event in ["outcome1", "IT.exhausted"]:
        runner.step(event)
    assert runner.status == "final"


def test_cbstate_outcomes_come_from_cb_interface_and_its_action_is_the_callback() -> None:
    model, _ = read(
        smach("""
        @smach.cb_interface(outcomes=['yes', 'no'])
        def decide(ud):
            return 'yes'
        sm = smach.StateMachine(outcomes=['yes', 'no'])
        with sm:
            smach.StateMachine.add('DECIDE', smach.CBState(decide))
    """)
    )
    assert model.states["DECIDE"].action == "decide"
    assert edges(model) == {("DECIDE", "yes", "yes", None), ("DECIDE", "no", "no", None)}


def test_aliases_literals_through_names_and_opened() -> None:
    model, _ = read(
        smach(
            """
        label = 'FIRST'
        moves = {'outcome1': 'end', 'outcome2': label}
        sm = SM(outcomes=['end'])
        with sm.opened():
            sm.add(label, Foo(), moves)
    """,
            head=HEAD + "from smach import StateMachine as SM\n",
        )
    )
    assert edges(model) == {
        ("FIRST", "outcome1", "end", None),
        ("FIRST", "outcome2", "FIRST", None),
    }


def test_container_subclass_built_in_its_init() -> None:
    model, _ = read(
        smach(
            """
        top = smach.StateMachine(outcomes=['end'])
        with top:
            smach.StateMachine.add('INNER', Inner(), {'fine': 'end'})
    """,
            head=HEAD
            + textwrap.dedent("""
        class Inner(smach.StateMachine):
            def __init__(self):
                smach.StateMachine.__init__(self, outcomes=['fine'])
                with self:
                    self.add('B', Bar(), transitions={'outcome1': 'fine'})
        """),
        )
    )
    assert edges(model.states["INNER"].regions[0]) == {("B", "outcome1", "fine", None)}


def test_several_top_level_machines_first_is_read_the_others_named() -> None:
    text = smach("""
        one = smach.StateMachine(outcomes=['a'])
        with one:
            smach.StateMachine.add('X', Bar(), {'outcome1': 'a'})
        two = smach.StateMachine(outcomes=['b'])
        with two:
            smach.StateMachine.add('Y', Bar(), {'outcome1': 'b'})
    """)
    model, warnings = read(text)
    assert list(model.states) == ["X", "a"]
    assert any("not read: 'two'" in w for w in warnings)
    other, _ = read(text, machine="two")
    assert list(other.states) == ["Y", "b"]


# -- refusals -----------------------------------------------------------------------------------
UNSUPPORTED = {
    "label built at run time": (
        """
        sm = smach.StateMachine(outcomes=['a'])
        with sm:
            smach.StateMachine.add('S' + str(1), Bar(), {'outcome1': 'a'})
    """,
        "label built at run time",
    ),
    "f-string label": (
        """
        sm = smach.StateMachine(outcomes=['a'])
        with sm:
            smach.StateMachine.add(f'S{n}', Bar(), {'outcome1': 'a'})
    """,
        "label built at run time",
    ),
    "states added in a loop": (
        """
        sm = smach.StateMachine(outcomes=['a'])
        with sm:
            for i in range(3):
                smach.StateMachine.add('S', Bar(), {'outcome1': 'a'})
    """,
        "in a loop",
    ),
    "computed transitions": (
        """
        sm = smach.StateMachine(outcomes=['a'])
        with sm:
            smach.StateMachine.add('S', Bar(), {o: 'a' for o in ['outcome1']})
    """,
        "transitions of 'S'",
    ),
    "transitions from a call": (
        """
        sm = smach.StateMachine(outcomes=['a'])
        with sm:
            smach.StateMachine.add('S', Bar(), make_transitions())
    """,
        "transitions of 'S'",
    ),
    "add under a condition": (
        """
        sm = smach.StateMachine(outcomes=['a'])
        with sm:
            if debug:
                smach.StateMachine.add('S', Bar(), {'outcome1': 'a'})
    """,
        "under a condition",
    ),
    "concurrence child of unknown outcomes": (
        """
        cc = smach.Concurrence(outcomes=['a'], default_outcome='a')
        with cc:
            smach.Concurrence.add('EXT', ImportedState())
    """,
        "outcomes of Concurrence child 'EXT'",
    ),
}


def test_a_concurrence_callback_is_read_not_run_and_named() -> None:
    # docs/semantics.md §11, "Concurrence callbacks": never executed; child_termination_cb
    # only stops children early (an outcome the environment already chooses); outcome_cb
    # becomes a state returning any declared outcome of the container
    text = smach(
        """
        cc = smach.Concurrence(outcomes=['a', 'b'], default_outcome='a',
                               child_termination_cb=lambda so: True, outcome_cb=pick)
        with cc:
            smach.Concurrence.add('B', Bar())
    """
    )
    model, warnings = read(text)
    assert any("child_termination_cb lambda so: True not modelled" in w for w in warnings)
    assert any("outcome_cb pick not modelled" in w for w in warnings)
    inner = model.states[str(model.initial)].regions[0] if model.name != "cc" else model
    chooser = inner.states["pick"]
    assert sorted(t.event for t in inner.outgoing("pick")) == ["a", "b"]
    assert all(inner.states[t.target].final for t in inner.outgoing("pick"))
    assert chooser.action == "pick"


@pytest.mark.parametrize("case", sorted(UNSUPPORTED))
def test_unsupported_constructs_are_named_with_their_line(case: str) -> None:
    body, cause = UNSUPPORTED[case]
    text = smach(body)
    with pytest.raises(UnsupportedError) as caught:
        read(text)
    message = str(caught.value)
    assert "unsupported:" in message and cause in message
    line = caught.value.location.line
    assert line is not None and line > HEAD.count("\n")


INVALID = {
    "outcome mapped to nothing": (
        """
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            smach.StateMachine.add('A', Foo(), {'outcome1': 'done'})
    """,
        "outcome 'outcome2' of state 'A' is mapped to nothing",
    ),
    "outcome mapped to None": (
        """
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            smach.StateMachine.add('A', Bar(), {'outcome1': None})
    """,
        "mapped to nothing",
    ),
    "unknown target": (
        """
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            smach.StateMachine.add('A', Bar(), {'outcome1': 'NOWHERE'})
    """,
        "neither a state",
    ),
    "outcome the class lacks": (
        """
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            smach.StateMachine.add('A', Bar(), {'outcome1': 'done', 'oops': 'done'})
    """,
        "outcome 'oops' it does not have",
    ),
    "unknown initial state": (
        """
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            smach.StateMachine.add('A', Bar(), {'outcome1': 'done'})
        sm.set_initial_state(['B'])
    """,
        "set_initial_state names 'B'",
    ),
    "add outside with": (
        """
        sm = smach.StateMachine(outcomes=['done'])
        smach.StateMachine.add('A', Bar(), {'outcome1': 'done'})
    """,
        "outside a 'with container:' block",
    ),
    "outcome map naming no child": (
        """
        cc = smach.Concurrence(outcomes=['a', 'b'], default_outcome='a',
                               outcome_map={'b': {'GHOST': 'outcome1'}})
        with cc:
            smach.Concurrence.add('B', Bar())
    """,
        "names 'GHOST'",
    ),
    "duplicate label": (
        """
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            smach.StateMachine.add('A', Bar(), {'outcome1': 'done'})
            smach.StateMachine.add('A', Bar(), {'outcome1': 'done'})
    """,
        "already used",
    ),
    "no state machine": ("x = 1\n", "no state machine is built"),
}


@pytest.mark.parametrize("case", sorted(INVALID))
def test_invalid_machines_are_located_input_errors(case: str) -> None:
    body, cause = INVALID[case]
    with pytest.raises(InputError) as caught:
        read(smach(body))
    assert not isinstance(caught.value, UnsupportedError)
    assert cause in str(caught.value)


# -- hostile inputs ------------------------------------------------------------------------------
def test_code_in_the_file_is_never_executed(tmp_path: Path) -> None:
    marker = tmp_path / "EXECUTED"
    path = tmp_path / "hostile.py"
    path.write_text(
        textwrap.dedent(f"""\
        import smach
        open({str(marker)!r}, 'w').write('module level ran')
        __import__('os').system('touch {marker}')

        class Foo(smach.State):
            open({str(marker)!r}, 'w')
            def __init__(self, x=open({str(marker)!r}, 'w')):
                smach.State.__init__(self, outcomes=['a'])

        def main():
            sm = smach.StateMachine(outcomes=['a'])
            with sm:
                smach.StateMachine.add('F', Foo(), {{'a': 'a'}})
            open({str(marker)!r}, 'w')

        if __name__ == '__main__':
            main()
        """),
        encoding="utf-8",
    )
    model = api.load(path).model
    assert isinstance(model, FSM) and list(model.states) == ["F", "a"]
    assert not marker.exists()


def test_syntax_error_is_a_located_input_error() -> None:
    with pytest.raises(InputError) as caught:
        read("import smach\n\nsm = smach.StateMachine(outcomes=['a'\n")
    assert "syntax error" in str(caught.value)
    assert caught.value.location.line is not None


@pytest.mark.parametrize(
    "expression",
    [
        "-" * 100_000 + "1",
        "1" + "+1" * 100_000,
        "(" * 100_000 + ")" * 100_000,
        "a" + ".b" * 100_000,
    ],
)
def test_hundred_thousand_deep_expression_is_a_clean_error(expression: str) -> None:
    with pytest.raises(InputError) as caught:
        read("import smach\nx = " + expression + "\n")
    assert "nested" in str(caught.value) or "syntax error" in str(caught.value)


def test_deeply_nested_with_blocks_are_refused_cleanly() -> None:
    lines = ["import smach"]
    for depth in range(300):
        lines.append("    " * depth + f"with s{depth}:")
    lines.append("    " * 300 + "pass")
    with pytest.raises(InputError):
        read("\n".join(lines) + "\n")


# -- the same through the real CLI ----------------------------------------------------------------
def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    root = Path(__file__).resolve().parents[2]
    env = dict(os.environ, PYTHONPATH=str(root / "src"))
    return subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", *args],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )


def test_cli_converts_a_smach_file_without_running_it(tmp_path: Path) -> None:
    marker = tmp_path / "EXECUTED"
    source = tmp_path / "robot.py"
    source.write_text(
        smach(
            """
        sm = smach.StateMachine(outcomes=['done'])
        with sm:
            smach.StateMachine.add('FOO', Foo(), {'outcome1': 'BAR', 'outcome2': 'done'})
            smach.StateMachine.add('BAR', Bar(), {'outcome1': 'FOO'})
    """,
            head=HEAD + f"open({str(marker)!r}, 'w')\n",
        ),
        encoding="utf-8",
    )
    out = tmp_path / "robot_bt.xml"
    done = _cli("convert", str(source), "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "verdict: EQUIVALENT" in done.stdout + done.stderr
    assert out.exists() and not marker.exists()


@pytest.mark.parametrize("kind", ["deep expression", "syntax error"])
def test_cli_reports_hostile_python_in_one_line(tmp_path: Path, kind: str) -> None:
    source = tmp_path / "bad.py"
    body = "x = " + "-" * 100_000 + "1\n" if kind == "deep expression" else "def (:\n"
    source.write_text("import smach\n" + body, encoding="utf-8")
    done = _cli("convert", str(source), "-o", str(tmp_path / "out.xml"))
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and str(source) in lines[0]
    assert "Traceback" not in done.stderr
