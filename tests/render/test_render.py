"""Pictures: the DOT source has the shapes, edges and clusters the drawing rules promise, and
the CLI writes real SVG/PNG files without ever replacing a file unless told to."""

from __future__ import annotations

import re
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.model import FSM, BehaviorTree, BTDocument, BTNode, NodeKind, State
from fsmbt.render import TooLargeError, bt_to_dot, fsm_to_dot, render_model
from fsmbt.render.bt_graph import CONTROL_SYMBOLS

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz dot not installed")


# -- a small reader for the DOT the graphviz package writes -------------------------------------
_ATTR = re.compile(r'(\w+)=("(?:[^"\\]|\\.)*"|<(?:[^<>]|<[^<>]*>)*>|[^\s\]]+)')


@dataclass
class Cluster:
    name: str
    attrs: dict[str, str] = field(default_factory=dict)
    nodes: list[str] = field(default_factory=list)
    children: list[Cluster] = field(default_factory=list)
    parent: Cluster | None = None


@dataclass
class Dot:
    nodes: dict[str, dict[str, str]]
    edges: list[tuple[str, str, dict[str, str]]]
    root: Cluster
    clusters: dict[str, Cluster]

    def label(self, node: str) -> str:
        return plain(self.nodes[node].get("label", node))

    def cluster_of(self, node: str) -> str | None:
        for c in self.clusters.values():
            if node in c.nodes:
                return c.name
        return None

    def children(self, node: str) -> list[str]:
        return [head for tail, head, _ in self.edges if tail == node]


def plain(value: str) -> str:
    """A DOT label value as text: quotes and HTML markup removed, line breaks as newlines."""
    if value.startswith("<"):
        value = re.sub(r"<BR/>", "\n", value[1:-1])
        return (
            re.sub(r"<[^>]+>", "", value)
            .replace("&amp;", "&")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
        )
    if value.startswith('"'):
        value = value[1:-1].replace('\\"', '"')
    return value.replace("\\n", "\n")


def parse_dot(source: str) -> Dot:
    root = Cluster("root")
    clusters: dict[str, Cluster] = {}
    current = root
    nodes: dict[str, dict[str, str]] = {}
    edges: list[tuple[str, str, dict[str, str]]] = []
    for raw in source.splitlines()[1:]:
        line = raw.strip()
        if line.startswith("subgraph "):
            child = Cluster(line.split()[1], parent=current)
            current.children.append(child)
            clusters[child.name] = child
            current = child
        elif line == "}":
            current = current.parent or root
        elif m := re.match(r"^(\S+) -> (\S+)(?: \[(.*)\])?$", line):
            edges.append((m.group(1), m.group(2), dict(_ATTR.findall(m.group(3) or ""))))
        elif m := re.match(r"^(\S+) \[(.*)\]$", line):
            if m.group(1) in ("node", "edge", "graph"):
                continue
            nodes.setdefault(m.group(1), {}).update(_ATTR.findall(m.group(2)))
            current.nodes.append(m.group(1))
        elif "=" in line and current is not root:
            current.attrs.update(_ATTR.findall(line))
    return Dot(nodes, edges, root, clusters)


def attrs_value(value: str | None) -> str:
    return plain(value) if value is not None else ""


# -- FSM ----------------------------------------------------------------------------------------
def paper_fsm() -> FSM:
    return api.load(EXAMPLES / "paper_fsm.json").model


def test_fsm_states_shapes_initial_arrow_and_labelled_transitions() -> None:
    fsm = paper_fsm()
    dot = parse_dot(fsm_to_dot(fsm))
    by_label = {dot.label(n): n for n, a in dot.nodes.items() if a.get("shape") != "point"}
    assert set(by_label) == set(fsm.states)
    for name, state in fsm.states.items():
        assert dot.nodes[by_label[name]]["shape"] == ("doublecircle" if state.final else "circle")
    points = [n for n, a in dot.nodes.items() if a.get("shape") == "point"]
    assert len(points) == 1
    assert attrs_value(dot.nodes[points[0]].get("xlabel")) == fsm.start_name
    name_of = {v: k for k, v in by_label.items()}
    drawn = {(name_of.get(t, t), attrs_value(a.get("label")), name_of[h]) for t, h, a in dot.edges}
    expected = {(t.source, t.event, t.target) for t in fsm.transitions}
    expected.add((points[0], fsm.initial_event, fsm.initial))
    assert drawn == expected


def test_parallel_transitions_share_one_labelled_arrow() -> None:
    fsm = FSM(name="m")
    fsm.add_state("a")
    fsm.add_state("b")
    for event in ("e1", "e2", "e3", "e4"):
        fsm.add_transition("a", event, "b")
    dot = parse_dot(fsm_to_dot(fsm))
    state_edges = [e for e in dot.edges if dot.nodes[e[0]].get("shape") != "point"]
    assert len(state_edges) == 1
    assert set(re.split(r"[,\n] ?", attrs_value(state_edges[0][2]["label"]))) == {
        "e1",
        "e2",
        "e3",
        "e4",
    }


def door_hfsm() -> FSM:
    """A composite state (Operating) and a parallel one (Panel, two regions)."""
    inner = FSM(name="Operating")
    for n in ("Closed", "Open"):
        inner.add_state(n)
    inner.add_transition("Closed", "open", "Open")
    inner.add_transition("Open", "close", "Closed")
    lights = FSM(name="lights")
    lights.add_state("Off")
    lights.add_state("On")
    lights.add_transition("Off", "toggle", "On")
    fan = FSM(name="fan")
    fan.add_state("Idle")
    fan.add_state("Done", final=True)
    fan.add_transition("Idle", "stop", "Done")
    top = FSM(name="door")
    top.add_state(State("Operating", action=None, regions=[inner]))
    top.add_state("Emergency")
    top.add_state(State("Panel", action=None, regions=[lights, fan]))
    top.add_state("End", final=True)
    top.add_transition("Operating", "alarm", "Emergency")
    top.add_transition("Emergency", "reset", "Operating")
    top.add_transition("Emergency", "panel", "Panel")
    top.add_transition("Panel", None, "End")
    return top


def test_composite_states_are_clusters_and_parallel_regions_dashed_subclusters() -> None:
    dot = parse_dot(fsm_to_dot(door_hfsm()))
    by_label = {attrs_value(c.attrs.get("label")): c for c in dot.clusters.values()}
    operating, panel = by_label["Operating"], by_label["Panel"]
    assert operating.parent is dot.root and panel.parent is dot.root
    assert {dot.label(n) for n in operating.nodes if dot.nodes[n].get("shape") != "point"} == {
        "Closed",
        "Open",
    }
    assert not operating.children
    regions = panel.children
    assert [attrs_value(r.attrs.get("label")) for r in regions] == ["lights", "fan"]
    assert all("dashed" in r.attrs.get("style", "") for r in regions)
    assert {dot.label(n) for n in regions[1].nodes if dot.nodes[n].get("shape") != "point"} == {
        "Idle",
        "Done",
    }
    # every region has its own initial point
    assert all(any(dot.nodes[n].get("shape") == "point" for n in r.nodes) for r in regions)
    # arrows into / out of a composite state end at its cluster's border
    emergency = next(n for n in dot.nodes if dot.label(n) == "Emergency")
    into = [a for t, h, a in dot.edges if t == emergency and "lhead" in a]
    assert {a["lhead"] for a in into} == {operating.name, panel.name}
    out_of = [a for t, h, a in dot.edges if a.get("ltail") == panel.name]
    assert len(out_of) == 1 and attrs_value(out_of[0].get("headlabel")) == "done"
    assert "compound=true" in fsm_to_dot(door_hfsm())


def test_names_that_look_like_markup_stay_text() -> None:
    fsm = FSM(name="weird")
    fsm.add_state("<b>")
    fsm.add_state('say "hi" \\n')
    fsm.add_transition("<b>", "a->b", 'say "hi" \\n')
    dot = parse_dot(fsm_to_dot(fsm))
    labels = {dot.label(n) for n, a in dot.nodes.items() if a.get("shape") != "point"}
    assert "<b>" in labels
    assert any('"hi"' in label for label in labels)


# -- BT -----------------------------------------------------------------------------------------
def _tree_from_dot(dot: Dot, node: str) -> tuple:
    """The drawn tree below ``node`` as nested ``(first label line, children)``, edge order."""
    top: list = []
    pending = [(node, top)]
    while pending:
        current, holder = pending.pop()
        kids: list = []
        holder.append((dot.label(current).split("\n")[0], kids))
        pending.extend((c, kids) for c in reversed(dot.children(current)))
    return _freeze(top[0])


def _freeze(item: tuple) -> tuple:
    label, kids = item
    return (label, tuple(_freeze(k) for k in kids))


def _tree_from_model(node: BTNode) -> tuple:
    symbol = (
        CONTROL_SYMBOLS.get(node.type, node.type) if node.kind is NodeKind.CONTROL else node.label
    )
    return (symbol, tuple(_tree_from_model(c) for c in node.children))


def test_robot_bt_is_drawn_top_down_with_the_tree_structure_and_symbols() -> None:
    doc = api.load(EXAMPLES / "robot_bt.xml").model
    source = bt_to_dot(doc)
    dot = parse_dot(source)
    assert "rankdir=TB" in source and "ordering=out" in source
    roots = [n for n in dot.nodes if not any(h == n for _, h, _ in dot.edges)]
    assert len(roots) == 1
    assert _tree_from_dot(dot, roots[0]) == _tree_from_model(doc.main.root)
    kinds = {node.label: node.kind for _, node in doc.nodes() if node.is_leaf}
    for n in dot.nodes:
        label = dot.label(n)
        if label in kinds:
            expected = "ellipse" if kinds[label] is NodeKind.CONDITION else "box"
            assert dot.nodes[n]["shape"] == expected, label
        else:
            assert dot.nodes[n]["shape"] == "box" and label in ("→", "?")


def test_decorators_parallel_reactive_memory_and_subtrees() -> None:
    doc = api.load(EXAMPLES / "game_npc_bt.xml").model
    dot = parse_dot(bt_to_dot(doc))
    firsts = {dot.label(n).split("\n")[0]: dot.nodes[n] for n in dot.nodes}
    assert firsts["¬"]["shape"] == "hexagon"
    assert firsts["R?"]["shape"] == "box" and firsts["R→"]["shape"] == "box"
    assert firsts["→*"]["shape"] == "box" and firsts["⇉"]["shape"] == "box"
    assert "success_count=2" in dot.label(
        next(n for n in dot.nodes if dot.label(n).startswith("⇉"))
    )
    assert firsts["SubTree Combat"]["shape"] == "tab"
    assert firsts["IsCornered"]["shape"] == "ellipse"
    assert firsts["Retry ↻"]["shape"] == "hexagon"
    titles = sorted(attrs_value(c.attrs.get("label")) for c in dot.clusters.values())
    assert titles == ["Combat", "NpcMain (main)", "Patrol"]
    assert len(dot.nodes) == sum(1 for _ in doc.nodes())


def test_expanded_subtrees_hang_below_their_reference_in_a_cluster() -> None:
    doc = api.load(EXAMPLES / "game_npc_bt.xml").model
    dot = parse_dot(bt_to_dot(doc, expand_subtrees=True))
    ref = next(n for n in dot.nodes if dot.label(n) == "SubTree Combat")
    (child,) = dot.children(ref)
    assert dot.label(child).startswith("?")
    cluster = dot.clusters[dot.cluster_of(child)]
    assert attrs_value(cluster.attrs.get("label")) == "Combat"
    expected = sum(1 for _ in doc.main.root.walk()) + sum(
        1 for tid in ("Combat", "Patrol") for _ in doc.trees[tid].root.walk()
    )
    assert len(dot.nodes) == expected


def test_recursive_subtree_reference_is_not_expanded_forever() -> None:
    a = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[
            BTNode("TickA", NodeKind.ACTION),
            BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "B"}),
        ],
    )
    b = BTNode(
        "Fallback",
        NodeKind.CONTROL,
        children=[
            BTNode("TickB", NodeKind.ACTION),
            BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": "A"}),
        ],
    )
    doc = BTDocument(trees={"A": BehaviorTree("A", a), "B": BehaviorTree("B", b)}, main_tree="A")
    dot = parse_dot(bt_to_dot(doc, expand_subtrees=True))
    # A, then B once below its reference, then B's reference back to A stops
    assert sorted(dot.label(n).split("\n")[0] for n in dot.nodes) == sorted(
        ["→", "TickA", "SubTree B", "?", "TickB", "SubTree A"]
    )
    (back,) = [n for n in dot.nodes if dot.label(n).startswith("SubTree A")]
    assert "recursive" in dot.label(back) and not dot.children(back)


def _chain(depth: int) -> BTNode:
    node = BTNode("Tick", NodeKind.ACTION)
    for _ in range(depth):
        node = BTNode("Inverter", NodeKind.DECORATOR, children=[node])
    return node


def test_large_models_are_refused_with_a_clear_message_not_drawn() -> None:
    deep = BTDocument.single(_chain(100_000))
    with pytest.raises(TooLargeError, match=r"too large to draw: 100001 nodes \(limit 5000\)"):
        bt_to_dot(deep)
    wide = FSM(name="wide")
    for i in range(5_001):
        wide.add_state(f"s{i}")
    with pytest.raises(TooLargeError, match="5001 states"):
        fsm_to_dot(wide)
    assert (
        len(parse_dot(bt_to_dot(BTDocument.single(_chain(6_000)), max_nodes=7_000)).nodes) == 6_001
    )


def test_expansion_that_grows_past_the_limit_is_refused() -> None:
    trees = {"T0": BehaviorTree("T0", BTNode("Tick", NodeKind.ACTION))}
    for i in range(1, 16):  # each tree references the previous one twice: 2^15 leaves expanded
        ref = {"ID": f"T{i - 1}"}
        trees[f"T{i}"] = BehaviorTree(
            f"T{i}",
            BTNode(
                "Sequence",
                NodeKind.CONTROL,
                children=[
                    BTNode("SubTree", NodeKind.SUBTREE, attrs=dict(ref)),
                    BTNode("SubTree", NodeKind.SUBTREE, attrs=dict(ref)),
                ],
            ),
        )
    doc = BTDocument(trees=trees, main_tree="T15")
    bt_to_dot(doc)  # 46 nodes unexpanded: fine
    with pytest.raises(TooLargeError, match="more than 5000 nodes"):
        bt_to_dot(doc, expand_subtrees=True)


# -- files and the CLI --------------------------------------------------------------------------
@needs_dot
def test_render_writes_svg_png_and_dot(tmp_path: Path) -> None:
    fsm = paper_fsm()
    svg = render_model(fsm, tmp_path / "a.svg")
    assert b"<svg" in svg.read_bytes()[:2000]
    png = render_model(fsm, tmp_path / "a.png")
    assert png.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    source = render_model(door_hfsm(), tmp_path / "door.dot")
    assert source.read_text(encoding="utf-8").startswith("digraph")


@needs_dot
def test_cli_never_overwrites_without_force(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    out = tmp_path / "pic.svg"
    out.write_text("keep me", encoding="utf-8")
    code = main(["render", str(EXAMPLES / "paper_fsm.json"), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "--force" in err and len(err.strip().splitlines()) == 1
    assert out.read_text(encoding="utf-8") == "keep me"
    assert main(["render", str(EXAMPLES / "paper_fsm.json"), "-o", str(out), "--force"]) == 0
    assert "<svg" in out.read_text(encoding="utf-8")


def test_cli_refuses_unknown_picture_formats_and_large_models(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    assert main(["render", str(EXAMPLES / "paper_fsm.json"), "-o", str(tmp_path / "a.jpg")]) == 2
    assert "use one of" in capsys.readouterr().err
    assert (
        main(
            [
                "render",
                str(EXAMPLES / "robot_bt.xml"),
                "-o",
                str(tmp_path / "a.svg"),
                "--max-nodes",
                "10",
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert "too large to draw: 21 nodes (limit 10)" in err
    assert not (tmp_path / "a.svg").exists() and not (tmp_path / "a.jpg").exists()


def test_large_fsms_switch_to_a_fast_layout_without_clusters() -> None:
    from fsmbt.render.fsm_graph import LAYERED_MAX_STATES

    big = FSM(name="big")
    n = LAYERED_MAX_STATES + 1
    for i in range(n):
        big.add_state(f"s{i}")
    for i in range(n):
        big.add_transition(f"s{i}", "next", f"s{(i + 1) % n}")
    source = fsm_to_dot(big)
    assert "layout=sfdp" in source and "rankdir" not in source
    assert "layout" not in fsm_to_dot(paper_fsm())
    hfsm = door_hfsm()
    for i in range(n):  # the same hierarchy, now too big for the layered layout
        hfsm.add_state(f"extra{i}")
    notes: list[str] = []
    dot = parse_dot(fsm_to_dot(hfsm, notes=notes))
    # issue 13: no box joined to its sub-machine by a dotted arrow; composites drawn closed,
    # each saying what it holds, and a note saying the picture was capped and how to see more
    assert not dot.clusters
    labels = {dot.label(n): n for n in dot.nodes}
    closed = [label for label in labels if label.startswith("Operating") and "inside" in label]
    assert closed and dot.nodes[labels[closed[0]]]["shape"] == "box"
    assert "Operating/Closed" not in labels
    assert not [a for _, _, a in dot.edges if a.get("style") == "dotted"]
    assert len(notes) == 1 and "capped" in notes[0] and "composite=NAME" in notes[0]
