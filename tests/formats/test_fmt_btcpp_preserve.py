"""A user's BehaviorTree.CPP file translated v3 -> v4 or v4 -> v4 keeps its comments, names,
ports, attribute order and every byte nothing changed (docs/formats/btcpp.md, "The user's file
kept"; ``fsmbt.formats.btcpp.preserve``), and the result still reads back equivalent."""

from __future__ import annotations

import difflib
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import dumps, loads
from fsmbt.formats.btcpp.preserve import edited_source
from fsmbt.formats.btcpp.xml_format import ASSUMED_DESCRIPTION
from fsmbt.model.bt import BTDocument
from support.corpus import CORPUS

V3 = """<?xml version="1.0"?>
<!-- the robot's mission, v3 -->
<root main_tree_to_execute = "Main" >
    <BehaviorTree ID="Main">
        <SequenceStar name='mission'>   <!-- keeps its place -->
            <Parallel failure_threshold='2'  success_threshold="1" >
                <MoveTo goal="{goal}"  speed = "0.5" />
                <SubTree ID="Dock" target="dock_pose" __shared_blackboard="false"/>
            </Parallel>
            <SubTree ID="Dock" __shared_blackboard="true" />
        </SequenceStar>
    </BehaviorTree>
    <BehaviorTree ID="Dock"><AlwaysSuccess/></BehaviorTree>
</root>
"""


def _changed_lines(before: str, after: str) -> tuple[list[str], list[str]]:
    diff = list(difflib.ndiff(before.splitlines(), after.splitlines()))
    return [d[2:] for d in diff if d.startswith("- ")], [d[2:] for d in diff if d.startswith("+ ")]


def _translate(tmp_path: Path, text: str, name: str = "tree.xml") -> str:
    source = tmp_path / name
    source.write_bytes(text.encode("utf-8"))
    _loaded, result, report = api.translate(source, to="btcpp")
    assert report is not None and report.equivalent
    return result.text


def test_v3_to_v4_edits_only_what_v4_says_otherwise(tmp_path: Path) -> None:
    text = _translate(tmp_path, V3)
    removed, added = _changed_lines(V3, text)
    assert removed == [
        '<root main_tree_to_execute = "Main" >',
        "        <SequenceStar name='mission'>   <!-- keeps its place -->",
        "            <Parallel failure_threshold='2'  success_threshold=\"1\" >",
        '                <SubTree ID="Dock" target="dock_pose" __shared_blackboard="false"/>',
        '            <SubTree ID="Dock" __shared_blackboard="true" />',
        "        </SequenceStar>",
    ]
    assert added[:6] == [
        '<root BTCPP_format="4" main_tree_to_execute = "Main" >',
        "        <SequenceWithMemory name='mission'>   <!-- keeps its place -->",
        "            <Parallel failure_count='2'  success_count=\"1\" >",
        '                <SubTree ID="Dock" target="{dock_pose}"/>',
        '            <SubTree ID="Dock" _autoremap="true" />',
        "        </SequenceWithMemory>",
    ]
    # the one undeclared leaf gets its declaration, indented like the trees, before </root>
    assert added[6:] == [
        "    <TreeNodesModel>",
        '        <Action ID="MoveTo">',
        '          <input_port name="goal"/>',
        '          <input_port name="speed"/>',
        f"          <description>{ASSUMED_DESCRIPTION}</description>",
        "        </Action>",
        "    </TreeNodesModel>",
    ]
    assert text.startswith('<?xml version="1.0"?>\n<!-- the robot\'s mission, v3 -->\n')
    # it says what the writer's file says
    assert loads(text, "btcpp") == loads(dumps(loads(V3, "btcpp"), "btcpp"), "btcpp")


def test_a_v4_file_that_lacks_nothing_is_kept_byte_for_byte(tmp_path: Path) -> None:
    v4 = (
        '<root BTCPP_format="4">\r\n  <!-- CRLF line ends, single quotes -->\r\n'
        "  <BehaviorTree ID='T'>\r\n    <Fallback>\r\n      <IsOk  level = '3' />\r\n"
        "      <AlwaysFailure/>\r\n    </Fallback>\r\n  </BehaviorTree>\r\n"
        "  <TreeNodesModel><Condition ID='IsOk'><input_port name='level'/></Condition>"
        "</TreeNodesModel>\r\n</root>\r\n"
    )
    assert _translate(tmp_path, v4) == v4


def test_a_v4_file_gains_only_its_missing_declarations(tmp_path: Path) -> None:
    v4 = """<root BTCPP_format="4" main_tree_to_execute="T">
  <BehaviorTree ID="T">
    <!-- two leaves, one declared -->
    <Sequence>
      <IsOk/>
      <Go speed="{s}"  mode='fast'/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Condition ID="IsOk"/>
  </TreeNodesModel>
</root>
"""
    text = _translate(tmp_path, v4)
    removed, added = _changed_lines(v4, text)
    assert removed == []
    assert added == [
        '    <Action ID="Go">',
        '      <input_port name="speed"/>',
        '      <input_port name="mode"/>',
        f"      <description>{ASSUMED_DESCRIPTION}</description>",
        "    </Action>",
    ]


def test_includes_are_inlined_into_the_users_file(tmp_path: Path) -> None:
    (tmp_path / "other.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="O"><Fallback><Ok/><AlwaysSuccess/>'
        "</Fallback></BehaviorTree></root>",
        encoding="utf-8",
    )
    with_include = """<root BTCPP_format="4" main_tree_to_execute="T">
  <include path="other.xml"/>
  <!-- O comes from other.xml -->
  <BehaviorTree ID="T"><SubTree ID="O"/></BehaviorTree>
</root>
"""
    text = _translate(tmp_path, with_include, "main.xml")
    removed, added = _changed_lines(with_include, text)
    assert removed == ['  <include path="other.xml"/>']
    assert added == [
        '  <BehaviorTree ID="O">',
        "    <Fallback>",
        "      <Ok/>",
        "      <AlwaysSuccess/>",
        "    </Fallback>",
        "  </BehaviorTree>",
        "  <TreeNodesModel>",
        '    <Action ID="Ok">',
        f"      <description>{ASSUMED_DESCRIPTION}</description>",
        "    </Action>",
        "  </TreeNodesModel>",
    ]


def test_what_the_editor_cannot_keep_is_written_by_the_writer() -> None:
    odd = """<root><BehaviorTree ID="T"><Go/></BehaviorTree><TreeNodesModel/></root>"""
    doc = loads(odd, "btcpp")
    assert isinstance(doc, BTDocument)
    written = dumps(doc, "btcpp")
    assert edited_source(odd, doc, written) is None  # a <TreeNodesModel/> to fill


def test_a_corpus_v3_tree_keeps_its_comments() -> None:
    source = CORPUS / "bt" / "bt_in_action" / "MROS-RobMoSys-ITP_Pilot-URJC_navigate.xml"
    if not source.exists():
        pytest.skip("corpus not present")
    original = source.read_text(encoding="utf-8")
    assert "<!--" in original and "BTCPP_format" not in original
    _loaded, result, report = api.translate(source, to="btcpp")
    assert report is not None and report.equivalent
    removed, _added = _changed_lines(original, result.text)
    assert all("SequenceStar" in line or line.startswith("<root") for line in removed)
    comments = [line for line in original.splitlines() if "<!--" in line]
    assert comments and all(line in result.text.splitlines() for line in comments)
