"""BT -> FSM of a dispatch tree (docs/semantics.md section 12, "Back to a state machine"): the
tree fsmbt wrote reads back as the source machine (same states, actions and transitions),
proven equivalent to the source and to the tree; a hand-broken tree is named (located
warnings, NOT EQUIVALENT against the source) or refused (one located line, exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.generate import random_fsm
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify


def _dispatch_text(fsm: FSM) -> str:
    return dumps(convert(fsm, style="dispatch").model, "btcpp")


def _shape(fsm: FSM) -> tuple[object, ...]:
    states = sorted((s.name, s.action, s.final) for s in fsm.states.values())
    edges = sorted((t.source, str(t.event), t.target) for t in fsm.transitions)
    return fsm.initial, fsm.initial_event, states, edges


@pytest.mark.parametrize("shape", ["tree", "chain"])
@pytest.mark.parametrize("n", [1, 2, 7, 40, 300])
@pytest.mark.parametrize("start_event", [False, True])
def test_a_dispatch_tree_reads_back_as_its_source(shape: str, n: int, start_event: bool) -> None:
    extra = {"extra_edges": 0} if shape == "chain" else {}
    fsm = random_fsm(f"d{n}", n, start_event=start_event, shape=shape, **extra)  # type: ignore[arg-type]
    doc = loads(_dispatch_text(fsm), "btcpp")  # what BehaviorTree.CPP reads
    back = convert(doc)
    assert back.direction == "bt->fsm" and back.stats["style"] == "dispatch"
    assert isinstance(back.model, FSM)
    assert back.warnings == []
    assert verify(doc, back.model).equivalent  # the tree and its machine
    assert verify(fsm, back.model).equivalent  # the source and the machine read back
    assert _shape(back.model) == _shape(fsm)  # the source itself, state by state


def test_the_cli_converts_back_and_verifies_either_order(tmp_path: Path) -> None:
    fsm = random_fsm("cli", 9, start_event=False, shape="tree")
    source = tmp_path / "fsm.json"
    api.write(fsm, source)
    tree, back = tmp_path / "d.xml", tmp_path / "back.json"
    assert main(["convert", str(source), "--style", "dispatch", "-o", str(tree)]) == 0
    assert main(["convert", str(tree), "-o", str(back)]) == 0
    assert back.exists()
    for first, second in ((tree, source), (source, tree), (back, source)):
        _first, _second, report = api.verify_files(first, second)
        assert report.equivalent
    report = api.verify_files(tree, source)[2]
    assert report.stats["pairing"] == "FSM ~ dispatch BT (macro steps)"
    assert api.conversion_blockers(api.load(tree).model) == []


def _mutated(fsm: FSM) -> str:
    """The dispatch tree of ``fsm`` with the second transition's Script writing another
    state's lowest digit."""
    text = _dispatch_text(fsm)
    lines = text.splitlines()
    first = [line for line in lines if "fsm_d0:='" in line][1]
    digit = first.split("fsm_d0:='")[1][0]
    other = "b" if digit != "b" else "c"
    return text.replace(first, first.replace(f"fsm_d0:='{digit}'", f"fsm_d0:='{other}'"), 1)


def test_a_wrong_target_reads_back_as_another_machine_named_where() -> None:
    fsm = random_fsm("wrong", 12, start_event=False, shape="tree")
    back = convert(loads(_mutated(fsm), "btcpp"))
    assert isinstance(back.model, FSM)
    clash = [w for w in back.warnings if "enter the same state index" in w]
    assert len(clash) == 1 and "<input>:" in clash[0]  # both leaves located
    report = verify(fsm, back.model)
    assert not report.equivalent
    assert not report.properties["completeness"].holds


def test_a_wrong_target_is_not_equivalent_through_the_cli(tmp_path: Path) -> None:
    fsm = random_fsm("wrongcli", 12, start_event=False, shape="tree")
    source, tree = tmp_path / "fsm.json", tmp_path / "d.xml"
    api.write(fsm, source)
    tree.write_text(_mutated(fsm))
    assert main(["convert", str(tree), "-o", str(tmp_path / "back.json")]) == 0
    assert not api.verify_files(tmp_path / "back.json", source)[2].equivalent
    assert not api.verify_files(tree, source)[2].equivalent


def test_a_foreign_leaf_is_refused_with_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fsm = random_fsm("foreign", 5, start_event=False, shape="chain", extra_edges=0)
    text = _dispatch_text(fsm)
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if "<DispatchEntry" in line and i > 5)
    lines[k] = lines[k].replace("<DispatchEntry", "<Beep")
    tree = tmp_path / "d.xml"
    tree.write_text("\n".join(lines) + "\n")
    assert main(["convert", str(tree), "-o", str(tmp_path / "back.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert f"d.xml:{k + 1}" in err and "DispatchEntry" in err
    assert not (tmp_path / "back.json").exists()


def test_a_tick_entering_two_states_is_refused() -> None:
    fsm = FSM("two")
    fsm.add_state("A")
    fsm.add_state("B")
    fsm.initial = "A"
    fsm.add_transition("A", "go", "B")
    text = _dispatch_text(fsm)
    entry = next(line.strip() for line in text.splitlines() if 'state="B"' in line)
    assert entry.startswith("<DispatchEntry")
    doubled = text.replace(
        entry, f'<Sequence>{entry}<DispatchEntry name="C" state="C" action="C"/></Sequence>', 1
    )
    with pytest.raises(UnsupportedError, match="enters one state per step") as caught:
        convert(loads(doubled, "btcpp"))
    assert caught.value.location is not None


def test_loop_is_refused_for_a_dispatch_tree() -> None:
    fsm = random_fsm("loop", 4, start_event=False, shape="chain", extra_edges=0)
    with pytest.raises(InputError, match="--loop"):
        convert(loads(_dispatch_text(fsm), "btcpp"), loop=True)


@pytest.mark.parametrize("start_event", [False, True])
def test_the_checker_sees_one_settled_state_per_fsm_state(start_event: bool) -> None:
    fsm = random_fsm("settled", 60, start_event=start_event, shape="tree")
    report = verify(fsm, convert(fsm, style="dispatch").model)
    assert report.equivalent
    # FSMMachine: its states plus the start pseudo-state when it has an initial event
    assert report.stats["result_states"] == report.stats["source_states"]
