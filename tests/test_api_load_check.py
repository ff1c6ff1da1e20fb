"""Every written tree loads (docs/semantics.md §5): ``convert`` loads each BehaviorTree.CPP tree
it writes in BehaviorTree.CPP 4.8.2 (the compiled loader, every ``<TreeNodesModel>`` node
registered with its ports; behaviortreepy, ports stripped, without the C++ build), says so, and
refuses - located, not written, exit 2 - a tree the engine does not load."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert.result import ConversionResult
from fsmbt.formats import dumps
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.engines import btcpp_load, scxml_load
from fsmbt.semantics.engines.btcpp_load import (
    ENGINE_CPP,
    ENGINE_PY,
    TINYXML2_MAX_DEPTH,
    TreeLoadError,
    check_loads,
)
from support.chains import chain


def nested_text(levels: int) -> str:
    """A BehaviorTree.CPP document whose tree is ``levels`` nested Inverters, one per line."""
    opening = "".join("<Inverter>\n" for _ in range(levels))
    closing = "".join("</Inverter>\n" for _ in range(levels))
    return (
        '<root BTCPP_format="4" main_tree_to_execute="MainTree">\n'
        '<BehaviorTree ID="MainTree">\n'
        f"{opening}<AlwaysSuccess/>\n{closing}"
        "</BehaviorTree>\n</root>\n"
    )


PORTS_TEXT = """<root BTCPP_format="4" main_tree_to_execute="MainTree">
  <BehaviorTree ID="MainTree">
    <Sequence>
      <Move goal="kitchen" speed="2"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="Move"><input_port name="goal"/></Action>
  </TreeNodesModel>
</root>
"""


@pytest.fixture(scope="module")
def cpp_program() -> Path:
    program = btcpp_load.find_program()
    if program is None:
        pytest.skip("BehaviorTree.CPP is not built here (fsmbt doctor --install btcpp)")
    return program


def test_a_converted_lebt_loads_in_the_cpp_build(cpp_program: Path) -> None:
    doc = api.convert_model(chain(300), "rules", style="lebt").model
    check = check_loads(dumps(doc, "btcpp"))
    assert check.loaded and check.engine == ENGINE_CPP
    assert check.nodes == sum(1 for _tree, _node in doc.nodes())
    assert check.summary() == "loads in BehaviorTree.CPP 4.8.2: yes"


def test_too_deep_a_tree_is_refused_at_the_line_tinyxml2_stops(cpp_program: Path) -> None:
    check = check_loads(nested_text(600))
    assert not check.loaded
    assert "XML_ELEMENT_DEPTH_EXCEEDED" in check.error
    assert check.line == TINYXML2_MAX_DEPTH  # <root> on line 1, one element per line
    assert check_loads(nested_text(150)).loaded


def test_ports_are_checked_by_the_cpp_build_and_stripped_by_behaviortreepy(
    cpp_program: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    refused = check_loads(PORTS_TEXT)
    assert not refused.loaded and "speed" in refused.error
    assert check_loads(PORTS_TEXT.replace(' speed="2"', "")).loaded
    monkeypatch.setattr(btcpp_load, "find_program", lambda build=True: None)
    stripped = check_loads(PORTS_TEXT)
    assert stripped.loaded and stripped.engine == ENGINE_PY
    assert "ports stripped" in stripped.summary()


def test_behaviortreepy_refuses_too_deep_a_tree_without_the_cpp_build(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(btcpp_load, "find_program", lambda build=True: None)
    check = check_loads(nested_text(600))
    assert check.engine == ENGINE_PY and not check.loaded
    assert check.line == TINYXML2_MAX_DEPTH


def test_convert_reports_that_its_tree_loads(tmp_path: Path) -> None:
    source = tmp_path / "chain.scxml"
    source.write_text(dumps(chain(300), "scxml"), encoding="utf-8")
    outcome = api.convert_file(source, tmp_path / "chain.xml", style="lebt")
    assert outcome.written and outcome.equivalent
    assert outcome.load is not None and outcome.load.loaded
    assert outcome.to_dict()["loads"]["loaded"] is True
    skipped = api.convert_file(source, None, style="lebt", load_check=False)
    assert skipped.load is None


def _deep_conversion(*_args: object, **_kwargs: object) -> ConversionResult:
    node = BTNode(type="AlwaysSuccess", kind=NodeKind.ACTION)
    for _ in range(600):
        node = BTNode(type="Inverter", kind=NodeKind.DECORATOR, children=[node])
    return ConversionResult(BTDocument.single(node), "rules", "fsm->bt", {"states": 1})


def test_a_result_that_would_not_load_is_a_located_error_and_not_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "one.scxml"
    source.write_text(dumps(chain(2), "scxml"), encoding="utf-8")
    output = tmp_path / "deep.xml"
    monkeypatch.setattr(api, "convert_model", _deep_conversion)
    with pytest.raises(TreeLoadError) as caught:
        api.convert_file(source, output, verify=False)
    assert caught.value.location is not None and caught.value.location.file == str(output)
    assert not output.exists()
    assert main(["convert", str(source), "-o", str(output), "--no-verify", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"error: {output}:" in err and "does not load in BehaviorTree.CPP 4.8.2" in err
    assert not output.exists()
    written = api.convert_file(source, output, verify=False, load_check=False)
    assert written.written and written.load is None


def test_a_loader_that_cannot_run_falls_back_to_behaviortreepy(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A compiled check whose library is gone answers nothing about the tree (the dynamic
    loader's exit 127): behaviortreepy loads it instead, and says so."""
    broken = tmp_path / "fsmbt_btcpp_load-broken"
    broken.write_text("#!/bin/sh\necho 'cannot open shared object file' >&2\nexit 127\n")
    broken.chmod(0o755)
    monkeypatch.setattr(btcpp_load, "find_program", lambda build=True: broken)
    good = check_loads(nested_text(10))
    assert good.loaded and good.engine == ENGINE_PY
    deep = check_loads(nested_text(600))
    assert not deep.loaded and deep.engine == ENGINE_PY


BROKEN_SCXML = (
    '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="nowhere">'
    '<state id="a"/></scxml>'
)


def test_an_scxml_result_is_loaded_in_python_statemachine(tmp_path: Path) -> None:
    pytest.importorskip("statemachine")
    robot = Path(__file__).resolve().parents[1] / "examples" / "robot_bt.xml"
    outcome = api.convert_file(robot, tmp_path / "robot.scxml")
    assert outcome.written and outcome.equivalent
    assert outcome.load is not None and outcome.load.loaded
    assert outcome.load.summary().startswith("loads in python-statemachine 3.")
    refused = scxml_load.check_scxml_loads(BROKEN_SCXML)
    assert refused is not None and not refused.loaded and "nowhere" in refused.error
