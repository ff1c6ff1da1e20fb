"""Metrics on hand-made models against hand counts; edit distance properties; the CLI."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from fsmbt.metrics import elements, graph_edit_distance, tree_edit_distance
from fsmbt.metrics.formulas import Comparison, bsd, hfsm, lebt
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM, State

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _leaf(name: str, condition: bool = False) -> BTNode:
    return BTNode(type=name, kind=NodeKind.CONDITION if condition else NodeKind.ACTION)


def _ctrl(kind: str, *children: BTNode) -> BTNode:
    return BTNode(type=kind, kind=NodeKind.CONTROL, children=list(children))


def small_bt() -> BTDocument:
    # Sequence(Fallback(c1, a1), Inverter(a2), a3): 7 nodes, 6 edges, 4 leaves, depth 3
    inverter = BTNode(type="Inverter", kind=NodeKind.DECORATOR, children=[_leaf("a2")])
    return BTDocument.single(
        _ctrl("Sequence", _ctrl("Fallback", _leaf("c1", True), _leaf("a1")), inverter, _leaf("a3"))
    )


def small_hfsm() -> FSM:
    # top: X (composite: p -> q, q final), Y (action None), Z final; 3 transitions on top
    sub = FSM(name="X")
    sub.add_state("p")
    sub.add_state(State("q", action="q", final=True))
    sub.add_transition("p", "go", "q")
    top = FSM(name="top")
    top.add_state(State("X", action=None, regions=[sub]))
    top.add_state(State("Y", action=None))
    top.add_state(State("Z", action="Z", final=True))
    top.add_transition("X", None, "Y", exit="q")
    top.add_transition("Y", "e1", "Z")
    top.add_transition("Y", "e2", "X")
    return top


def test_bt_elements_hand_count():
    e = elements(small_bt())
    assert (e.nodes, e.edges, e.graphical, e.active, e.depth, e.leaves) == (7, 6, 13, 4, 3, 4)
    assert e.by_type["Inverter"] == 1 and e.by_type["Sequence"] == 1


def test_fsm_elements_hand_count():
    e = elements(small_hfsm())
    # states: X, Y, Z, p, q = 5; machines 2 (one start marker + one initial arrow each);
    # transitions 3 + 1 = 4  ->  5 + 2 + 4 + 2 = 13; active: Z, p, q (X composite, Y none)
    assert (e.states, e.transitions, e.machines, e.sub_fsms) == (5, 4, 2, 1)
    assert (e.graphical, e.active, e.depth) == (13, 3, 2)
    assert e.by_type == {"atomic": 2, "composite": 1, "final": 2}


def test_formulas():
    assert (lebt(10), hfsm(12, 3), bsd(10)) == (69, 55, 81)
    c = Comparison.of("x", "8M+1", [81, 90], [81, 81])
    assert c.exact_share == 0.5 and c.deviation_max > 0 and c.measured_min == 81


def mutated(doc: BTDocument) -> BTDocument:
    root = doc.main.root
    copy = BTDocument.single(_ctrl(root.type, *root.children[:-1], _leaf("changed")))
    return copy


def test_tree_edit_distance_properties():
    a = small_bt()
    b = mutated(small_bt())
    c = BTDocument.single(_ctrl("Fallback", _leaf("a1"), _leaf("c1", True)))
    assert tree_edit_distance(a, small_bt()).value == 0
    assert tree_edit_distance(a, b).value == 1  # one relabel
    for x, y in ((a, b), (a, c), (b, c)):
        assert tree_edit_distance(x, y).value == tree_edit_distance(y, x).value
    ab, bc, ac = (tree_edit_distance(*p).value for p in ((a, b), (b, c), (a, c)))
    assert ac <= ab + bc
    assert tree_edit_distance(a, c).value > 0


def test_graph_edit_distance_properties():
    f = small_hfsm()
    g = small_hfsm()
    g.transitions[1].event = "other"  # relabel one edge
    assert graph_edit_distance(f, small_hfsm()).value == 0
    d = graph_edit_distance(f, g)
    assert d.exact and d.value == 1
    assert graph_edit_distance(g, f).value == d.value


def test_graph_edit_distance_timeout_reports_upper_bound():
    from fsmbt.generate.generator import random_fsm

    a = random_fsm(seed=1, n_states=25)
    b = random_fsm(seed=2, n_states=25)
    d = graph_edit_distance(a, b, timeout=0.05)
    assert not d.exact and d.to_dict()["kind"] == "upper bound" and d.value > 0


def test_metrics_cli_json_and_errors():
    def run(*args):
        return subprocess.run(
            [sys.executable, "-m", "fsmbt.cli", "metrics", *args],  # noqa: E731
            capture_output=True,
            text=True,
            timeout=120,
        )

    proc = run(str(EXAMPLES / "robot_bt.xml"), str(EXAMPLES / "robot_bt.xml"), "--json")
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["model"]["graphical"] == 2 * data["model"]["nodes"] - 1
    assert data["distance"]["value"] == 0 and data["distance"]["exact"]
    mixed = run(str(EXAMPLES / "robot_bt.xml"), str(EXAMPLES / "paper_fsm.json"))
    assert mixed.returncode == 2 and "Traceback" not in mixed.stderr
