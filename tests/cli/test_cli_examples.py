"""Every example through the CLI (info, render, validate when present), the paper's two models
checked against the issue's own description of them, and the BTs loaded by BehaviorTree.CPP."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from lxml import etree

from fsmbt import api
from fsmbt.cli import main
from fsmbt.formats.registry import format_for_path, formats
from fsmbt.model import FSM, BTDocument, BTNode, NodeKind

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: runnable example programs (not models): run_*.py
SCRIPTS = sorted(p for p in EXAMPLES.iterdir() if p.suffix == ".py" and p.name.startswith("run_"))
MODEL_FILES = sorted(
    p for p in EXAMPLES.iterdir() if p.is_file() and p.name != "README.md" and p not in SCRIPTS
)


def _readable(path: Path) -> bool:
    """Some readers land in parallel with these examples; a model whose format no reader
    claims yet is skipped (with the reason), never silently passed."""
    return format_for_path(path) is not None or any(
        f.read is not None and f.sniff is not None and f.sniff(path.read_text(encoding="utf-8"))
        for f in formats()
    )


def _need_reader(path: Path) -> None:
    assert _readable(path), f"no reader is registered for {path.name}"


def test_examples_readme_lists_exactly_the_example_files() -> None:
    readme = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    mentioned = set(re.findall(r"`([\w.-]+\.\w+)`", readme))
    assert mentioned == {p.name for p in MODEL_FILES + SCRIPTS}


@pytest.mark.parametrize("path", MODEL_FILES, ids=lambda p: p.name)
def test_info_and_render_every_example(
    path: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    _need_reader(path)
    assert main(["info", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    model = api.load(path).model
    assert data["kind"] == ("fsm" if isinstance(model, FSM) else "bt")
    if shutil.which("dot") is None:
        pytest.skip("Graphviz dot not installed")
    out = tmp_path / f"{path.stem}.svg"
    assert main(["render", str(path), "-o", str(out)]) == 0
    svg = out.read_text(encoding="utf-8")
    assert "<svg" in svg
    names = (
        list(model.states)
        if isinstance(model, FSM)
        else [node.label for _, node in model.nodes() if node.is_leaf]
    )
    assert all(f">{name}<" in svg for name in names)  # every state / leaf is in the picture


@pytest.mark.parametrize("path", MODEL_FILES, ids=lambda p: p.name)
def test_validate_every_example(path: Path, capsys: pytest.CaptureFixture) -> None:
    _need_reader(path)
    code = main(["validate", str(path)])
    captured = capsys.readouterr()
    assert code == 0, captured.err


def test_cli_as_a_process_prints_no_traceback(tmp_path: Path) -> None:
    missing = tmp_path / "nope.json"
    done = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "info", str(missing)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 2
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    done = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "info", str(EXAMPLES / "robot_bt.xml"), "--json"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0 and json.loads(done.stdout)["nodes"] == 21


# -- the paper's models, as issue 2 describes them ----------------------------------------------
PAPER_FSM = "Start→A; A→B, A→C, A→D, A→F; B→C, B→D; C→D; D→E; E→C, E→D, E→G; G→H; F→I; I→J"
ROBOT_BT = (
    "Sequence[ Fallback(BatteryBelow, Recharge), Fallback(Cube2inDelivery, Sequence[ "
    "Fallback(CubeinHand, Sequence[Fallback(RobotatCube2, MovetoCube2), Pickcube2]), "
    "Fallback(RobotatDelivery, MovetoDelivery), PlaceCube2 ]), "
    "Fallback(RobotAtInspection, Dock) ]"
)
ROBOT_CONDITIONS = {
    "BatteryBelow",
    "Cube2inDelivery",
    "CubeinHand",
    "RobotatCube2",
    "RobotatDelivery",
    "RobotAtInspection",
}


@pytest.mark.parametrize("name", ["paper_fsm.xml", "paper_fsm.json"])
def test_paper_fsm_is_the_issues_fsm(name: str) -> None:
    fsm = api.load(EXAMPLES / name).model
    assert isinstance(fsm, FSM)
    pairs = {
        tuple(p.strip().split("→")) for group in PAPER_FSM.split(";") for p in group.split(",")
    }
    drawn = {(t.source, t.target) for t in fsm.transitions} | {(fsm.start_name, fsm.initial)}
    assert drawn == pairs
    for t in fsm.transitions:
        assert t.event == f"event{t.source}{t.target}"
    assert fsm.initial_event == "eventSA"
    assert sorted(fsm.states) == list("ABCDEFGHIJ")


def test_paper_fsm_xml_and_json_hold_the_same_model() -> None:
    assert api.load(EXAMPLES / "paper_fsm.xml").model == api.load(EXAMPLES / "paper_fsm.json").model


def _parse_bracket(text: str) -> tuple:
    """``Sequence[a, Fallback(b, c)]`` as nested ``(name, children)`` tuples."""
    tokens = re.findall(r"\w+|[\[\]()]|,", text)
    position = 0

    def node() -> tuple:
        nonlocal position
        name = tokens[position]
        position += 1
        if position < len(tokens) and tokens[position] in "[(":
            close = "]" if tokens[position] == "[" else ")"
            position += 1
            kids = [node()]
            while tokens[position] == ",":
                position += 1
                kids.append(node())
            assert tokens[position] == close
            position += 1
            return (name, tuple(kids))
        return (name, ())

    return node()


def _shape(node: BTNode) -> tuple:
    return (node.type, tuple(_shape(c) for c in node.children))


def test_robot_bt_is_the_issues_tree() -> None:
    doc = api.load(EXAMPLES / "robot_bt.xml").model
    assert isinstance(doc, BTDocument)
    assert _shape(doc.main.root) == _parse_bracket(ROBOT_BT)
    leaves = {n.type: n.kind for _, n in doc.nodes() if n.is_leaf}
    assert {t for t, k in leaves.items() if k is NodeKind.CONDITION} == ROBOT_CONDITIONS
    assert all(n.kind_declared for _, n in doc.nodes())


def _btcpp_run(xml: str, conditions: set[str], actions: set[str]) -> tuple[str, list[str]]:
    btpy = pytest.importorskip("behaviortreepy")
    factory = btpy.BehaviorTreeFactory()
    ticked: list[str] = []

    def leaf(name: str, status):  # noqa: ANN001 - a behaviortreepy callback
        return lambda _node: (ticked.append(name), status)[1]

    for name in conditions:
        factory.register_simple_condition(name, leaf(name, btpy.NodeStatus.FAILURE))
    for name in actions:
        factory.register_simple_action(name, leaf(name, btpy.NodeStatus.SUCCESS))
    tree = factory.create_tree_from_text(xml)
    return str(tree.tick_once()), ticked


def _declared(path: Path) -> tuple[set[str], set[str]]:
    model = etree.parse(str(path)).getroot().find("TreeNodesModel")
    return (
        {m.get("ID") for m in model if m.tag == "Condition"},
        {m.get("ID") for m in model if m.tag == "Action"},
    )


def test_robot_bt_runs_in_behaviortree_cpp() -> None:
    path = EXAMPLES / "robot_bt.xml"
    status, ticked = _btcpp_run(path.read_text(encoding="utf-8"), *_declared(path))
    # every condition fails and every action succeeds: each Fallback runs its action
    doc = api.load(path).model
    assert status.endswith("SUCCESS")
    assert ticked == [n.type for _, n in doc.nodes() if n.is_leaf]


def test_game_npc_bt_loads_and_ticks_in_behaviortree_cpp() -> None:
    path = EXAMPLES / "game_npc_bt.xml"
    root = etree.parse(str(path)).getroot()
    for element in root.iter("MoveToWaypoint"):  # simple Python leaves cannot declare ports
        del element.attrib["waypoint"]
    status, ticked = _btcpp_run(etree.tostring(root, encoding="unicode"), *_declared(path))
    assert ticked[:2] == ["IsHealthLow", "CanSeeEnemy"]  # not hurt, no enemy: patrol
    assert ticked[2] == "MoveToWaypoint" and status.endswith(("SUCCESS", "RUNNING"))


# -- the README and the docs describe what exists -----------------------------------------------
ROOT = EXAMPLES.parent


def _registered_commands() -> set[str]:
    from fsmbt import cli

    assert main(["--help"]) == 0  # registers every cmd_*.py module
    return {c.name for c in cli.app.registered_commands} | {
        g.name for g in cli.app.registered_groups
    }


def test_readme_marks_exactly_the_existing_commands_available(
    capsys: pytest.CaptureFixture,
) -> None:
    rows = re.findall(
        r"^\| `fsmbt ([\w-]+)[^|]*\|[^|]*\| (\w+) \|$",
        (ROOT / "README.md").read_text(encoding="utf-8"),
        flags=re.M,
    )
    available = {name for name, status in rows if status == "available"}
    registered = _registered_commands()
    capsys.readouterr()
    assert available == registered, "README.md's command table is out of date"
    assert {name for name, status in rows if status == "planned"}.isdisjoint(registered)


def test_cli_doc_has_a_section_per_command(capsys: pytest.CaptureFixture) -> None:
    text = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    documented = set(re.findall(r"^## `fsmbt ([\w-]+)`", text, flags=re.M))
    registered = _registered_commands()
    capsys.readouterr()
    assert registered <= documented, f"docs/cli.md lacks {sorted(registered - documented)}"


def test_docs_index_links_every_document_and_nothing_missing() -> None:
    docs = ROOT / "docs"
    index = (docs / "README.md").read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)#]+)\)", index)
    assert all((docs / link).resolve().exists() for link in links), links
    linked = {(docs / link).resolve() for link in links}
    documents = [*docs.glob("*.md"), *docs.glob("*/README.md")]  # sub-folders have an index
    unlisted = [
        str(p.relative_to(docs))
        for p in documents
        if p != docs / "README.md" and p.resolve() not in linked
    ]
    assert not unlisted, f"docs/README.md does not list {unlisted}"
