"""BehaviorTree.CPP v3 XML (``btcpp3``, write only): files for ROS 2 Humble's Nav2, which runs
BehaviorTree.CPP 3.8 (docs/formats/btcpp.md, "Version 3").

The document is written as v4 is (``xml_format.document_root``: compact style, main tree
named, custom types declared) and then said in v3's words (``fsmbt.formats.btcpp.versions``):
``BTCPP_format="3"``, ``SequenceWithMemory`` as ``SequenceStar``, Parallel's ``success_count``
/ ``failure_count`` as ``success_threshold`` / ``failure_threshold`` (both always written:
3.8 requires the first), a SubTree as ``<SubTree>`` / ``<SubTree __shared_blackboard="true">``
/ ``<SubTreePlus>`` (``versions.v3_subtree``).

What v3 cannot say (``prepare_v3``, the rule of docs/formats/btcpp.md):
- refused (``UnsupportedError`` naming the node, its tree and line), because the tree would
  behave otherwise or not load: a v4-only built-in node (``Script``, ``RunOnce``,
  ``AsyncSequence``, ``LoopInt``...), a pre-condition (``_skipIf``, ``_failureIf``,
  ``_successIf``, ``_while``: they decide whether a node runs), a post-condition writing an
  entry a ``Switch`` reads (the dispatch form's ``_onSuccess``: it steers the tree), a
  ``SequenceWithMemory``,
  ``Repeat`` or ``RetryUntilSuccessful`` under an ancestor that ticks or halts between two
  ticks (reactive controls, Parallel, PipelineSequence, WhileDoElse, Timeout: 3.8's nodes
  go on within one tick, and SequenceStar restarts when halted; ``_GRANULAR``); under another
  project's or a user's control or decorator, that difference is a named loss;
- written otherwise, named: a ``WhileDoElse`` without an else branch (3.8 requires three
  children) gets ``<AlwaysFailure/>``, which v4's rule without one returns the same;
- dropped and named as a loss, located: other post-conditions (``_onSuccess``...: they only
  write the blackboard, which no control node then reads, docs/semantics.md section 2), other
  v4 ``_`` attributes (Groot2's ``_uid``...; 3.8 would refuse them as unknown ports), and a
  ``{@key}`` / ``{=}`` port value is kept but named (v3 reads it as a key of that name).

``fsmbt translate --to btcpp3`` reads the file back with the ``btcpp`` reader (v3 names mean
their v4 counterparts, docs/semantics.md section 1) and proves it equivalent to the source.
Costs: one copy of the document and one pass over its nodes and elements, O(n).
"""

from __future__ import annotations

import copy
import re

from lxml import etree

from fsmbt.formats.btcpp import v3_ticks, versions
from fsmbt.formats.btcpp.xml_format import document_root, serialize
from fsmbt.formats.registry import Format, register
from fsmbt.model import Model
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind, builtin_spec
from fsmbt.model.errors import FsmbtError, InputError, UnsupportedError

#: What the format cannot hold (``fsmbt formats``).
CANNOT_HOLD = "v4-only nodes (Script, RunOnce, AsyncSequence, Loop*...), pre-conditions"


def _v4_only(node: BTNode) -> bool:
    """A BehaviorTree.CPP built-in that 3.8 does not have."""
    if node.kind is NodeKind.SUBTREE:
        return False
    spec = builtin_spec(node.type)
    return (
        spec is not None
        and spec.library == "BehaviorTree.CPP"
        and versions.v3_name(spec.name) is None
    )


def prepare_v3(model: Model) -> tuple[BTDocument, list[str]]:
    """A copy of ``model`` that v3 can hold, and what was dropped or changes meaning (one
    located line each).

    Raises:
        InputError: ``model`` is not a behavior tree.
        UnsupportedError: a v4-only node, a pre-condition, or a node 3.8 ticks otherwise
            under its ancestor (``v3_ticks``): the first one, located; the message counts the
            others.
    """
    if not isinstance(model, BTDocument):
        raise InputError("BehaviorTree.CPP XML holds a behavior tree, not a state machine")
    doc = copy.deepcopy(model)
    doc.format_version = "3"
    losses: list[str] = []
    refused: list[tuple[str, BTNode, str]] = []
    # entries a Switch reads: a post-condition writing one steers the tree (the dispatch form)
    switched = {
        m.group(1)
        for _t, n in doc.nodes()
        if n.type.startswith("Switch")
        and (m := re.fullmatch(r"\{([A-Za-z_][A-Za-z0-9_]*)\}", n.attrs.get("variable", "")))
    }
    for tree_id, node in doc.nodes():
        steering = [
            k
            for k in versions.POST_CONDITIONS
            if k in node.attrs
            and any(re.search(rf"\b{re.escape(key)}\s*:?=", node.attrs[k]) for key in switched)
        ]
        if steering:
            refused.append(
                (
                    tree_id,
                    node,
                    f"the post-condition {steering[0]} writes a blackboard entry a Switch reads; "
                    "version 3 has no post-conditions",
                )
            )
            continue
        if _v4_only(node):
            refused.append(
                (tree_id, node, f"{node.type} is a BehaviorTree.CPP v4 node; version 3 has none")
            )
            continue
        pre = [k for k in node.attrs if k in versions.PRE_CONDITIONS]
        if pre:
            refused.append(
                (
                    tree_id,
                    node,
                    f'the pre-condition {pre[0]}="{node.attrs[pre[0]]}" decides whether the '
                    "node runs; version 3 has no pre-conditions",
                )
            )
            continue
        for key in list(node.attrs):
            value = node.attrs[key]
            keep = key in versions.V3_RESERVED or (
                key == versions.AUTOREMAP and node.kind is NodeKind.SUBTREE
            )
            if key.startswith("_") and not keep:
                del node.attrs[key]
                why = (
                    "v3 has no post-conditions (it wrote the blackboard only)"
                    if key in versions.POST_CONDITIONS
                    else "v3 would refuse it as an unknown port"
                )
                losses.append(f'{v3_ticks.where(tree_id, node)}: {key}="{value}" dropped: {why}')
            elif value.startswith("{@") or value == "{=}":
                losses.append(
                    f'{v3_ticks.where(tree_id, node)}: {key}="{value}" is v4 blackboard syntax; '
                    f"v3 reads it as the key '{value[1:-1]}'"
                )
        for port, default in versions.V3_REQUIRED_DEFAULTS.get(node.type, {}).items():
            node.attrs.setdefault(port, default)
        if node.type == "WhileDoElse" and len(node.children) == 2:
            # 3.8 needs the else branch; v4 returns FAILURE without one, as AlwaysFailure does
            node.children.append(BTNode("AlwaysFailure", NodeKind.ACTION))
            losses.append(
                f"{v3_ticks.where(tree_id, node)}: no else branch, which v3's WhileDoElse requires: "
                "written as <AlwaysFailure/> (v4 returns FAILURE without one, the same)"
            )
    granular, granular_losses = v3_ticks.granularity(doc)
    refused.extend(granular)
    losses.extend(granular_losses)
    if refused:
        tree_id, node, why = refused[0]
        more = f" ({len(refused) - 1} more such node(s))" if len(refused) > 1 else ""
        hint = (
            " (an FSM converted to a BT: --style lebt writes no Script and no post-condition)"
            if node.type == "Script" or any(k in node.attrs for k in versions.POST_CONDITIONS)
            else ""
        )
        raise UnsupportedError(
            f"{v3_ticks.where(tree_id, node)}: {why}{more}; write v4 (--to btcpp) or replace it{hint}",
            location=node.location,
            element=node.label,
        )
    return doc, losses


def v3_holds(model: BTDocument) -> bool:
    """Whether ``prepare_v3(model)`` succeeds (the web page offers the v3 download only then).

    A v4-only node or a pre-condition is refused whatever else the document holds, so one
    read-only pass over the nodes answers for the trees that have one (the dispatch form's
    ``Script`` nodes) without ``prepare_v3``'s copy of the document; any other is answered by
    ``prepare_v3`` itself. Costs: O(n), plus ``prepare_v3``'s copy when no node decides it.
    """
    for _tree_id, node in model.nodes():
        if _v4_only(node) or any(key in versions.PRE_CONDITIONS for key in node.attrs):
            return False
    try:
        prepare_v3(model)
    except FsmbtError:
        return False
    return True


def _v3_element(element: etree._Element) -> None:
    """Say one written node element in v3's words (tag and attributes, order kept)."""
    tag = str(element.tag)
    attrs = dict(element.attrib)
    if tag == "SubTree":
        name = {"name": attrs.pop("name")} if "name" in attrs else {}
        tag, rest = versions.v3_subtree(attrs)
        attrs = {**name, **rest}
    else:
        ports = versions.V4_TO_V3_PORTS.get(tag, {})
        attrs = {ports.get(k, k): v for k, v in attrs.items()}
        tag = versions.V4_TO_V3_NAMES.get(tag, tag)
    element.tag = tag
    element.attrib.clear()
    for key, value in attrs.items():
        element.set(key, value)


def write_btcpp3(model: Model) -> str:
    """Write a BehaviorTree.CPP v3 file (``prepare_v3`` first: refuses what v3 cannot hold)."""
    doc, _losses = prepare_v3(model)
    root, depth = document_root(doc)
    root.set("BTCPP_format", "3")
    for tree in root:
        if tree.tag != "BehaviorTree":
            continue
        for element in tree.iter():  # lxml iterates: no recursion on deep trees
            if element is not tree and isinstance(element.tag, str):
                _v3_element(element)
    return serialize(root, depth)


register(
    Format(
        "btcpp3",
        (),
        frozenset({"bt"}),
        "BehaviorTree.CPP v3 XML (write only: ROS 2 Humble's Nav2; --to btcpp3)",
        None,
        write_btcpp3,
        cannot_hold=CANNOT_HOLD,
        read_back_as="btcpp",
    )
)

__all__ = ["CANNOT_HOLD", "prepare_v3", "write_btcpp3"]
