"""The SMV encodings: safe names, rejected node types, decoded counterexamples."""

from __future__ import annotations

import re

import pytest

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify
from fsmbt.verify.native import replay
from fsmbt.verify.nusmv import build_model, check
from fsmbt.verify.pairing import machines_for

RESERVED = ["A", "E", "F", "G", "X", "U", "AF", "AG", "case", "init", "next", "TRUE", "S"]


def _fsm(names: list[str], events: list[str]) -> FSM:
    fsm = FSM(name="reserved")
    for name in names:
        fsm.add_state(name)
    for i, name in enumerate(names):
        fsm.add_transition(name, events[i % len(events)], names[(i + 1) % len(names)])
    return fsm


def test_reserved_words_never_reach_the_smv_text():
    fsm = _fsm(RESERVED, ["G", "X", "U"])
    text, _names, _ctx = build_model(fsm, fsm)
    text = text.split("MODULE main")[0]  # the specs themselves use AG/EF/EX
    for word in RESERVED:
        if word in ("TRUE", "case", "init", "next"):
            continue
        assert re.search(rf"(?<![\w.]){word}(?![\w.])", text) is None, word


def test_fsm_with_reserved_names_verifies_and_agrees(nusmv_binary):
    source = _fsm(RESERVED, ["G", "X", "U"])
    result = _fsm(RESERVED, ["G", "X", "U"])
    result.transitions[2].target = "A"  # a real difference
    for other in (source, result):
        native = verify(source, other)
        smv = check(source, other)
        assert smv.verdicts() == native.verdicts()
    assert not check(source, result).equivalent


def _leaf(name: str, kind: NodeKind = NodeKind.ACTION) -> BTNode:
    return BTNode(name, kind, name=name)


@pytest.mark.parametrize("node_type", ["Parallel", "Repeat", "RunOnce", "ParallelAll"])
def test_unencodable_nodes_are_rejected_with_the_node_named(node_type):
    attrs = {"num_cycles": "2"} if node_type == "Repeat" else {}
    kind = NodeKind.DECORATOR if node_type in ("Repeat", "RunOnce") else NodeKind.CONTROL
    kids = (
        [_leaf("a")] if kind is NodeKind.DECORATOR else [_leaf("a", NodeKind.CONDITION), _leaf("b")]
    )
    doc = BTDocument.single(BTNode(node_type, kind, name="N", attrs=attrs, children=kids))
    with pytest.raises(UnsupportedError, match=node_type):
        build_model(doc, doc)


def test_counterexample_replays_to_a_difference(nusmv_binary):
    """The trace NuSMV gives for a failing property, replayed on the native machines,
    really shows the two models differing at its last step."""
    root = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[
            _leaf("a", NodeKind.CONDITION),
            BTNode("Fallback", NodeKind.CONTROL, children=[_leaf("b"), _leaf("c")]),
        ],
    )
    source = BTDocument.single(root)
    mutated = BTDocument.single(
        BTNode(
            "Sequence",
            NodeKind.CONTROL,
            children=[
                _leaf("a", NodeKind.CONDITION),
                BTNode("Sequence", NodeKind.CONTROL, children=[_leaf("b"), _leaf("c")]),
            ],
        )
    )
    report = check(source, mutated)
    failing = [p for p in report.properties.values() if not p.holds]
    assert failing
    trace = next(p.counterexample for p in failing if p.name == "completeness")
    assert trace and trace[0].input is None
    inputs = [step.input for step in trace[1:]]
    src, res, _mode = machines_for(source, mutated)
    assert replay(src, res, inputs).differs
    assert trace[-1].source_outputs != trace[-1].result_outputs
