"""BehaviorTree.CPP XML reader/writer and the safe XML parse under it."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import dumps, loads
from fsmbt.formats.btcpp.xml_format import ASSUMED_DESCRIPTION
from fsmbt.formats.xml_safe import parse_xml, root_tag
from fsmbt.limits import current as current_limits
from fsmbt.model import BTDocument, BTNode, NodeKind
from fsmbt.model.errors import InputError, UnsupportedError
from support.corpus import CORPUS


def corpus(rel: str) -> Path:
    path = CORPUS / rel
    if not path.exists():
        pytest.skip(f"corpus file {rel} not present")
    return path


def roundtrip(doc: BTDocument) -> BTDocument:
    return loads(dumps(doc, "btcpp"), "btcpp")


V4 = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="top">
      <IsReady/>
      <Fallback>
        <Door open="{door}" speed="2"/>
        <SubTree ID="Other" target="{t}"/>
      </Fallback>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Other"><AlwaysSuccess/></BehaviorTree>
  <TreeNodesModel>
    <Condition ID="IsReady"/>
    <Action ID="Door"><input_port name="open" type="bool">is it open</input_port></Action>
  </TreeNodesModel>
</root>
"""


def test_v4_compact_reads_kinds_ports_and_lines() -> None:
    doc = loads(V4, "btcpp")
    assert doc.main_tree == "Main" and list(doc.trees) == ["Main", "Other"]
    root = doc.main.root
    assert root is not None and root.type == "Sequence" and root.name == "top"
    ready, fallback = root.children
    assert (ready.type, ready.kind, ready.kind_declared) == ("IsReady", NodeKind.CONDITION, True)
    door, sub = fallback.children
    assert door.attrs == {"open": "{door}", "speed": "2"}  # order kept
    assert list(door.attrs) == ["open", "speed"]
    assert door.kind is NodeKind.ACTION and door.location is not None and door.location.line == 6
    assert sub.kind is NodeKind.SUBTREE and sub.subtree_id == "Other"
    assert doc.node_models["Door"].ports[0].description == "is it open"
    assert roundtrip(doc) == doc


def test_v3_aliases_and_explicit_groot_style_equal_compact() -> None:
    explicit = """<root main_tree_to_execute="T"><BehaviorTree ID="T">
      <Control ID="SequenceStar"><Condition ID="Ok"/><Decorator ID="RetryUntilSuccesful" num_attempts="2">
      <Action ID="Go" x="1"/></Decorator><SubTreePlus ID="S" __autoremap="1"/></Control>
      </BehaviorTree></root>"""
    doc = loads(explicit, "btcpp")
    assert doc.format_version == "3"
    root = doc.main.root
    assert root is not None and root.type == "SequenceWithMemory"
    ok, retry, sub = root.children
    assert ok.kind is NodeKind.CONDITION and retry.type == "RetryUntilSuccessful"
    assert retry.children[0].attrs == {"x": "1"} and "ID" not in retry.children[0].attrs
    # v3's SubTreePlus auto-remapping is v4's _autoremap (formats/btcpp/versions.py)
    assert sub.type == "SubTree" and sub.attrs == {"ID": "S", "_autoremap": "1"}
    again = roundtrip(doc)
    assert again.format_version == "4"
    again.format_version = "3"
    assert again == doc


def test_undeclared_types_are_assumed_and_stay_assumed() -> None:
    doc = loads(
        """<root BTCPP_format="4"><BehaviorTree ID="T">
        <Pipeline><Leaf/><Wrap><Leaf/></Wrap></Pipeline></BehaviorTree></root>""",
        "btcpp",
    )
    root = doc.main.root
    assert root is not None
    assert (root.kind, root.kind_declared) == (NodeKind.CONTROL, False)
    leaf, wrap = root.children
    assert (leaf.kind, leaf.kind_declared) == (NodeKind.ACTION, False)
    assert (wrap.kind, wrap.kind_declared) == (NodeKind.DECORATOR, False)
    text = dumps(doc, "btcpp")
    assert ASSUMED_DESCRIPTION in text and 'ID="Pipeline"' in text  # Groot2 still learns the type
    assert loads(text, "btcpp") == doc


def test_writer_declares_custom_types_for_groot() -> None:
    leaf = BTNode("Grab", NodeKind.ACTION, attrs={"obj": "cup"})
    cond = BTNode("Seen", NodeKind.CONDITION)
    doc = BTDocument.single(BTNode("Sequence", NodeKind.CONTROL, children=[cond, leaf]))
    text = dumps(doc, "btcpp")
    assert 'BTCPP_format="4"' in text and 'main_tree_to_execute="MainTree"' in text
    back = loads(text, "btcpp")
    assert back.node_models["Grab"].kind is NodeKind.ACTION
    assert [p.name for p in back.node_models["Grab"].ports] == ["obj"]
    assert back.node_models["Seen"].kind is NodeKind.CONDITION
    assert back.trees == doc.trees
    assert roundtrip(back) == back  # stable after the first write


def test_includes_resolve_relative_and_are_written_inline() -> None:
    path = corpus("bt/btcpp/trees/parent_include_child_include_parent.xml")
    doc = api.load(path).model
    assert set(doc.trees) == {
        "ParentIncludeChildIncludeParent",
        "ChildIncludeParent",
        "ParentNoInclude",
    }
    assert len(doc.includes) == 2
    text = dumps(doc, "btcpp")
    assert "<include" not in text
    back = loads(text, "btcpp")
    assert back.trees == doc.trees and back.includes == []


def test_include_cycle_is_reported(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    (tmp_path / "a.xml").write_text(
        '<root BTCPP_format="4"><include path="sub/b.xml"/>'
        '<BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree></root>'
    )
    (tmp_path / "sub" / "b.xml").write_text(
        '<root BTCPP_format="4"><include path="../a.xml"/>'
        '<BehaviorTree ID="B"><AlwaysSuccess/></BehaviorTree></root>'
    )
    with pytest.raises(InputError, match="include cycle"):
        api.load(tmp_path / "a.xml")


def test_missing_include_names_the_line(tmp_path: Path) -> None:
    (tmp_path / "a.xml").write_text(
        '<root BTCPP_format="4">\n<include path="nope.xml"/>\n'
        '<BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree></root>'
    )
    with pytest.raises(InputError) as info:
        api.load(tmp_path / "a.xml")
    assert info.value.location is not None and info.value.location.line == 2


def test_external_node_models_option_decides_leaf_kinds() -> None:
    models = corpus("bt/nav2/models/nav2_tree_nodes.xml")
    tree = corpus("bt/nav2/navigate_w_replanning_time.xml")
    plain = api.load(tree, options={"no_profiles": True}).model
    informed = api.load(tree, options={"node_models": [str(models)], "no_profiles": True}).model
    undeclared = [n for _, n in plain.nodes() if not n.kind_declared]
    assert undeclared, "without Nav2's model file some kinds are assumed"
    assert all(n.kind_declared for _, n in informed.nodes())
    assert any(
        n.kind is NodeKind.CONTROL and n.type == "PipelineSequence" for _, n in informed.nodes()
    )
    assert roundtrip(informed) == informed


def test_bad_structure_errors_name_line() -> None:
    with pytest.raises(InputError, match="exactly one") as info:
        loads(
            '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n<A/><B/></BehaviorTree></root>',
            "btcpp",
        )
    assert info.value.location.line == 2
    with pytest.raises(InputError, match="duplicate BehaviorTree"):
        loads(
            '<root><BehaviorTree ID="T"><A/></BehaviorTree><BehaviorTree ID="T"><A/></BehaviorTree></root>',
            "btcpp",
        )
    with pytest.raises(UnsupportedError, match="BTCPP_format"):
        loads('<root BTCPP_format="9"/>', "btcpp")
    with pytest.raises(InputError, match="without ID"):
        loads('<root><BehaviorTree ID="T"><Action/></BehaviorTree></root>', "btcpp")


# -- the safe parse --------------------------------------------------------------------------
def test_malformed_xml_names_line_column_and_cause() -> None:
    with pytest.raises(InputError) as info:
        parse_xml("<root>\n  <a>\n</root>", "f.xml")
    err = info.value
    assert err.location is not None and err.location.file == "f.xml"
    assert err.location.line == 3 and err.location.column is not None
    assert "malformed XML" in str(err) and "mismatch" in str(err)


@pytest.mark.parametrize(
    "doctype",
    [
        '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>',
        '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>',
    ],
)
def test_entity_declarations_are_refused(doctype: str) -> None:
    start = time.monotonic()
    with pytest.raises(InputError, match="entities"):
        parse_xml(f'{doctype}<root BTCPP_format="4">&b;</root>', "bomb.xml")
    assert time.monotonic() - start < 2


def test_deep_documents_read_and_deeper_ones_fail_fast() -> None:
    depth = 5000  # beyond libxml2's 2 048 levels: goes through the expat path
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        + "<Inverter>" * depth
        + "<Leaf/>"
        + "</Inverter>" * depth
        + "</BehaviorTree></root>"
    )
    doc = loads(text, "btcpp")
    assert sum(1 for _ in doc.nodes()) == depth + 1
    # BTNode's dataclass ``==`` recurses, so deep trees are compared node by node, in order.
    again = roundtrip(doc)
    assert [_shallow(n) for _, n in again.nodes()] == [_shallow(n) for _, n in doc.nodes()]
    start = time.monotonic()
    with pytest.raises(InputError, match=f"deeper than {current_limits().max_xml_depth}"):
        parse_xml("<a>" * 100_000 + "</a>" * 100_000, "deep.xml")
    assert time.monotonic() - start < 2


def _shallow(node: BTNode) -> tuple[object, ...]:
    return (node.type, node.kind, node.name, node.attrs, len(node.children), node.kind_declared)


def test_root_tag_sniffing() -> None:
    assert root_tag('<?xml version="1.0"?>\n<!-- c -->\n<root BTCPP_format="4"/>') == "root"
    assert root_tag("<sc:scxml xmlns:sc='x'/>") == "scxml"
    assert root_tag("not xml") is None
