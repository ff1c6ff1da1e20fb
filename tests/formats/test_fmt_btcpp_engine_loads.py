"""benchmarks/btcpp_loads.py: does BehaviorTree.CPP 4.8.2 itself (behaviortreepy) load a file,
with every unknown node registered as a dummy of its declared kind (docs/corpus.md)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

pytest.importorskip("behaviortreepy")
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import btcpp_loads  # noqa: E402

from support.corpus import CORPUS


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def test_unknown_nodes_of_every_kind_load_as_dummies(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "ok.xml",
        '<root BTCPP_format="4"><BehaviorTree ID="M"><MyControl speed="3">'
        '<MyDecorator rate="1"><Go target="{t}"/></MyDecorator><Condition ID="IsOk" x="1"/>'
        '<Control ID="Other"><Stop/></Control></MyControl></BehaviorTree></root>',
    )
    assert btcpp_loads.refusal(path, tmp_path, {}) is None


def test_the_engine_checks_child_counts_ports_and_subtrees(tmp_path: Path) -> None:
    cases = {
        "no_child.xml": ("<Inverter/>", "must have exactly 1 child"),
        "bad_port.xml": ('<Sequence bogus="1"><Go/></Sequence>', "bogus"),
        "dummy_control_empty.xml": (
            '<Control ID="Mine"/>',
            "must have 1 or more children",
        ),
        "missing_subtree.xml": ('<SubTree ID="Nowhere"/>', "Nowhere"),
    }
    for name, (body, expected) in cases.items():
        path = write(
            tmp_path,
            name,
            f'<root BTCPP_format="4"><BehaviorTree ID="M">{body}</BehaviorTree></root>',
        )
        message = btcpp_loads.refusal(path, tmp_path, {})
        assert message is not None and expected in message, (name, message)


def test_includes_resolve_as_the_engine_resolves_them(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    write(
        tmp_path,
        "common.xml",
        '<root BTCPP_format="4"><BehaviorTree ID="C"><Go/></BehaviorTree></root>',
    )
    child = write(
        tmp_path / "sub",
        "child.xml",
        '<root BTCPP_format="4" main_tree_to_execute="M"><include path="../common.xml"/>'
        '<BehaviorTree ID="M"><SubTree ID="C"/></BehaviorTree></root>',
    )
    assert btcpp_loads.refusal(child, tmp_path, {"include_root": str(tmp_path)}) is None


@pytest.mark.skipif(not (CORPUS / "bt").is_dir(), reason="corpus not present")
def test_the_fuzzing_corpus_files_fsmbt_refuses_are_refused_by_the_engine_too() -> None:
    source = CORPUS / "bt" / "btcpp"
    fuzz = source / "fuzzing_corpus"
    corpus3 = btcpp_loads.refusal(fuzz / "corpus3.xml", source, {})
    corpus4 = btcpp_loads.refusal(fuzz / "corpus4.xml", source, {})
    assert corpus3 is not None and "SubTree" in corpus3 and "line 5" in corpus3
    assert corpus4 is not None and "ForceSuccess" in corpus4 and "line 5" in corpus4
    tutorials = CORPUS / "bt" / "btcpp_tutorials"
    assert btcpp_loads.refusal(tutorials / "t01_build_your_first_tree.xml", tutorials, {}) is None
    # the SubTrees of tutorial 7 live in two other files of its folder, registered as fsmbt
    # finds them
    assert btcpp_loads.refusal(tutorials / "t07_load_multiple_xml.xml", tutorials, {}) is None
