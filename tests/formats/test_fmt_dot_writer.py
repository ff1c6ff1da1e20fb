"""One DOT writer: ``fsmbt convert --to dot`` (the format) and ``fsmbt render x.dot`` (the
picture) come from the same builder (docs/formats/dot.md), and the format's DOT of a flat FSM is
read back exactly, odd names included."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.formats import dumps, loads
from fsmbt.generate import random_fsm
from fsmbt.model import FSM, State
from fsmbt.render import bt_to_dot, fsm_to_dot

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
_NODE = re.compile(r'^\t+("(?:[^"\\]|\\.)*"|\S+) \[(.*)\]$')
_SHAPE = re.compile(r"\bshape=(\w+)")


def odd_fsm() -> FSM:
    """Names that DOT would otherwise misread: spaces, a colon (a port), markup, a keyword-like
    word, a leading digit, non-ASCII, quotes and a line break in events."""
    fsm = FSM(name="odd names")
    for name in ("C/x", "st:ate", "a b", "9lives", "<b>", "Ünï"):
        fsm.add_state(State(name, action=f"act {name}"))
    fsm.add_transition("C/x", "go on", "a b")
    fsm.add_transition("a b", "x:y", "st:ate")
    fsm.add_transition("st:ate", None, "9lives")
    fsm.add_transition("9lives", 'say "hi"', "<b>")
    fsm.add_transition("<b>", "two\nlines", "Ünï")
    fsm.add_transition("<b>", "again", "Ünï")  # a second transition between the same pair
    fsm.states["Ünï"].final = True
    fsm.states["st:ate"].action = None
    fsm.start_name, fsm.initial_event = "Begin", "init"
    return fsm


def shapes(source: str) -> list[str]:
    """The ``shape=`` of every node statement, in order."""
    found = []
    for line in source.splitlines():
        match = _NODE.match(line)
        if match and match.group(1) not in ("node", "edge", "graph"):
            shape = _SHAPE.search(match.group(2))
            found.append(shape.group(1) if shape else "")
    return found


def test_odd_names_roundtrip_exactly_through_the_format_writer() -> None:
    fsm = odd_fsm()
    assert loads(dumps(fsm, "dot"), "dot") == fsm


def test_format_dot_of_a_bt_is_the_picture_dot() -> None:
    doc = api.load(EXAMPLES / "robot_bt.xml").model
    assert dumps(doc, "dot") == bt_to_dot(doc)


@pytest.mark.parametrize("name", ["paper_fsm.json", "turnstile.mmd", "door_hfsm.scxml"])
def test_format_and_picture_draw_fsms_with_the_same_nodes_and_clusters(name: str) -> None:
    fsm = api.load(EXAMPLES / name).model
    written, drawn = dumps(fsm, "dot"), fsm_to_dot(fsm)
    assert shapes(written) == shapes(drawn)
    assert written.count("subgraph cluster_") == drawn.count("subgraph cluster_")
    # graph, node, edge defaults; the picture alone carries its pixel cap (size=, 4096 px)
    picture = [line for line in drawn.splitlines() if not line.startswith("\tsize=")]
    assert written.splitlines()[1:4] == picture[1:4]


def test_format_writes_every_transition_the_picture_groups() -> None:
    fsm = odd_fsm()
    transitions = len(fsm.transitions) + 1  # and the initial arrow
    assert dumps(fsm, "dot").count(" -> ") == transitions
    assert fsm_to_dot(fsm).count(" -> ") == transitions - 1  # "<b>" -> "Ünï" shares one arrow


def test_format_has_no_size_limit_the_picture_has() -> None:
    fsm = FSM(name="big")
    for index in range(30):
        fsm.add_state(State(f"S{index}"))
    for index in range(29):
        fsm.add_transition(f"S{index}", "next", f"S{index + 1}")
    assert loads(dumps(fsm, "dot"), "dot") == fsm
    with pytest.raises(Exception, match="too large to draw"):
        fsm_to_dot(fsm, max_nodes=10)


def test_cli_convert_to_dot_and_render_dot_give_the_same_bt_dot(tmp_path: Path) -> None:
    source = EXAMPLES / "paper_fsm.json"
    as_dot, as_xml, drawn = tmp_path / "bt.dot", tmp_path / "bt.xml", tmp_path / "drawn.dot"
    lebt = ["--style", "lebt"]  # 37 nodes: a picture with nothing folded or wrapped
    assert (
        main(["convert", str(source), *lebt, "--to", "dot", "-o", str(as_dot), "--no-verify"]) == 0
    )
    assert main(["convert", str(source), *lebt, "-o", str(as_xml), "--no-verify"]) == 0
    assert main(["render", str(as_xml), "-o", str(drawn)]) == 0
    assert as_dot.read_text(encoding="utf-8") == drawn.read_text(encoding="utf-8")


def test_the_dot_format_is_the_whole_tree_while_render_folds_a_big_one(tmp_path: Path) -> None:
    """A 40-state machine's dispatch tree (the default style): ``--to dot`` is an exchange
    format and holds every node; ``render`` draws the picture a person reads, with folds."""
    source = tmp_path / "big_fsm.json"
    source.write_text(dumps(random_fsm("fold", 40, start_event=False), "json"), encoding="utf-8")
    as_dot, as_xml, drawn = tmp_path / "bt.dot", tmp_path / "bt.xml", tmp_path / "drawn.dot"
    assert main(["convert", str(source), "--to", "dot", "-o", str(as_dot), "--no-verify"]) == 0
    assert main(["convert", str(source), "-o", str(as_xml), "--no-verify"]) == 0
    assert main(["render", str(as_xml), "-o", str(drawn)]) == 0
    whole = as_dot.read_text(encoding="utf-8")
    picture = drawn.read_text(encoding="utf-8")
    nodes = sum(1 for _ in loads(as_xml.read_text(encoding="utf-8"), "btcpp").nodes())
    assert nodes > 60
    assert len(re.findall(r"^\tn\d+ \[label=", whole, flags=re.MULTILINE)) == nodes
    assert "nodes]" not in whole
    assert "nodes]" in picture  # at least one fold box
    assert len(re.findall(r"^\tn\d+ \[label=", picture, flags=re.MULTILINE)) < nodes


def test_format_dot_of_odd_names_is_accepted_by_graphviz() -> None:
    dot = shutil.which("dot")
    if dot is None:
        pytest.skip("Graphviz 'dot' is not installed")
    done = subprocess.run(
        [dot, "-Tsvg"], input=dumps(odd_fsm(), "dot"), text=True, capture_output=True, timeout=30
    )
    assert done.returncode == 0, done.stderr
    assert "Warning" not in done.stderr, done.stderr
