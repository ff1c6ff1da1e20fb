"""Text formats (YAML, CSV, Markdown, Mermaid, DOT): read -> write -> read gives an equal model,
content sniffing picks the right reader, and the documented rules hold."""

from __future__ import annotations

import random
import shutil
import subprocess
from pathlib import Path

import pytest

from fsmbt.formats import detect_format, dumps, loads
from fsmbt.model import FSM, BTDocument, BTNode, InputError, NodeKind, State, UnsupportedError
from fsmbt.model.serialize import model_to_dict

TABLE = "source,event,target,action\nA,go,B,doB\nB,back,A,\nB,stop,C,\n"
MERMAID_HIERARCHICAL = """---
title: Door
---
stateDiagram-v2
    %% comments and notes are ignored
    direction LR
    [*] --> Closed
    state "opening the door" as Opening
    Closed --> Opening : open
    Opening --> Open : done
    Open --> Closed : close
    note right of Open : a note
    note left of Closed
        a multi-line note
    end note
    state Locked {
        [*] --> Armed
        Armed --> Alarm : shake
        state Alarm {
            [*] --> Ringing
            Ringing --> Quiet : hush
            Quiet --> [*]
        }
        Alarm --> [*]
    }
    Closed --> Locked : lock
    Locked --> Closed
    Locked --> Gone : kaboom
    Gone --> [*]
"""


def random_flat_fsm(seed: int) -> FSM:
    """A flat FSM every text format can hold: finals are exactly the states without outgoing
    transitions, every state is on some transition, the initial state has one out."""
    rng = random.Random(seed)
    n = rng.randint(2, 9)
    names = [f"S{i}" for i in range(n)]
    fsm = FSM(name="fsm")
    for name in names:
        fsm.add_state(State(name, action=rng.choice([name, f"do_{name}"])))
    fsm.states["S0"].action = "S0"  # nothing enters S0 in every model: keep its default action
    for i in range(1, n):  # a spanning tree from S0 so every state is mentioned
        fsm.add_transition(names[rng.randrange(i)], f"e{i}", names[i])
    for _ in range(rng.randint(0, n)):
        source, target = rng.choice(names), rng.choice(names)
        event = f"x{rng.randint(0, 3)}"
        if all((t.source, t.event) != (source, event) for t in fsm.transitions):
            fsm.add_transition(source, event, target)
    sources = {t.source for t in fsm.transitions}
    for state in fsm.states.values():
        state.final = state.name not in sources
    return fsm


def hierarchical_fsm() -> FSM:
    inner = FSM(name="Work")
    inner.add_state(State("Prepare", action="prepare"))
    inner.add_state(State("Done", final=True, action="Done"))
    inner.add_transition("Prepare", "ready", "Done")
    fsm = FSM(name="job")
    fsm.add_state(State("Idle", action="Idle"))
    fsm.add_state(State("Work", action=None, regions=[inner]))
    fsm.add_state(State("End", action="End", final=True))
    fsm.add_transition("Idle", "start", "Work")
    fsm.add_transition("Work", None, "End")
    fsm.add_transition("Work", "abort", "Idle")
    return fsm


def robot_bt() -> BTDocument:
    def leaf(name: str, kind: NodeKind = NodeKind.ACTION) -> BTNode:
        return BTNode(name, kind)

    def control(kind: str, *children: BTNode) -> BTNode:
        return BTNode(kind, NodeKind.CONTROL, children=list(children))

    root = control(
        "Sequence",
        control("Fallback", leaf("BatteryBelow", NodeKind.CONDITION), leaf("Recharge")),
        BTNode("Inverter", NodeKind.DECORATOR, name="not", children=[leaf("Dock")]),
        BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "Sub", "_autoremap": "true"}),
    )
    doc = BTDocument.single(root, "Main")
    doc.trees["Sub"] = BTDocument.single(leaf("Wave"), "Sub").trees["Sub"]
    return doc


def roundtrip(model, fmt: str):
    first = loads(dumps(model, fmt), fmt)
    second = loads(dumps(first, fmt), fmt)
    assert second == first
    return first


# -- round trips -----------------------------------------------------------------------------
@pytest.mark.parametrize("fmt", ["yaml", "csv", "md", "mermaid", "dot"])
@pytest.mark.parametrize("seed", range(25))
def test_flat_fsm_roundtrip_is_exact(fmt: str, seed: int) -> None:
    fsm = random_flat_fsm(seed)
    assert loads(dumps(fsm, fmt), fmt) == fsm


@pytest.mark.parametrize("fmt", ["yaml", "mermaid"])
def test_hierarchical_fsm_roundtrip(fmt: str) -> None:
    fsm = hierarchical_fsm()
    assert loads(dumps(fsm, fmt), fmt) == fsm


def test_hierarchical_mermaid_file_roundtrip() -> None:
    fsm = loads(MERMAID_HIERARCHICAL)
    assert fsm.name == "Door"
    assert fsm.states["Opening"].action == "opening the door"
    locked = fsm.states["Locked"]
    assert locked.is_composite and locked.action is None
    alarm = locked.regions[0].states["Alarm"]
    assert alarm.is_composite and alarm.final
    assert alarm.regions[0].initial == "Ringing"
    assert alarm.regions[0].states["Quiet"].final
    assert [(t.source, t.event, t.target) for t in fsm.transitions if t.source == "Locked"] == [
        ("Locked", None, "Closed"),
        ("Locked", "kaboom", "Gone"),
    ]
    assert roundtrip(fsm, "mermaid") == fsm


def test_bt_yaml_roundtrip_keeps_everything() -> None:
    doc = robot_bt()
    back = loads(dumps(doc, "yaml"), "yaml")
    assert back == doc
    assert model_to_dict(back) == model_to_dict(doc)


def test_yaml_reads_what_json_writes_same_schema() -> None:
    doc = robot_bt()
    assert loads(dumps(doc, "json"), "yaml") == doc


def test_start_pseudo_state_roundtrips_in_mermaid_and_dot() -> None:
    fsm = random_flat_fsm(3)
    fsm.start_name, fsm.initial_event = "Begin", "init"
    for fmt in ("mermaid", "dot", "yaml"):
        assert loads(dumps(fsm, fmt), fmt) == fsm, fmt


def test_odd_names_roundtrip_in_mermaid() -> None:
    fsm = FSM(name="odd names")
    for name in ("C/x", "state", "a b", "9lives"):
        fsm.add_state(State(name, action=f"act {name}"))
    fsm.add_transition("C/x", "go on", "a b")
    fsm.add_transition("a b", "x:y", "state")
    fsm.add_transition("state", None, "9lives")
    fsm.states["9lives"].final = True
    fsm.states["state"].action = None
    assert loads(dumps(fsm, "mermaid"), "mermaid") == fsm


def test_dot_output_is_accepted_by_graphviz() -> None:
    dot = shutil.which("dot")
    if dot is None:
        pytest.skip("Graphviz 'dot' is not installed")
    for model in (hierarchical_fsm(), robot_bt(), random_flat_fsm(7)):
        result = subprocess.run(
            [dot, "-Tsvg"], input=dumps(model, "dot"), text=True, capture_output=True, timeout=30
        )
        assert result.returncode == 0, result.stderr
        assert "<svg" in result.stdout
        assert "Warning" not in result.stderr, result.stderr


def test_dot_bt_is_a_tree_with_one_edge_per_child() -> None:
    doc = robot_bt()
    text = dumps(doc, "dot")
    nodes = sum(1 for _ in doc.nodes())
    # one visible edge per child (trees stacked in rows are held apart by invisible edges)
    visible = [line for line in text.splitlines() if " -> " in line and "invis" not in line]
    assert len(visible) == nodes - len(doc.trees)


# -- table rules ------------------------------------------------------------------------------
def test_table_rules_initial_final_and_target_action() -> None:
    fsm = loads(TABLE, "csv")
    assert fsm.initial == "A"
    assert [s.name for s in fsm.states.values() if s.final] == ["C"]
    assert fsm.states["B"].action == "doB" and fsm.states["A"].action == "A"
    assert loads(TABLE, "csv", options={"initial": "B"}).initial == "B"


def test_table_header_is_case_and_space_insensitive_in_any_order() -> None:
    fsm = loads("  Target , SOURCE ,Event \nB,A,go\nA,B,back\n", "csv")
    assert [(t.source, t.event, t.target) for t in fsm.transitions] == [
        ("A", "go", "B"),
        ("B", "back", "A"),
    ]


def test_markdown_table_inside_prose() -> None:
    text = (
        "# My machine\n\nSome words.\n\n| Source | Event | Target |\n|:---|---|---:|\n"
        "| `A` | go | B |\n| B | a\\|b | A |\n\nMore prose | with a pipe.\n"
    )
    fsm = loads(text)
    assert [(t.source, t.event, t.target) for t in fsm.transitions] == [
        ("A", "go", "B"),
        ("B", "a|b", "A"),
    ]
    assert loads(dumps(fsm, "md"), "md") == fsm


def test_conflicting_actions_name_both_rows() -> None:
    with pytest.raises(InputError) as info:
        loads("source,event,target,action\nA,e,B,x\nB,f,B,y\n", "csv")
    assert ":3" in str(info.value) and "line 2" in str(info.value)


@pytest.mark.parametrize(
    "text,needle",
    [
        ("source,event\nA,go\n", "lacks column(s) target"),
        ("source,event,target,colour\nA,go,B,red\n", "unknown column 'colour'"),
        ("source,event,target\nA,go\n", ":2: row has 2 cells"),
        ("source,event,target\n,go,B\n", ":2: empty 'source'"),
        ("source,event,target\n", "no transitions"),
    ],
)
def test_csv_errors_name_the_line(text: str, needle: str) -> None:
    with pytest.raises(InputError, match=None) as info:
        loads(text, "csv")
    assert needle in str(info.value)


def test_table_writer_refuses_what_a_table_cannot_say() -> None:
    with pytest.raises(UnsupportedError, match="composite"):
        dumps(hierarchical_fsm(), "csv")
    fsm = random_flat_fsm(1)
    fsm.start_name, fsm.initial_event = "Start", "init"
    with pytest.raises(UnsupportedError, match="start pseudo-state"):
        dumps(fsm, "md")
    fsm = loads(TABLE, "csv")
    fsm.states["C"].final = False
    with pytest.raises(UnsupportedError, match="not final"):
        dumps(fsm, "csv")


# -- Mermaid and DOT rules ---------------------------------------------------------------------
@pytest.mark.parametrize(
    "text,needle",
    [
        ("stateDiagram-v2\nstate F <<fork>>\n", "unsupported: <<fork>>"),
        ("stateDiagram-v2\nstate C <<choice>>\n", "unsupported: <<choice>>"),
        ("stateDiagram-v2\nstate P {\n a --> b\n --\n c --> d\n}\n", ":4: unsupported: concurrent"),
        ("stateDiagram-v2\nA --> [*] : quit\n", "unsupported: a labelled transition to [*]"),
        (
            "stateDiagram-v2\nstate C {\n a --> b\n}\nb --> D\n",
            ":5: unsupported: state 'b' belongs",
        ),
        ("stateDiagram-v2\n[*] --> A\n[*] --> B\n", "two initial states"),
        ("stateDiagram-v2\nA ==> B\n", ":2: cannot read"),
        ("flowchart TD\nA-->B\n", "not a Mermaid state diagram"),
        ("stateDiagram-v2\nstate C {\nA --> B\n", "never closed"),
    ],
)
def test_mermaid_errors(text: str, needle: str) -> None:
    with pytest.raises(InputError) as info:
        loads(text, "mermaid")
    assert needle in str(info.value)


def test_dot_reads_the_classic_fsm_idiom() -> None:
    text = """digraph finite_state_machine {
        rankdir=LR;
        node [shape = doublecircle]; LR_3;
        node [shape = circle];
        __start__ [shape=point];
        __start__ -> LR_0;
        LR_0 -> LR_2 [label = "SS(B)"];
        LR_2 -> LR_3 -> LR_0 [label = "S(A)"];  // an edge chain: both edges get the label
    }"""
    fsm = loads(text)
    assert fsm.name == "finite_state_machine" and fsm.initial == "LR_0"
    assert fsm.states["LR_3"].final and not fsm.states["LR_2"].final
    assert "__start__" not in fsm.states
    assert [(t.source, t.event, t.target) for t in fsm.transitions] == [
        ("LR_0", "SS(B)", "LR_2"),
        ("LR_2", "S(A)", "LR_3"),
        ("LR_3", "S(A)", "LR_0"),
    ]


@pytest.mark.parametrize(
    "text,needle",
    [
        ("graph G { a -- b }", "undirected"),
        ("digraph { subgraph cluster_x { a } }", "subgraphs"),
        ("digraph { a:p -> b }", "ports"),
        ("digraph { a -> b", "missing '}'"),
        ("digraph { s [shape=point]; s -> a; s -> b }", "more than one initial arrow"),
    ],
)
def test_dot_errors(text: str, needle: str) -> None:
    with pytest.raises(InputError) as info:
        loads(text, "dot")
    assert needle in str(info.value)


# -- YAML guards ------------------------------------------------------------------------------
def test_yaml_alias_is_refused_with_its_line() -> None:
    with pytest.raises(InputError, match=r":2:\d+: YAML aliases"):
        loads("kind: fsm\nstates: *x\n", "yaml")


def test_yaml_deep_nesting_refused_and_moderate_depth_read() -> None:
    depth = 1000
    text = (
        "kind: bt\ntrees:\n- id: T\n  root: "
        + "{type: Inverter, kind: Decorator, children: [" * depth
        + "{type: A}"
        + "]}" * depth
        + "\n"
    )
    doc = loads(text, "yaml")
    assert sum(1 for _ in doc.nodes()) == depth + 1
    with pytest.raises(InputError, match="nested deeper"):
        loads("a: " + "[" * 100_000 + "]" * 100_000, "yaml")


# -- sniffing ---------------------------------------------------------------------------------
@pytest.mark.parametrize("fmt", ["json", "yaml", "csv", "md", "mermaid", "dot"])
def test_content_sniffing_picks_the_writer_format(fmt: str) -> None:
    fsm = random_flat_fsm(5)
    assert detect_format(dumps(fsm, fmt)).name == fmt


def test_sniffing_bt_yaml_and_dot() -> None:
    assert detect_format(dumps(robot_bt(), "yaml")).name == "yaml"
    assert detect_format(dumps(robot_bt(), "dot")).name == "dot"


def test_write_model_creates_missing_folders_and_never_overwrites(tmp_path: Path) -> None:
    """`fsmbt convert -o out/x.xml` on a fresh clone has no out/ yet."""
    from fsmbt import api
    from fsmbt.model.errors import InputError
    from fsmbt.model.fsm import FSM

    fsm = FSM()
    fsm.add_state("A")
    target = tmp_path / "new" / "deeper" / "model.json"
    api.write(fsm, target)
    assert target.read_text(encoding="utf-8").startswith("{")
    with pytest.raises(InputError, match="exists"):
        api.write(fsm, target)
