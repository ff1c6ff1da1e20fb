"""`fsmbt info` and the statistics behind it, checked against figures computed independently
from the example files (lxml over the XML, not fsmbt's readers)."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest
from lxml import etree

from fsmbt.cli import main
from fsmbt.model import FSM, BehaviorTree, BTDocument, BTNode, NodeKind, State
from fsmbt.model.stats import bt_stats, expanded_depth, fsm_stats

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def info_json(path: Path, capsys: pytest.CaptureFixture) -> dict:
    assert main(["info", str(path), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


# -- the paper's A-J FSM ------------------------------------------------------------------------
def paper_xml_facts() -> dict:
    """States, transitions and in-degrees read straight from the paper-format XML."""
    root = etree.parse(str(EXAMPLES / "paper_fsm.xml")).getroot()
    start = root.find("InitialState").get("name")
    states = [s.get("name") for s in root.iter("State")]
    edges = [(t.get("from"), t.get("event"), t.get("to")) for t in root.iter("Transition")]
    preds: dict[str, set[str]] = {s: set() for s in states}
    for source, _event, target in edges:
        preds[target].add(source)
    (entry,) = [target for source, _e, target in edges if source == start]
    return {
        "start": start,
        "states": states,
        "edges": edges,
        "entry": entry,
        "loops": [s for s in states if len(preds[s]) >= 2],
        "finals": [s.get("name") for s in root.iter("State") if s.get("type") == "final"],
    }


@pytest.mark.parametrize("name", ["paper_fsm.json", "paper_fsm.xml"])
def test_paper_fsm_figures(name: str, capsys: pytest.CaptureFixture) -> None:
    facts = paper_xml_facts()
    data = info_json(EXAMPLES / name, capsys)
    assert data["kind"] == "fsm"
    assert data["states"] == len(facts["states"]) == 10
    # the initial transition Start->A is kept as the initial event, not as a transition
    assert data["transitions"] + 1 == len(facts["edges"]) == 15
    assert set(data["events"]) == {event for _s, event, _t in facts["edges"]}
    assert data["start"] == facts["start"] and data["initial_event"] == "eventSA"
    assert data["entry_state"] == facts["entry"] == "A"
    assert (
        data["loop_states"] == facts["loops"] == ["C", "D"]
    )  # docs/conversion.md, 'FSM -> BT', on the paper's FSM
    assert data["finals"] == facts["finals"] == ["H", "J"]
    assert data["unreachable"] == []
    assert data["in_degree"]["C"] == 3 and data["in_degree"]["D"] == 4  # C: A,B,E; D: A,B,C,E
    assert data["nesting_depth"] == 1 and not data["hierarchical"]


def test_in_degree_counts_distinct_sources_and_the_start_edge() -> None:
    fsm = FSM(name="m")
    for n in ("a", "b", "c"):
        fsm.add_state(n)
    fsm.add_transition("a", "x", "b")
    fsm.add_transition("a", "y", "b")  # same source twice: one predecessor
    fsm.add_transition("b", "z", "a")  # a: start edge + b = 2 -> entry and loop state
    fsm.add_transition("c", "w", "c")  # c: unreachable self-loop
    s = fsm_stats(fsm)
    assert s.in_degree == {"a": 2, "b": 1, "c": 1}
    assert s.entry_state == "a" and s.loop_states == ["a"]
    assert s.unreachable == ["c"]


def test_hierarchical_counts() -> None:
    region = FSM(name="inner")
    region.add_state("x")
    region.add_state("y")
    region.add_transition("x", "go", "y")
    deeper = FSM(name="deep")
    deeper.add_state(State("Inner", action=None, regions=[region]))
    other = FSM(name="other")
    other.add_state("z")
    top = FSM(name="top")
    top.add_state(State("P", action=None, regions=[deeper, other]))
    top.add_state("Q")
    top.add_transition("P", "leave", "Q")
    s = fsm_stats(top)
    assert (s.states, s.all_states) == (2, 6)  # P, Q; Inner, z; x, y
    assert (s.transitions, s.all_transitions) == (1, 2)
    assert (s.composite_states, s.parallel_states, s.nesting_depth) == (1, 1, 3)
    assert s.events == ["leave", "go"] and s.hierarchical


def test_fsm_nested_100000_deep_is_measured_without_recursion() -> None:
    fsm = FSM(name="leaf")
    fsm.add_state("s")
    for i in range(100_000):
        outer = FSM(name=f"m{i}")
        outer.add_state(State(f"c{i}", action=None, regions=[fsm]))
        fsm = outer
    s = fsm_stats(fsm)
    assert s.nesting_depth == 100_001 and s.composite_states == 100_000


# -- the paper's robot BT -----------------------------------------------------------------------
def robot_xml_facts() -> dict:
    """Node counts, depth and breadth of the robot BT, from the XML with lxml only."""
    root = etree.parse(str(EXAMPLES / "robot_bt.xml")).getroot()
    declared = {m.get("ID"): m.tag for m in root.find("TreeNodesModel")}
    tree = root.find("BehaviorTree")
    nodes = [e for e in tree.iter() if isinstance(e.tag, str) and e is not tree]
    levels = Counter(len(list(e.iterancestors())) - 1 for e in nodes)  # root element: level 1
    kinds = Counter(declared.get(e.tag, "Control") for e in nodes)
    return {
        "nodes": len(nodes),
        "depth": max(levels),
        "breadth": max(levels.values()),
        "kinds": dict(kinds),
        "types": Counter(e.tag for e in nodes),
        "leaves": sum(1 for e in nodes if len(e) == 0),
    }


def test_robot_bt_figures(capsys: pytest.CaptureFixture) -> None:
    facts = robot_xml_facts()
    data = info_json(EXAMPLES / "robot_bt.xml", capsys)
    assert data["kind"] == "bt" and data["trees"] == 1 and data["main_tree"] == "RobotMission"
    assert data["nodes"] == facts["nodes"] == 21
    assert data["depth"] == facts["depth"] == 7
    assert data["breadth"] == facts["breadth"]
    assert data["by_kind"] == facts["kinds"]
    assert data["by_type"] == dict(facts["types"])
    assert data["leaves"] == facts["leaves"] == 12
    assert (data["actions"], data["conditions"], data["subtree_references"]) == (6, 6, 0)
    assert data["expanded_depth"] == data["depth"]


def test_subtree_expansion_depth_cycles_and_dangling_references() -> None:
    leaf = BTNode("Tick", NodeKind.ACTION)
    sub = BTDocument(
        trees={
            "Main": BehaviorTree(
                "Main",
                BTNode(
                    "Sequence",
                    NodeKind.CONTROL,
                    children=[BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Deep"})],
                ),
            ),
            "Deep": BehaviorTree("Deep", BTNode("Inverter", NodeKind.DECORATOR, children=[leaf])),
        },
        main_tree="Main",
    )
    s = bt_stats(sub)
    assert (s.depth, s.expanded_depth, s.subtree_references, s.trees) == (2, 4, 1, 2)
    sub.trees["Deep"].root.children[0] = BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Main"})
    assert expanded_depth(sub) is None  # a cycle
    sub.trees["Deep"].root.children[0] = BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Nope"})
    assert expanded_depth(sub) is None  # a dangling reference


def test_bt_100000_deep_is_measured_without_recursion() -> None:
    node = BTNode("Tick", NodeKind.ACTION)
    for _ in range(100_000):
        node = BTNode("Inverter", NodeKind.DECORATOR, children=[node])
    s = bt_stats(BTDocument.single(node))
    assert (s.nodes, s.depth, s.breadth, s.leaves) == (100_001, 100_001, 1, 1)
    assert s.expanded_depth == 100_001


# -- the table ----------------------------------------------------------------------------------
def test_info_table_for_both_kinds(capsys: pytest.CaptureFixture) -> None:
    assert main(["info", str(EXAMPLES / "paper_fsm.xml")]) == 0
    out = capsys.readouterr().out
    assert "loop states" in out and "C, D" in out and "Start --eventSA--> A" in out
    assert main(["info", str(EXAMPLES / "game_npc_bt.xml")]) == 0
    out = capsys.readouterr().out
    assert "subtree references" in out and "per tree" in out and "Combat" in out


def test_info_bad_input_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text('{"kind": "fsm", "states": [1]}', encoding="utf-8")
    assert main(["info", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "bad.json" in err
