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


def _dec(kind: str, child: BTNode, **attrs: str) -> BTNode:
    return BTNode(kind, NodeKind.DECORATOR, name=kind, attrs=attrs, children=[child])


def _internal(kind: str = "AlwaysSuccess") -> BTNode:
    return BTNode(kind, NodeKind.ACTION)


@pytest.mark.parametrize(
    ("root", "loop", "reason"),
    [
        # SKIPPED is encoded under the sequences, reactive controls, status maps and SubTree
        # only: under any other parent the parent is named
        (
            _dec("Repeat", _dec("RunOnce", _leaf("a")), num_cycles="2"),
            False,
            r"SKIPPED under Repeat",
        ),
        (_dec("RunOnce", _leaf("a")), True, "livelock"),
        # ticks that end without any leaf: the native leaf machine reports LIVELOCK
        (_dec("Repeat", _internal(), num_cycles="-1"), False, "livelock"),
        (
            _dec("RetryUntilSuccessful", _internal("AlwaysFailure"), num_attempts="-1"),
            False,
            "livelock",
        ),
        (_dec("RunOnce", _leaf("a"), then_skip="false"), True, "livelock"),
        (_dec("Repeat", _leaf("a"), num_cycles="0"), True, "livelock"),
    ],
)
def test_refused_trees_name_the_cause(root, loop, reason):
    doc = BTDocument.single(root)
    with pytest.raises(UnsupportedError, match=reason) as caught:
        build_model(doc, doc, loop=loop)
    assert "native" in str(caught.value)  # the way out is named


def _smv_vars(root: BTNode, *, loop: bool = False) -> dict[str, str]:
    doc = BTDocument.single(root)
    text = build_model(doc, doc, loop=loop)[0].split("MODULE result")[0]
    text = text.split("\nVAR\n")[1].split("\nDEFINE\n")[0]
    return dict(re.findall(r"^\s+(\w+) : ([^;]+);", text, flags=re.M))


def test_loop_counters_are_bounded_and_absent_for_endless_loops():
    finite = _smv_vars(_dec("Repeat", _leaf("a"), num_cycles="4"))
    assert finite["lc_0"] == "0..3" and "prev_0" in finite
    retry = _smv_vars(_dec("RetryUntilSuccessful", _leaf("a"), num_attempts="3"))
    assert retry["lc_0"] == "0..2"
    endless = _smv_vars(_dec("Repeat", _leaf("a"), num_cycles="-1"))
    assert not any(name.startswith("lc_") for name in endless) and "prev_0" in endless


def test_parallel_memory_is_read_from_the_children_statuses():
    """No completed-set or counter variable: the DEFINEs count the children's statuses."""
    par = BTNode(
        "Parallel",
        NodeKind.CONTROL,
        attrs={"success_count": "2", "failure_count": "1"},
        children=[_leaf("a"), _leaf("b"), _leaf("c")],
    )
    doc = BTDocument.single(par)
    text = build_model(doc, doc)[0].split("MODULE result")[0]
    assert "psc_0 := (toint(st_1 = zS) + toint(st_2 = zS) + toint(st_3 = zS))" in text
    assert set(_smv_vars(par)) == {"cur", "res", "lidx", "wake", "bres"} | {
        f"st_{i}" for i in range(4)
    }


def test_run_once_result_survives_a_halt():
    """RunOnce's memory is not reset by the halt closure (v4: the node stays 'already run')."""
    root = BTNode(
        "ReactiveSequence",
        NodeKind.CONTROL,
        children=[_leaf("c", NodeKind.CONDITION), _dec("RunOnce", _leaf("a"), then_skip="false")],
    )
    doc = BTDocument.single(root)
    text = build_model(doc, doc)[0].split("MODULE result")[0]
    rules = text.split("next(ro_2) := case")[1].split("esac;")[0]
    assert "hlt_2" not in rules and "res = zS : 1" in rules.replace("case ", "")


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
