"""validate()/check() messages: each rule fires on a model that breaks it, names the element and
location, and stays quiet on a model that keeps it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt.formats import loads
from fsmbt.model import FSM, BTDocument, BTNode, InputError, NodeKind, NodeModel, State
from fsmbt.model.validate import check, validate


def issues_of(model, severity: str | None = None) -> list[str]:
    return [str(i) for i in validate(model) if severity is None or i.severity == severity]


def good_fsm() -> FSM:
    return loads("source,event,target\nA,go,B\nB,back,A\nB,stop,C\n", "csv")


def test_good_fsm_has_no_issue() -> None:
    assert validate(good_fsm()) == []
    assert check(good_fsm()) == []


def test_nondeterminism_names_row_and_both_targets() -> None:
    fsm = loads("source,event,target\nA,go,B\nA,go,C\nB,x,A\n", "csv")
    [error] = issues_of(fsm, "error")
    assert error.startswith("<input>:3: A --go--> C: error: nondeterministic")
    assert "'B' and 'C'" in error


def test_eventless_transitions_count_as_event_none() -> None:
    fsm = good_fsm()
    fsm.add_transition("A", None, "B")
    fsm.add_transition("A", None, "C")
    assert any("no event (eventless)" in e for e in issues_of(fsm, "error"))


def test_unknown_states_and_missing_initial() -> None:
    fsm = good_fsm()
    fsm.add_transition("A", "jump", "Nowhere")
    fsm.add_transition("Ghost", "boo", "A")
    errors = issues_of(fsm, "error")
    assert any("target 'Nowhere' is not a state" in e for e in errors)
    assert any("source 'Ghost' is not a state" in e for e in errors)
    fsm = good_fsm()
    fsm.initial = None
    assert any("no initial state" in e for e in issues_of(fsm, "error"))
    fsm.initial = "Z"
    assert any("initial state 'Z' is not a state" in e for e in issues_of(fsm, "error"))


def test_empty_fsm_and_final_with_outgoing() -> None:
    assert issues_of(FSM(name="nothing"), "error") == [
        "nothing: error: the state machine has no states"
    ]
    fsm = good_fsm()
    fsm.states["B"].final = True
    assert any("final state 'B' has an outgoing transition" in e for e in issues_of(fsm, "error"))


def test_warnings_unreachable_dead_end_transient() -> None:
    fsm = good_fsm()
    fsm.add_state(State("Island", action="Island"))
    fsm.states["C"].final = False
    fsm.add_state(State("T", action="blink"))
    fsm.add_transition("C", "on", "T")
    fsm.add_transition("T", None, "A")
    warnings = issues_of(fsm, "warning")
    assert any("Island: warning: unreachable" in w for w in warnings)
    assert any("Island: warning: no way out" in w for w in warnings)
    assert any("T: warning: transient state" in w and "'blink'" in w for w in warnings)
    assert issues_of(fsm, "error") == []


def test_hierarchical_checks_every_level() -> None:
    inner = FSM(name="W")
    inner.add_state(State("p", action="p"))
    inner.add_state(State("q", action="q"))
    inner.add_transition("p", "e", "q")
    inner.add_transition("p", "e", "p")
    inner.add_transition("q", "e", "missing")
    inner.add_state(State("r", action="r"))
    fsm = FSM(name="top")
    fsm.add_state(State("Start", action="Start"))
    fsm.add_state(State("W", action="oops", regions=[inner]))
    fsm.add_transition("Start", "go", "W")
    errors = issues_of(fsm, "error")
    assert any(e.startswith("W/p --e--> p: error: nondeterministic") for e in errors)
    assert any("W/q --e--> missing" in e and "not a state" in e for e in errors)
    assert any("W: error: composite state has its own action 'oops'" in e for e in errors)
    # r is a dead end inside W, and W has no event transition out: warned
    assert any("W/r: warning: no way out" in w for w in issues_of(fsm, "warning"))


def test_inner_dead_end_is_fine_when_the_composite_can_be_left() -> None:
    fsm = loads(
        "stateDiagram-v2\n[*] --> C\nstate C {\n [*] --> a\n a --> b : e\n}\n"
        "C --> D : leave\nD --> [*]\n"
    )
    assert not any("no way out" in w for w in issues_of(fsm))


def bt(*children: BTNode, models: dict[str, NodeModel] | None = None) -> BTDocument:
    doc = BTDocument.single(BTNode("Sequence", NodeKind.CONTROL, children=list(children)), "T")
    doc.node_models = models or {}
    return doc


def leaf(name: str, **kwargs) -> BTNode:
    return BTNode(name, NodeKind.ACTION, **kwargs)


def test_good_bt_has_no_issue() -> None:
    doc = bt(leaf("Move"), BTNode("Inverter", NodeKind.DECORATOR, children=[leaf("Check")]))
    assert validate(doc) == []


@pytest.mark.parametrize(
    "node,needle",
    [
        (
            BTNode("Frob", NodeKind.CONTROL, kind_declared=False, children=[leaf("a")]),
            "error: unknown node type 'Frob'",
        ),
        (BTNode("Fallback", NodeKind.CONTROL), "error: control node 'Fallback' has no children"),
        (
            BTNode("Inverter", NodeKind.DECORATOR, children=[leaf("a"), leaf("b")]),
            "error: decorator 'Inverter' needs exactly one child, has 2",
        ),
        (
            BTNode("Switch2", NodeKind.CONTROL, children=[leaf("a")]),
            "error: 'Switch2' needs exactly 3 children, has 1",
        ),
        (
            BTNode("Check", NodeKind.CONDITION, children=[leaf("a")]),
            "error: condition leaf 'Check' has 1 child(ren)",
        ),
        (
            BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Gone"}),
            "error: SubTree references missing tree 'Gone'",
        ),
        (
            BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "SubTree"}),
            "error: SubTree ID 'SubTree' is the name of a built-in node",
        ),
        (
            BTNode("ManualSelector", NodeKind.CONTROL),
            "warning: 'ManualSelector' without children",
        ),
        (
            BTNode("Delay", NodeKind.DECORATOR, children=[leaf("a")]),
            "warning: time-based node 'Delay'",
        ),
        (
            BTNode("Mystery", NodeKind.ACTION, kind_declared=False),
            "warning: leaf type 'Mystery' is not declared",
        ),
        (
            BTNode("Pipeline", NodeKind.CONTROL, children=[leaf("a")]),
            "warning: custom control 'Pipeline' has no known semantics",
        ),
    ],
)
def test_bt_rules(node: BTNode, needle: str) -> None:
    found = issues_of(bt(leaf("first"), node))
    assert any(needle in f for f in found), found
    assert any(f.startswith(f"T/Sequence/{node.label}") for f in found), found


def test_bt_document_level_errors() -> None:
    assert issues_of(BTDocument(), "error") == ["error: the document holds no behavior tree"]
    doc = bt(leaf("a"))
    doc.main_tree = "Elsewhere"
    assert any("main tree 'Elsewhere' is not defined" in e for e in issues_of(doc, "error"))
    doc = bt(leaf("a"))
    doc.trees["T"].root = None
    assert any("the tree is empty" in e for e in issues_of(doc, "error"))


def test_recursive_subtrees_reported_once() -> None:
    doc = bt(BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "U"}))
    doc.trees["U"] = BTDocument.single(
        BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "T"}), "U"
    ).trees["U"]
    cycles = [e for e in issues_of(doc, "error") if "recursive SubTree" in e]
    assert len(cycles) == 1 and "T -> U -> T" in cycles[0]


def test_locations_come_from_the_file() -> None:
    fsm = loads("stateDiagram-v2\n[*] --> A\nA --> B : e\nA --> C : e\n")
    [error] = issues_of(fsm, "error")
    assert error.startswith("<input>:4: A --e--> C")


def test_check_raises_with_all_errors_listed() -> None:
    doc = bt(BTNode("Fallback", NodeKind.CONTROL), BTNode("Inverter", NodeKind.DECORATOR))
    with pytest.raises(InputError) as info:
        check(doc)
    message = str(info.value)
    assert "control node 'Fallback' has no children" in message
    assert "and 1 more error(s)" in message and "decorator 'Inverter'" in message


def test_validate_handles_100000_deep_trees() -> None:
    node = leaf("A", children=[leaf("B")])
    for _ in range(100_000):
        node = BTNode("Inverter", NodeKind.DECORATOR, children=[node])
    found = issues_of(BTDocument.single(node, "T"))
    assert len(found) == 1 and "action leaf 'A' has 1 child(ren)" in found[0]
    assert "…" in found[0]  # the element path is shortened, not 100 000 names long


# -- the command ------------------------------------------------------------------------------
def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "validate", *args],
        capture_output=True,
        text=True,
        timeout=60,
    )


def test_cli_exit_codes_json_and_strict(tmp_path: Path) -> None:
    good = tmp_path / "good.csv"
    good.write_text("source,event,target\nA,go,B\nB,back,A\nB,stop,C\n", encoding="utf-8")
    warned = tmp_path / "warned.mmd"
    warned.write_text(
        "stateDiagram-v2\n[*] --> A\nA --> B : go\nC --> A : x\nB --> [*]\n", encoding="utf-8"
    )
    assert run_cli(str(good)).returncode == 0
    result = run_cli(str(warned))
    assert result.returncode == 0 and "unreachable" in result.stdout
    strict = run_cli("--strict", str(warned))
    assert strict.returncode == 2 and strict.stderr.count("\n") == 1
    assert "unreachable" in strict.stderr
    report = json.loads(run_cli("--json", str(warned)).stdout)
    assert report["valid"] is True and report["errors"] == 0 and report["warnings"] >= 1
    assert {"severity", "message", "element", "file", "line", "column"} <= set(report["issues"][0])
    assert report["issues"][0]["file"] == str(warned)
