"""``fsmbt translate`` through the real CLI (a subprocess, as a user runs it) for each example
pair of issue 12 - SMACH -> SCXML, BehaviorTree.CPP v3 -> v4, SCXML -> Mermaid, FlexBE -> JSON -
and the library's refusal of a loss that changes behaviour.

Each output is read back here independently and compared with the source model.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import Format, loads
from fsmbt.formats.schema.json_format import write_json
from fsmbt.formats.translate import (
    differences_between,
    rename_events,
    scxml_event_renames,
    translate,
)
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify
from support.corpus import CORPUS

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
needs_corpus = pytest.mark.skipif(not (CORPUS / "fsm").exists(), reason="corpus not present")


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", *args],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )


SMACH_SOURCE = """\
import smach
from support.corpus import CORPUS

class Foo(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=['outcome1', 'outcome2'])

def main():
    sm = smach.StateMachine(outcomes=['outcome4'])
    with sm:
        smach.StateMachine.add('FOO', Foo(), transitions={'outcome1': 'BAR',
                                                          'outcome2': 'outcome4'})
        sub = smach.StateMachine(outcomes=['back'])
        with sub:
            smach.StateMachine.add('INNER', Foo(), {'outcome1': 'back', 'outcome2': 'back'})
        smach.StateMachine.add('BAR', sub, transitions={'back': 'FOO'})
"""


def test_smach_to_scxml(tmp_path: Path) -> None:
    source = tmp_path / "machine.py"
    source.write_text(SMACH_SOURCE, encoding="utf-8")
    out = tmp_path / "machine.scxml"
    done = cli("translate", str(source), "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "(smach) ->" in done.stderr and "(scxml)" in done.stderr
    assert "verified equivalent" in done.stderr
    model, back = api.load(source).model, api.load(out).model
    assert differences_between(model, back) == []
    again = cli("translate", str(source), "-o", str(out))
    assert again.returncode == 2 and "--force" in again.stderr  # never overwritten silently
    assert cli("translate", str(source), "-o", str(out), "--force").returncode == 0


@needs_corpus
def test_smach_concurrence_to_scxml_names_what_scxml_cannot_say(tmp_path: Path) -> None:
    out = tmp_path / "c.scxml"
    done = cli(
        "translate", str(CORPUS / "fsm" / "smach_tutorials" / "concurrence2.py"), "-o", str(out)
    )
    assert done.returncode == 0, done.stderr
    # SCXML can say how CON ended: each completion transition is guarded by In('<final>')
    text = out.read_text(encoding="utf-8")
    assert 'event="done.state.CON"' in text and 'cond="In(' in text
    assert "ends differently by final state" not in done.stderr
    assert verify(
        api.load(CORPUS / "fsm" / "smach_tutorials" / "concurrence2.py").model, api.load(out).model
    ).equivalent


@needs_corpus
def test_btcpp_v3_to_v4(tmp_path: Path) -> None:
    source = CORPUS / "bt" / "bt_in_action" / "julienbayle_stardust_r1_bt.xml"
    assert "BTCPP_format" not in source.read_text(encoding="utf-8")
    out = tmp_path / "v4.xml"
    done = cli("translate", str(source), "-o", str(out), "--to", "btcpp")
    assert done.returncode == 0, done.stderr
    assert 'format_version: "3" becomes "4"' in done.stderr  # the change is named
    text = out.read_text(encoding="utf-8")
    assert 'BTCPP_format="4"' in text and "SequenceStar" not in text
    before, after = api.load(source).model, api.load(out).model
    assert isinstance(before, BTDocument) and isinstance(after, BTDocument)
    assert verify(before, after).equivalent


def test_scxml_to_mermaid(tmp_path: Path) -> None:
    out = tmp_path / "door.mmd"
    done = cli("translate", str(EXAMPLES / "door_hfsm.scxml"), "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "\nstateDiagram-v2\n" in out.read_text(encoding="utf-8")
    assert (
        differences_between(api.load(EXAMPLES / "door_hfsm.scxml").model, api.load(out).model) == []
    )


def test_a_refusing_target_is_an_error_and_flatten_is_offered(tmp_path: Path) -> None:
    source = tmp_path / "machine.py"
    source.write_text(SMACH_SOURCE, encoding="utf-8")
    out = tmp_path / "m.fsm.xml"  # the paper's FSM XML holds no composite state
    done = cli("translate", str(source), "-o", str(out))
    assert done.returncode == 2 and "--flatten" in done.stderr and not out.exists()
    assert "Traceback" not in done.stderr
    flat = cli("translate", str(source), "-o", str(out), "--flatten")
    assert flat.returncode == 0, flat.stderr
    assert "warning: paper-xml: flattened:" in flat.stderr
    assert verify(api.load(source).model, api.load(out).model).equivalent


@needs_corpus
def test_flexbe_to_json(tmp_path: Path) -> None:
    source = CORPUS / "fsm" / "flexbe_turtlesim_demo" / "flexbe_turtlesim_demo_sm.py"
    out = tmp_path / "demo.json"
    done = cli("translate", str(source), "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "(flexbe) ->" in done.stderr
    assert "warning:" in done.stderr and "declares outcome 'failed'" in done.stderr  # reader's
    model, back = api.load(source).model, api.load(out).model
    assert isinstance(back, FSM) and differences_between(model, back) == []


def test_reader_option_picks_another_machine(tmp_path: Path) -> None:
    source = tmp_path / "two.py"
    source.write_text(
        SMACH_SOURCE
        + """
    other = smach.StateMachine(outcomes=['end'])
    with other:
        smach.StateMachine.add('SOLO', Foo(), {'outcome1': 'end', 'outcome2': 'end'})
""",
        encoding="utf-8",
    )
    first = cli("translate", str(source), "--to", "json")
    assert first.returncode == 0 and "not read: 'other'" in first.stderr
    assert list(loads(first.stdout, "json").states) == ["FOO", "BAR", "outcome4"]
    chosen = cli("translate", str(source), "--to", "json", "-O", "machine=other", "--json")
    assert chosen.returncode == 0, chosen.stderr
    summary = json.loads(chosen.stdout)
    assert summary["verified_equivalent"] is True and summary["from"] == "smach"
    assert list(loads(summary["model"], "json").states) == ["SOLO", "end"]
    assert cli("translate", str(source), "--to", "json", "-O", "machine").returncode == 2


def test_stdout_needs_a_target_format(tmp_path: Path) -> None:
    source = tmp_path / "machine.py"
    source.write_text(SMACH_SOURCE, encoding="utf-8")
    assert cli("translate", str(source)).returncode == 2
    done = cli("translate", str(source), "--to", "json")
    assert done.returncode == 0 and loads(done.stdout, "json") == api.load(source).model


def test_a_loss_that_changes_behaviour_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    def drop_last_transition(model: FSM) -> str:  # a target that silently loses an edge
        assert isinstance(model, FSM)
        cut = FSM(
            name=model.name,
            states=dict(model.states),
            transitions=model.transitions[:-1],
            initial=model.initial,
            start_name=model.start_name,
            initial_event=model.initial_event,
        )
        return write_json(cut)

    from fsmbt.formats import registry

    registry.formats()  # the built-in formats first, then the test's (removed afterwards)
    monkeypatch.setitem(
        registry._FORMATS,
        "lossy-for-test",
        Format(
            "lossy-for-test",
            (".lossy",),
            frozenset({"fsm"}),
            "test only",
            lambda text, ctx: loads(text, "json"),
            drop_last_transition,
        ),
    )
    with pytest.raises(UnsupportedError, match="changes the model's behaviour"):
        api.translate(EXAMPLES / "paper_fsm.xml", to="lossy-for-test")
    model = api.load(EXAMPLES / "paper_fsm.xml").model
    unchecked = translate(model, "lossy-for-test")  # formats never verify: structure only
    assert not unchecked.verified
    assert any("transitions" in loss and "is lost" in loss for loss in unchecked.losses)


@needs_corpus
def test_labels_that_are_not_scxml_ids_are_renamed_and_named(tmp_path: Path) -> None:
    source = CORPUS / "fsm" / "flexbe_turtlesim_demo" / "flexbe_turtlesim_demo_sm.py"
    out = tmp_path / "demo.scxml"
    done = cli("translate", str(source), "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "'Finished Eight-pattern' -> 'Finished_Eight-pattern'" in done.stderr
    text = out.read_text(encoding="utf-8")
    assert 'id="Finished Eight-pattern"' not in text and 'id="Finished_Eight-pattern"' in text
    # the outcome 'done' would match every done.state.X event in SCXML: renamed, and named
    assert "'done' -> 'ev_done'" in done.stderr
    source_model = api.load(source).model
    renamed = rename_events(source_model, scxml_event_renames(source_model))
    assert verify(renamed, api.load(out).model).equivalent
