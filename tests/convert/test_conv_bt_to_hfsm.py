"""BT -> HFSM: depth compression, conversion units, and equivalence on the paper's robot BT."""

from __future__ import annotations

import pytest

from fsmbt.convert import convert
from fsmbt.convert.compress import compress
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.model.flatten import flatten
from support.conv_helpers import check, paper_robot_bt


def _leaf(name: str, kind: NodeKind = NodeKind.ACTION) -> BTNode:
    return BTNode(type=name, kind=kind)


def _ctl(kind: str, *children: BTNode, node_kind: NodeKind = NodeKind.CONTROL) -> BTNode:
    return BTNode(type=kind, kind=node_kind, children=list(children))


def _depth(node: BTNode) -> int:  # small trees only
    return 1 + max((_depth(c) for c in node.children), default=0)


def _unit_starts(node: BTNode, level: int = 0) -> int:
    """Control nodes at even distance from the root: each heads a unit (no decorators here)."""
    own = 1 if node.kind is NodeKind.CONTROL and level % 2 == 0 else 0
    return own + sum(_unit_starts(c, level + 1) for c in node.children)


def test_robot_bt_units_depths_and_equivalence() -> None:
    doc = paper_robot_bt()
    result = convert(doc)
    root = doc.main.root
    assert result.stats["depth_before"] == _depth(root) == 7
    assert result.stats["depth_after"] == 7  # no Sequence in Sequence / Fallback in Fallback
    assert result.stats["k"] == _unit_starts(root) == 3
    hfsm = result.model
    composites = [path for path, _m, s in hfsm.walk() if s.is_composite]
    assert len(composites) == 2
    top_leaves = {s.action for s in hfsm.states.values() if s.is_atomic and not s.final}
    assert top_leaves == {
        "BatteryBelow",
        "Recharge",
        "Cube2inDelivery",
        "RobotAtInspection",
        "Dock",
    }
    assert {s.name for s in hfsm.states.values() if s.final} == {"SUCCESS", "FAILURE"}
    flat = flatten(hfsm)
    assert flat.states[flat.initial].action == "BatteryBelow"
    report = check(doc, hfsm)
    assert report.equivalent, report.to_dict()


def test_depth_compression_merges_only_same_plain_type() -> None:
    inner = _ctl("Sequence", _leaf("b"), _ctl("Sequence", _leaf("c"), _leaf("d")))
    root = _ctl("Sequence", _leaf("a"), inner, _leaf("e"))
    result = compress(root)
    assert [c.type for c in result.root.children] == ["a", "b", "c", "d", "e"]
    assert (result.depth_before, result.depth_after, result.merged) == (4, 2, 2)
    reactive = _ctl("ReactiveSequence", _leaf("a"), _ctl("Sequence", _leaf("b"), _leaf("c")))
    kept = compress(reactive)
    assert kept.merged == 0 and kept.depth_after == 3
    fb = _ctl(
        "Fallback",
        _ctl("Fallback", _leaf("x", NodeKind.CONDITION), _leaf("y")),
        _ctl("Sequence", _leaf("z")),
    )
    assert compress(fb).merged == 1
    doc = BTDocument.single(root)
    conv = convert(doc)
    assert conv.stats["depth_before"] == 4 and conv.stats["depth_after"] == 2
    assert check(doc, conv.model).equivalent


def test_extended_nodes_and_subtrees_convert_equivalently() -> None:
    cond = lambda n: _leaf(n, NodeKind.CONDITION)  # noqa: E731
    combat = _ctl(
        "Fallback",
        _ctl(
            "Sequence",
            cond("InRange"),
            _ctl(
                "Parallel",
                _leaf("Attack"),
                _ctl("ForceSuccess", _leaf("Taunt"), node_kind=NodeKind.DECORATOR),
            ),
        ),
        BTNode(
            type="RetryUntilSuccessful",
            kind=NodeKind.DECORATOR,
            attrs={"num_attempts": "2"},
            children=[_leaf("Chase")],
        ),
    )
    combat.children[0].children[1].attrs.update({"success_count": "2", "failure_count": "1"})
    main = _ctl(
        "ReactiveFallback",
        _ctl(
            "Sequence",
            cond("HealthLow"),
            _ctl("Inverter", cond("Cornered"), node_kind=NodeKind.DECORATOR),
            _leaf("Flee"),
        ),
        _ctl(
            "ReactiveSequence",
            cond("SeeEnemy"),
            BTNode(type="SubTree", kind=NodeKind.SUBTREE, attrs={"ID": "Combat"}),
        ),
        _ctl(
            "SequenceWithMemory",
            _leaf("GoGate"),
            BTNode(
                type="Repeat",
                kind=NodeKind.DECORATOR,
                attrs={"num_cycles": "2"},
                children=[_leaf("Look")],
            ),
        ),
    )
    doc = BTDocument(
        trees={"Main": BehaviorTree("Main", main), "Combat": BehaviorTree("Combat", combat)},
        main_tree="Main",
    )
    result = convert(doc)
    assert result.stats["explored_regions"] >= 1
    assert check(doc, result.model).equivalent

    stateless = _ctl(
        "Sequence",
        _ctl("Inverter", cond("Busy"), node_kind=NodeKind.DECORATOR),
        _ctl("ForceFailure", _leaf("Work"), node_kind=NodeKind.DECORATOR),
    )
    plain = convert(BTDocument.single(stateless))
    assert plain.stats["explored_regions"] == 0, "stateless decorators stay structural"
    assert check(BTDocument.single(stateless), plain.model).equivalent


def test_missing_subtree_is_a_clear_error() -> None:
    doc = BTDocument.single(
        _ctl("Sequence", BTNode(type="SubTree", kind=NodeKind.SUBTREE, attrs={"ID": "Nowhere"}))
    )
    with pytest.raises(InputError, match="Nowhere"):
        convert(doc)


def test_leaf_label_matches_the_leaf_machine() -> None:
    from fsmbt.convert.bt_to_hfsm import leaf_label
    from fsmbt.semantics.leaf_machine import leaf_label as shared

    for node in (_leaf("Grasp"), BTNode(type="Grasp", kind=NodeKind.ACTION, name="Grasp_2")):
        assert leaf_label(node) == shared(node)


@pytest.mark.parametrize(
    "tree",
    [
        lambda: _ctl(
            "ReactiveFallback",
            _leaf("a", NodeKind.CONDITION),
            _ctl("Inverter", _leaf("b"), node_kind=NodeKind.DECORATOR),
            _leaf("c"),
        ),
        lambda: _ctl(
            "KeepRunningUntilFailure",
            _ctl("Sequence", _leaf("a", NodeKind.CONDITION), _leaf("b")),
            node_kind=NodeKind.DECORATOR,
        ),
    ],
)
def test_loop_conversion_of_explored_trees_keeps_the_root_result(tree) -> None:
    """With loop, a step that ends the tick outputs (result, first leaf); the HFSM must say
    both (a final state named after the result), not jump back to the start silently."""
    from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
    from fsmbt.verify import verify

    doc = BTDocument.single(tree())
    hfsm = bt_to_hfsm(doc, loop=True).model
    report = verify(doc, hfsm, loop=True)
    assert report.equivalent, report.verdicts()


def test_loop_step_that_cannot_be_one_state_is_refused() -> None:
    """ReactiveSequence over a SequenceWithMemory: after a failure the next tick does not start
    where the first one did, so (FAILURE, a) has no state to stand for it."""
    from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
    from fsmbt.model.errors import UnsupportedError

    doc = BTDocument.single(
        _ctl(
            "ReactiveSequence",
            _leaf("a", NodeKind.CONDITION),
            _ctl("SequenceWithMemory", _leaf("b"), _leaf("c")),
        )
    )
    with pytest.raises(UnsupportedError, match="cannot express the outputs"):
        bt_to_hfsm(doc, loop=True)
