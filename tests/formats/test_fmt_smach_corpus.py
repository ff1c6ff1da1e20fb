"""Every SMACH and FlexBE file of the external corpus reads, converts (FSM -> BT, rules engine)
and verifies equivalent, and goes through the SMACH writer and back to an equivalent model.

The corpus holds real files written by others (../shared/corpus, see its README); skipped only
when the folder is absent. A file that stops reading fails here with the reader's message.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import loads
from fsmbt.formats.pysm.smach_write import write_smach
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify
from support.corpus import CORPUS

FSM_DIR = CORPUS / "fsm"
SMACH_FILES = sorted([*FSM_DIR.glob("smach_tutorials/*.py"), *FSM_DIR.glob("smach_tests/*.py")])
FLEXBE_FILES = sorted(FSM_DIR.glob("flexbe_turtlesim_demo/*_sm.py"))
FILES = SMACH_FILES + FLEXBE_FILES

pytestmark = pytest.mark.skipif(not FSM_DIR.exists(), reason="corpus not present (FSMBT_CORPUS)")


def _id(path: Path) -> str:
    return f"{path.parent.name}/{path.name}"


def test_the_corpus_has_the_files_the_readme_promises() -> None:
    assert (len(SMACH_FILES), len(FLEXBE_FILES)) == (15, 7)


@pytest.mark.parametrize("path", FILES, ids=_id)
def test_corpus_file_reads_converts_and_verifies(path: Path) -> None:
    model = api.load(path).model
    assert isinstance(model, FSM) and model.states
    expected = "flexbe" if "flexbe" in path.parent.name else "smach"
    assert loads(path.read_text(encoding="utf-8"), path=path).name == model.name
    from fsmbt.formats import detect_format

    assert detect_format(path.read_text(encoding="utf-8")).name == expected
    result = convert(model)
    report = verify(model, result.model)
    assert report.equivalent, f"{path}: {report.verdicts()}"


@pytest.mark.parametrize("path", FILES, ids=_id)
def test_corpus_file_round_trips_through_the_smach_writer(path: Path) -> None:
    model = api.load(path).model
    again = loads(write_smach(model), "smach")
    assert verify(model, again).equivalent


def test_embedded_behaviours_are_nested_from_their_files() -> None:
    demo = api.load(FSM_DIR / "flexbe_turtlesim_demo" / "flexbe_turtlesim_demo_sm.py").model
    embedded = demo.states["Turtlesim Input State Behavior"]
    assert embedded.attrs["flexbe.behaviour"] == "TurtlesimInputStateBehaviorSM"
    alone = api.load(
        FSM_DIR / "flexbe_turtlesim_demo" / "turtlesim_input_state_behavior_sm.py"
    ).model
    assert embedded.regions[0].states.keys() == alone.states.keys()
    assert embedded.regions[0].transitions == alone.transitions
