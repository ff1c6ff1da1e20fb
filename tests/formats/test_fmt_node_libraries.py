"""The node-library files of node_libraries/ (``--nodes FILE``; docs/semantics.md
"Project nodes"): each one loads, names registered kinds, cites the source it was read from,
and makes its project's corpus trees (files written by other people, ``FSMBT_CORPUS``) convert
and verify; without it those trees are refused, naming the node."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from fsmbt import api
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.nodes import node_semantics
from fsmbt.model.nodes.library import build_library
from fsmbt.semantics.bt_interpreter import CompiledTree
from support.corpus import CORPUS

LIBRARIES = Path(__file__).resolve().parents[2] / "node_libraries"
BT = CORPUS / "bt"
_COMMIT = re.compile(r"@?\b[0-9a-f]{7,40}\b")

#: corpus file -> (library file, extra options, the node the plain setting refuses)
CASES = {
    "bt_in_action/IntelligentRoboticsLabs_robocup2020_bt_receptionist.xml": (
        "robocup2020.yaml",
        {},
        "ActivationSequence",
    ),
    "bt_in_action/IntelligentRoboticsLabs_robocup2020_bt_serving_drinks.xml": (
        "robocup2020.yaml",
        {},
        "ActivationSequence",
    ),
    "bt_in_action/kmi-robots_hans-ros-supervisor_StateMachine.xml": (
        "hans_ros_supervisor.yaml",
        {},
        "Negation",
    ),
    "btcpp_tutorials/t18_waypoints.xml": ("btcpp_tutorials.yaml", {}, "LoopPose"),
}


def library_files() -> list[Path]:
    return sorted(LIBRARIES.glob("*.yaml"))


def test_fmt_node_library_files_exist() -> None:
    names = {p.name for p in library_files()}
    assert {
        "robocup2020.yaml",
        "stardust.yaml",
        "hans_ros_supervisor.yaml",
        "btcpp_tutorials.yaml",
    } <= names


@pytest.mark.parametrize("path", library_files(), ids=lambda p: p.name)
def test_fmt_node_library_file_loads_and_names_registered_kinds(path: Path) -> None:
    library = build_library([str(path)])
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    entries = data["nodes"]
    assert entries
    for type_name, entry in entries.items():
        ((key, value),) = entry.items()
        if key in ("alias", "semantics"):
            assert node_semantics(value) is not None, (type_name, value)
            table = library.aliases if key == "alias" else library.semantics
            assert table[type_name] == node_semantics(value).name  # type: ignore[union-attr]
        else:
            assert key == "kind" and type_name in library.leaf_kinds


@pytest.mark.parametrize("path", library_files(), ids=lambda p: p.name)
def test_fmt_node_library_entries_cite_their_source(path: Path) -> None:
    """Every control/decorator entry is preceded by a comment naming a source commit."""
    lines = path.read_text(encoding="utf-8").splitlines()
    for i, line in enumerate(lines):
        if "{alias:" in line or "{semantics:" in line:
            comment: list[str] = []
            j = i - 1
            while j >= 0 and lines[j].strip().startswith("#"):
                comment.append(lines[j])
                j -= 1
            text = "\n".join(comment)
            assert comment and _COMMIT.search(text), f"{path.name}: {line.strip()} cites nothing"
            assert ".cpp" in text or ".h" in text, f"{path.name}: {line.strip()} names no file"


def _corpus_file(rel: str) -> Path:
    path = BT / rel
    if not path.is_file():
        pytest.skip(f"corpus file not available: {path} (set FSMBT_CORPUS)")
    return path


@pytest.mark.parametrize("rel", sorted(CASES), ids=lambda r: Path(r).stem)
def test_fmt_corpus_tree_converts_with_its_node_library(rel: str) -> None:
    path = _corpus_file(rel)
    library, extra, _node = CASES[rel]
    options: dict[str, object] = {"nodes": [str(LIBRARIES / library)], **extra}
    outcome = api.convert_file(path, options=options)
    assert outcome.equivalent is True, outcome.verdict
    if "LoopPose" in path.read_text(encoding="utf-8"):  # an abstraction: the verdict says so
        assert any("LoopPose" in s for s in outcome.report.stats.get("abstractions", []))


@pytest.mark.parametrize("rel", sorted(CASES), ids=lambda r: Path(r).stem)
def test_fmt_corpus_tree_without_its_library_is_refused_naming_the_node(rel: str) -> None:
    path = _corpus_file(rel)
    _library, extra, node = CASES[rel]
    with pytest.raises(InputError) as caught:
        api.convert_file(path, options={**extra, "no_profiles": True})
    assert node in str(caught.value)
    assert re.search(r"\.xml:\d+", str(caught.value))  # located


def test_fmt_stardust_r2_compiles_with_its_library() -> None:
    """r2_bt.xml's RealParallel and BlackboardCheckString are read (its five parallel subtrees
    make a state space beyond the default limit: docs/corpus.md)."""
    path = _corpus_file("bt_in_action/julienbayle_stardust_r2_bt.xml")
    plain = api.load(path, options={"no_profiles": True}).model
    with pytest.raises(UnsupportedError, match="RealParallel"):
        CompiledTree(plain)  # type: ignore[arg-type]
    loaded = api.load(
        path, options={"nodes": [str(LIBRARIES / "stardust.yaml")], "abstract": ["blackboard"]}
    ).model
    tree = CompiledTree(loaded)  # type: ignore[arg-type]
    assert sum(n.type == "stardust.RealParallel" for n in tree.nodes) >= 2
