"""``--to btcpp3``: BehaviorTree.CPP v3 files for ROS 2 Humble's Nav2 (docs/formats/btcpp.md,
"Version 3"): v3 names and ports, what v3 cannot hold refused or named, each written file
checked against v3's rules (``v3_rules``) and read back proven equivalent by fsmbt's verifier
(``fsmbt.api.translate``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.formats.btcpp.v3_rules import v3_problems
from fsmbt.formats.btcpp.v3_write import prepare_v3
from fsmbt.formats.translate import Translation
from fsmbt.generate import random_fsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from support.corpus import CORPUS

V4 = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <SequenceWithMemory name="top">
      <IsReady/>
      <Parallel success_count="2">
        <Door open="{door}" speed="2" _onSuccess="done:=true"/>
        <SubTree ID="Other" target="{t}" _autoremap="true"/>
        <SubTree ID="Other" _autoremap="true"/>
      </Parallel>
      <Fallback>
        <SubTree ID="Other"/>
        <RetryUntilSuccessful num_attempts="3"><Door open="{door}" speed="1"/></RetryUntilSuccessful>
      </Fallback>
    </SequenceWithMemory>
  </BehaviorTree>
  <BehaviorTree ID="Other"><ReactiveFallback><IsReady/><AlwaysSuccess/></ReactiveFallback></BehaviorTree>
  <TreeNodesModel>
    <Condition ID="IsReady"/>
    <Action ID="Door"><input_port name="open"/><input_port name="speed"/></Action>
  </TreeNodesModel>
</root>
"""


def _translate(tmp_path: Path, text: str, to: str = "btcpp3") -> Translation:
    source = tmp_path / "in.xml"
    source.write_text(text, encoding="utf-8")
    _loaded, result, report = api.translate(source, to=to)
    assert report is not None and report.equivalent and result.verified
    return result


def test_v3_names_ports_and_subtrees(tmp_path: Path) -> None:
    result = _translate(tmp_path, V4)
    text = result.text
    assert v3_problems(text) == []
    assert 'BTCPP_format="3"' in text and "SequenceWithMemory" not in text
    assert '<SequenceStar name="top">' in text
    # 3.8 requires success_threshold; failure_count's v4 default is written out
    assert '<Parallel success_threshold="2" failure_threshold="1">' in text
    assert '<SubTreePlus ID="Other" target="{t}" __autoremap="true"/>' in text
    assert '<SubTree ID="Other" __shared_blackboard="true"/>' in text
    assert '<SubTree ID="Other"/>' in text
    assert "_autoremap" not in text.replace("__autoremap", "")
    # the post-condition is gone, named with its node and line
    assert "_onSuccess" not in text
    assert any("node 'Door', line 6" in loss and "_onSuccess" in loss for loss in result.losses)
    # read back, v3's names mean their v4 counterparts: the same document but the version
    back = loads(text, "btcpp")
    assert isinstance(back, BTDocument) and back.format_version == "3"
    main = back.main.root
    assert main is not None and main.type == "SequenceWithMemory"
    parallel = main.children[1]
    assert parallel.attrs == {"success_count": "2", "failure_count": "1"}
    plus, shared = parallel.children[1:]
    assert plus.attrs == {"ID": "Other", "target": "{t}", "_autoremap": "true"}
    assert shared.attrs == {"ID": "Other", "_autoremap": "true"}


def test_the_rule_check_refuses_v4(tmp_path: Path) -> None:
    problems = v3_problems(V4)
    assert any('BTCPP_format="4"' in p for p in problems)
    assert any("<SequenceWithMemory> is neither" in p for p in problems)
    assert any("no port 'success_count'" in p for p in problems)
    assert any("_autoremap" in p for p in problems)
    assert any("_onSuccess" in p for p in problems)
    assert any("remaps a key named without braces" in p for p in problems)


@pytest.mark.parametrize(
    ("node", "named"),
    [
        ('<Script code="a:=1"/>', "Script is a BehaviorTree.CPP v4 node"),
        ("<RunOnce><Go/></RunOnce>", "RunOnce is a BehaviorTree.CPP v4 node"),
        ("<AsyncSequence><Go/><Go/></AsyncSequence>", "AsyncSequence is a"),
        ('<LoopInt queue="1;2"><Go/></LoopInt>', "LoopInt is a"),
        ('<Go _skipIf="a==1"/>', 'pre-condition _skipIf="a==1"'),
        ('<Go _while="a==1"/>', "pre-condition _while"),
    ],
)
def test_what_v3_cannot_run_is_refused_with_its_node(node: str, named: str) -> None:
    doc = loads(
        f"""<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence>
<Go/>
{node}
</Sequence></BehaviorTree></root>""",
        "btcpp",
    )
    with pytest.raises(UnsupportedError) as caught:
        dumps(doc, "btcpp3")
    message = str(caught.value)
    assert named in message and "tree 'Main'" in message and "line 3" in message


def test_v3_files_read_with_v4_meaning(tmp_path: Path) -> None:
    v3 = """<root main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Parallel success_threshold="1" failure_threshold="2">
      <SubTree ID="Move" target="move_goal" __shared_blackboard="false"/>
      <SubTree ID="Move" __shared_blackboard="true"/>
      <SubTreePlus ID="Move" target="{g}" speed="3" __autoremap="1"/>
    </Parallel>
  </BehaviorTree>
  <BehaviorTree ID="Move"><AlwaysSuccess/></BehaviorTree>
</root>"""
    doc = loads(v3, "btcpp")
    assert isinstance(doc, BTDocument)
    parallel = doc.main.root
    assert parallel is not None
    assert parallel.attrs == {"success_count": "1", "failure_count": "2"}
    plain, shared, plus = parallel.children
    assert plain.attrs == {"ID": "Move", "target": "{move_goal}"}  # a key, in v4's braces
    assert shared.attrs == {"ID": "Move", "_autoremap": "true"}
    assert plus.attrs == {"ID": "Move", "target": "{g}", "speed": "3", "_autoremap": "1"}
    v4 = _translate(tmp_path, v3, to="btcpp").text
    assert '<Parallel success_count="1" failure_count="2">' in v4
    assert '<SubTree ID="Move" target="{move_goal}"/>' in v4
    # and back to v3: the same file's meaning in v3's words
    again = _translate(tmp_path, v4).text
    assert v3_problems(again) == []
    assert '<SubTreePlus ID="Move" target="{move_goal}"/>' in again


def test_a_nav2_tree_writes_for_humble() -> None:
    source = CORPUS / "bt" / "nav2" / "navigate_to_pose_w_replanning_and_recovery.xml"
    if not source.exists():
        pytest.skip("corpus not present")
    _loaded, result, report = api.translate(source, to="btcpp3")
    assert report is not None and report.equivalent
    assert v3_problems(result.text) == [] and 'BTCPP_format="3"' in result.text
    assert result.losses == []


EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("name", ["paper_fsm.xml", "door_hfsm.scxml", "delivery_smach.py"])
def test_fsm_to_bt_for_humble(tmp_path: Path, name: str) -> None:
    out = tmp_path / "tree.xml"
    # outcome-driven machines convert in the structured style by default, whose Script nodes
    # v3 has not: the LEBT style writes none
    outcome = api.convert_file(EXAMPLES / name, out, to="btcpp3", style="lebt")
    assert outcome.equivalent is True
    text = out.read_text(encoding="utf-8")
    assert 'BTCPP_format="3"' in text and v3_problems(text) == []
    # the file itself, read as btcpp3 (the btcpp reader), is proven equivalent to the machine
    back = api.load(out, "btcpp3")
    assert isinstance(back.model, BTDocument) and back.model.format_version == "3"
    assert api.verify_models(api.load(EXAMPLES / name).model, back.model).equivalent


def test_a_structured_conversion_names_the_way_out(tmp_path: Path) -> None:
    with pytest.raises(UnsupportedError, match="--style lebt writes no Script"):
        api.convert_file(EXAMPLES / "delivery_smach.py", tmp_path / "t.xml", to="btcpp3")


@pytest.mark.parametrize(
    ("ancestor", "node", "named"),
    [
        ("ReactiveSequence", "<SequenceWithMemory><Go/><Go/></SequenceWithMemory>", "SequenceStar"),
        ("ReactiveFallback", '<Repeat num_cycles="3"><Go/></Repeat>', "cycles within one tick"),
        (
            "Parallel",
            '<RetryUntilSuccessful num_attempts="2"><Go/></RetryUntilSuccessful>',
            "retries",
        ),
    ],
)
def test_v3_ticks_otherwise_under_an_interrupting_ancestor(
    ancestor: str, node: str, named: str
) -> None:
    # v4 returns RUNNING after a child that completed at once, 3.8 goes on in the same tick;
    # a reactive parent or a Parallel ticks something else in between only in v4
    doc = loads(
        f"""<root BTCPP_format="4"><BehaviorTree ID="Main"><{ancestor}>
<IsOk/>
{node}
</{ancestor}></BehaviorTree>
<TreeNodesModel><Condition ID="IsOk"/><Action ID="Go"/></TreeNodesModel></root>""",
        "btcpp",
    )
    with pytest.raises(UnsupportedError) as caught:
        dumps(doc, "btcpp3")
    message = str(caught.value)
    assert named in message and f"ancestor {ancestor}" in message and "line 3" in message
    # the same node under a plain Sequence is written
    plain = dumps(loads(dumps(doc, "btcpp").replace(ancestor, "Sequence"), "btcpp"), "btcpp3")
    assert v3_problems(plain) == []


def test_under_a_control_fsmbt_cannot_tell_about_the_difference_is_named() -> None:
    doc = loads(
        """<root BTCPP_format="4"><BehaviorTree ID="Main"><MyControl>
<IsOk/>
<Repeat num_cycles="2"><Go/></Repeat>
</MyControl></BehaviorTree>
<TreeNodesModel><Control ID="MyControl"/><Condition ID="IsOk"/><Action ID="Go"/>
</TreeNodesModel></root>""",
        "btcpp",
    )
    assert isinstance(doc, BTDocument)
    _written, losses = prepare_v3(doc)
    assert len(losses) == 1
    assert "node 'Repeat', line 3" in losses[0] and "MyControl" in losses[0]
    assert v3_problems(dumps(doc, "btcpp3")) == []


def test_a_while_do_else_without_else_gets_always_failure(tmp_path: Path) -> None:
    result = _translate(
        tmp_path,
        """<root BTCPP_format="4"><BehaviorTree ID="Main">
<WhileDoElse><IsOk/><Go/></WhileDoElse>
</BehaviorTree><TreeNodesModel><Condition ID="IsOk"/><Action ID="Go"/></TreeNodesModel></root>""",
    )
    # 3.8 requires three children; v4 without an else branch returns FAILURE, as this does
    assert "<AlwaysFailure/>\n    </WhileDoElse>" in result.text
    assert v3_problems(result.text) == []
    assert any("no else branch" in loss and "line 2" in loss for loss in result.losses)
    assert any(
        "three children" in p for p in v3_problems(result.text.replace("<AlwaysFailure/>", ""))
    )


def test_a_v3_file_that_3_8_ticks_otherwise_is_read_with_a_warning() -> None:
    warnings: list[str] = []
    loads(
        """<root><BehaviorTree ID="Main"><ReactiveSequence>
<IsOk/>
<SequenceStar><Go/><Go/></SequenceStar>
<Repeat num_cycles="2"><Go/></Repeat>
</ReactiveSequence></BehaviorTree></root>""",
        "btcpp",
        warnings=warnings,
    )
    ticks = [w for w in warnings if "fsmbt reads this v3 file with v4's rule" in w]
    assert len(ticks) == 1 and "line 3" in ticks[0] and "(1 more such node(s))" in ticks[0]
    # the same tree in v4 is read without it: v4's rule is the file's own
    warnings.clear()
    loads(
        """<root BTCPP_format="4"><BehaviorTree ID="Main"><ReactiveSequence>
<IsOk/><SequenceWithMemory><Go/><Go/></SequenceWithMemory>
</ReactiveSequence></BehaviorTree></root>""",
        "btcpp",
        warnings=warnings,
    )
    assert not any("v4's rule" in w for w in warnings)


def test_a_post_condition_a_switch_reads_is_refused_not_dropped() -> None:
    """The dispatch form's transitions write the state index in ``_onSuccess``; dropping it
    would leave a v3 tree that never leaves its initial state."""
    fsm = random_fsm("v3post", 5, start_event=False, shape="chain", extra_edges=0)
    doc = convert(fsm, style="dispatch").model
    with pytest.raises(
        UnsupportedError, match="post-condition _onSuccess writes a blackboard entry"
    ):
        prepare_v3(doc)


def test_v3_holds_answers_as_prepare_v3_does() -> None:
    """``v3_holds`` (the web page's v3 download offer) agrees with ``prepare_v3`` on trees it
    decides without a copy (the dispatch form's Script, a pre-condition) and on trees it hands
    to ``prepare_v3`` (the LEBT and structured forms, a v4-only feature, the examples)."""
    from fsmbt.formats.btcpp.v3_write import v3_holds
    from fsmbt.model.errors import FsmbtError

    examples = Path(__file__).resolve().parents[2] / "examples"
    paper = api.load(examples / "paper_fsm.xml")
    trees = [loads(V4, "btcpp")]
    trees += [api.convert_loaded(paper, style=s).result for s in ("dispatch", "lebt", "auto")]
    trees += [api.load(examples / n).model for n in ("robot_bt.xml", "game_npc_bt.xml")]
    pre = V4.replace("<IsReady/>", '<IsReady _skipIf="x"/>')
    trees.append(loads(pre, "btcpp"))
    answers = []
    for tree in trees:
        assert isinstance(tree, BTDocument)
        try:
            prepare_v3(tree)
            expected = True
        except FsmbtError:
            expected = False
        assert v3_holds(tree) is expected
        answers.append(expected)
    assert True in answers and False in answers  # both answers were exercised
