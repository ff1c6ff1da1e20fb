"""The node registry is the one home of node-kind knowledge (docs/semantics.md "Node registry").

Two kinds of test: every consumer's node set is the registry's (so nothing restates a set), and
a kind added with ``register()`` is read, validated and ticked by the real pipeline pieces.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable
from pathlib import Path

import pytest

import fsmbt
from fsmbt.convert import bt_to_hfsm, compress
from fsmbt.convert.baselines import common as baseline_common
from fsmbt.formats.btcpp.xml_format import read_btcpp
from fsmbt.formats.registry import ReadContext
from fsmbt.llm import structural
from fsmbt.model import bt_nodes
from fsmbt.model import nodes as model_nodes
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.kinds import NodeKind
from fsmbt.model.validate import validate
from fsmbt.semantics import bt_interpreter, leaf_fast, nodes
from fsmbt.semantics.bt_interpreter import BTRunner
from fsmbt.semantics.families import registry as family_registry
from fsmbt.semantics.status import LeafOutcome, MachineStatus, NodeStatus, RootResult
from fsmbt.verify.nusmv import encode_bt


def _names(pred: Callable[[nodes.NodeSemantics], object]) -> frozenset[str]:
    return frozenset(n.name for n in nodes.all_nodes() if pred(n))


def test_sem_registry_every_consumer_set_is_the_registry_set() -> None:
    tables = nodes.runtime_tables()
    assert tables.controls == _names(lambda n: n.kind is NodeKind.CONTROL and n.handler)
    assert tables.decorators == _names(lambda n: n.kind is NodeKind.DECORATOR and n.handler)
    plain = _names(lambda n: n.is_plain)
    assert plain == {"Sequence", "Fallback"}  # the paper's two controls
    assert leaf_fast.PLAIN_CONTROLS is nodes.PLAIN_CONTROLS == plain
    assert baseline_common.PLAIN_CONTROLS is nodes.PLAIN_CONTROLS
    assert structural.PAPER_CONTROLS is nodes.PLAIN_CONTROLS
    assert bt_to_hfsm.PLAIN_CONTROLS is nodes.PLAIN_CONTROLS
    assert compress.MERGEABLE_CONTROLS == _names(lambda n: n.mergeable) == plain
    assert (
        baseline_common.REACTIVE_CONTROLS
        == _names(lambda n: n.reactive)
        == {"ReactiveSequence", "ReactiveFallback"}
    )
    assert (
        bt_to_hfsm.RESULT_MAP_DECORATORS
        == _names(lambda n: n.result_map is not None)
        == {"Inverter", "ForceSuccess", "ForceFailure"}
    )
    assert encode_bt.SUPPORTED == _names(lambda n: n.nusmv is not None)
    assert set(encode_bt.NOT_ENCODED) == _names(lambda n: n.nusmv_refusal is not None)
    assert not set(encode_bt.SUPPORTED) & set(encode_bt.NOT_ENCODED)
    assert set(bt_nodes.BUILTIN_NODES) == _names(lambda n: True)
    assert bt_nodes.V3_ALIASES == {
        "SequenceStar": "SequenceWithMemory",
        "RetryUntilSuccesful": "RetryUntilSuccessful",
        "SubTreePlus": "SubTree",
    }


def test_sem_registry_entries_are_consistent() -> None:
    for node in nodes.all_nodes():
        assert node.tick, node.name
        if node.handler is None and node.internal_result is None:
            # refused by the interpreter (internal leaves are run by its leaf rule)
            assert node.nusmv is None, node.name
        if node.nusmv is None:
            assert node.nusmv_refusal, f"{node.name}: say why NuSMV does not encode it"
        if node.time_based or node.blackboard_based:
            # ticked only as an abstraction the user enables (--abstract), never by default
            assert node.handler is None or node.requires in nodes.ABSTRACTIONS, node.name
        if node.requires is not None:
            assert node.abstraction and node.abstraction.startswith(node.name), node.name
        if node.default_memory is not None:
            assert len(node.default_memory) == len(node.memory), node.name
        if node.kind is NodeKind.DECORATOR:
            assert node.children == 1, node.name
        if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
            assert node.children == 0, node.name
        if node.handler is not None and node.kind is not NodeKind.CONDITION:
            # a family has the tick rule it names (a condition is an environment leaf)
            assert family_registry.rule(node.handler) is not None, node.name


def test_sem_registry_refused_kinds_keep_their_reasons() -> None:
    doc = BTDocument.single(
        BTNode(
            "Delay",
            NodeKind.DECORATOR,
            attrs={"delay_msec": "5"},
            children=[BTNode("A", NodeKind.ACTION)],
        )
    )
    with pytest.raises(UnsupportedError, match="time-based node"):
        bt_interpreter.CompiledTree(doc)


def test_sem_registry_rejects_a_duplicate_name() -> None:
    with pytest.raises(ValueError, match="already registered"):
        nodes.register(dataclasses.replace(model_nodes.controls.SEQUENCE))
    with pytest.raises(ValueError, match="already registered"):
        nodes.register(
            dataclasses.replace(model_nodes.controls.FALLBACK, name="X", aliases=("SequenceStar",))
        )


MY_XML = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <{kind}>
      <Action ID="a"/>
      <Action ID="b"/>
    </{kind}>
  </BehaviorTree>
</root>"""


def _run(doc: BTDocument, plan: dict[str, list[str]], ticks: int) -> list[tuple[list[str], str]]:
    remaining = {k: list(v) for k, v in plan.items()}
    runner = BTRunner(doc, lambda node, path: remaining[node.label].pop(0))
    return [
        ([leaf[0] for leaf in r.leaves], r.result)
        for r in (runner.tick_once() for _ in range(ticks))
    ]


def test_sem_registry_a_registered_kind_is_read_validated_and_ticked() -> None:
    """One entry is all a new kind needs: the reader knows it is a control, validate knows its
    semantics, the interpreter ticks it by the rule the entry names."""
    mine = dataclasses.replace(
        model_nodes.controls.SEQUENCE,
        name="MySequence",
        aliases=(),
        tick="a Sequence under another name (test)",
    )
    plan = {"a": ["success", "success"], "b": ["running", "failure", "success"]}
    with nodes.registered(mine):
        doc = read_btcpp(MY_XML.format(kind="MySequence"), ReadContext())
        root = doc.main.root
        assert root is not None and root.kind is NodeKind.CONTROL and root.kind_declared
        assert not [i for i in validate(doc) if "no known semantics" in i.message]
        assert "MySequence" in nodes.runtime_tables().controls
        ours = _run(doc, plan, 3)
    reference = _run(read_btcpp(MY_XML.format(kind="Sequence"), ReadContext()), plan, 3)
    assert (
        ours == reference == [(["a", "b"], "RUNNING"), (["b"], "FAILURE"), (["a", "b"], "SUCCESS")]
    )
    # unregistered again: an unknown control, refused by the interpreter
    assert nodes.node_semantics("MySequence") is None
    assert "MySequence" not in nodes.runtime_tables().controls
    stray = BTDocument.single(
        BTNode("MySequence", NodeKind.CONTROL, children=[BTNode("A", NodeKind.ACTION)])
    )
    with pytest.raises(UnsupportedError, match="custom or unknown semantics"):
        bt_interpreter.CompiledTree(stray)


def test_sem_registry_rewired_follows_the_result_map() -> None:
    assert nodes.rewired("Inverter", "ok", "ko") == ("ko", "ok")
    assert nodes.rewired("ForceSuccess", "ok", "ko") == ("ok", "ok")
    assert nodes.rewired("ForceFailure", "ok", "ko") == ("ko", "ko")
    with pytest.raises(ValueError):
        nodes.rewired("Repeat", "ok", "ko")


def test_sem_statuses_keep_their_old_values() -> None:
    assert [int(s) for s in NodeStatus] == [0, 1, 2, 3, 4]
    assert bt_interpreter.STATUS_NAMES == ("IDLE", "RUNNING", "SUCCESS", "FAILURE", "SKIPPED")
    assert (
        bt_interpreter.IDLE,
        bt_interpreter.RUNNING,
        bt_interpreter.SUCCESS,
        bt_interpreter.FAILURE,
        bt_interpreter.SKIPPED,
    ) == tuple(NodeStatus)
    assert bt_interpreter.OUTCOME_TO_STATUS == {"success": 2, "failure": 3, "running": 1}
    assert [o.value for o in LeafOutcome] == ["success", "failure", "running"]
    assert [m.value for m in MachineStatus] == ["running", "final"]
    assert [r.value for r in RootResult] == ["SUCCESS", "FAILURE"]
    assert bt_to_hfsm.ROOT_RESULTS == ("SUCCESS", "FAILURE")


_KIND = r'"(?:Sequence|Fallback|ReactiveSequence|ReactiveFallback|Inverter|ForceSuccess)"'
_SET_LITERAL = re.compile(r"(?:frozenset\(\{|=\s*\{)[^}\n]*" + _KIND)


def test_sem_no_module_restates_a_node_set() -> None:
    """A set literal of built-in kind names outside the registry would be a second home."""
    src = Path(fsmbt.__file__).parent
    offenders = []
    for path in sorted(src.rglob("*.py")):
        rel = path.relative_to(src).as_posix()
        if rel.startswith("model/nodes/") or rel.startswith("semantics/engines/"):
            continue  # the registry itself; engine adapters map kinds to another library's
        if rel.startswith("formats/pysm/"):
            continue  # SMACH's own container classes (its Sequence is not a BT node kind)
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if _SET_LITERAL.search(line):
                offenders.append(f"{rel}:{number}: {line.strip()}")
    assert offenders == []
