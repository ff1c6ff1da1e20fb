"""Profiles found by themselves (issue 26 item 1; fsmbt.formats.btcpp.profiles,
docs/semantics.md §10): a known project's nodes, a model file beside the tree and the bundled
node libraries are applied with no option and said in one line; ``--no-profiles`` refuses them;
a found declaration that does not fit is a warning naming both files.

The corpus figure (every well-formed BT file converts with no option as with the profiles) is
measured in full by ``benchmarks/corpus_coverage.py``; here a seeded sample of it is checked."""

from __future__ import annotations

import random
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api, limits
from fsmbt.model.errors import InputError
from fsmbt.model.kinds import NodeKind
from support.corpus import CORPUS

BT = CORPUS / "bt"
NAV2_MODELS = BT / "nav2" / "models" / "nav2_tree_nodes.xml"
LIBRARIES = Path(__file__).resolve().parents[2] / "node_libraries"


def _corpus(rel: str) -> Path:
    path = BT / rel
    if not path.is_file():
        pytest.skip(f"corpus file not available: {path} (set FSMBT_CORPUS)")
    return path


def test_nav2_tree_converts_with_no_option_and_says_which_profile() -> None:
    path = _corpus("nav2/navigate_w_replanning_distance.xml")
    with pytest.raises(InputError, match="DistanceController"):
        api.convert_file(path, options={"no_profiles": True})
    outcome = api.convert_file(path)
    assert outcome.equivalent is True
    loaded = api.load(path)
    notes = [w for w in loaded.warnings if "read with the Nav2 profile" in w]
    assert len(notes) == 1 and "DistanceController as environment inputs" in notes[0]
    assert "--no-profiles to refuse" in notes[0]
    assert any(str(NAV2_MODELS.name) in w and "found beside it" in w for w in loaded.warnings)
    assert outcome.report is not None
    assert any("DistanceController" in a for a in outcome.report.stats.get("abstractions", []))


def test_nav2_profile_knows_nav2_leaves_without_the_model_file(tmp_path: Path) -> None:
    """A Nav2 tree alone in a folder: the Nav2 profile declares its leaves (a condition is a
    Condition, never RUNNING) from fsmbt's table, not from a file beside it."""
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T"><PipelineSequence>'
        '<GoalReached goal="{goal}"/><RateController hz="1.0">'
        '<ControllerSelector selected_controller="{c}" default_controller="F" '
        'topic_name="t"/></RateController></PipelineSequence></BehaviorTree></root>'
    )
    (tmp_path / "tree.xml").write_text(text, encoding="utf-8")
    doc = api.load(tmp_path / "tree.xml").model
    kinds = {n.type: (n.kind, n.kind_declared) for _, n in doc.nodes()}  # type: ignore[attr-defined]
    assert kinds["GoalReached"] == (NodeKind.CONDITION, True)
    assert kinds["ControllerSelector"] == (NodeKind.ACTION, True)
    assert api.convert_file(tmp_path / "tree.xml").equivalent is True
    plain = api.load(tmp_path / "tree.xml", options={"no_profiles": True}).model
    assert not {n.type: n.kind_declared for _, n in plain.nodes()}["GoalReached"]  # type: ignore[attr-defined]


def test_a_model_file_beside_that_does_not_fit_is_a_warning_naming_both_files(
    tmp_path: Path,
) -> None:
    (tmp_path / "models").mkdir()
    models = tmp_path / "models" / "my_tree_nodes.xml"
    models.write_text(
        '<root BTCPP_format="4"><TreeNodesModel><Condition ID="IsReady">'
        '<input_port name="topic"/></Condition></TreeNodesModel></root>',
        encoding="utf-8",
    )
    tree = tmp_path / "tree.xml"
    tree.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>\n'
        '<IsReady topic="a" timeout="3"/><Go/></Sequence></BehaviorTree></root>',
        encoding="utf-8",
    )
    loaded = api.load(tree)
    kinds = {n.type: n.kind for _, n in loaded.model.nodes()}  # type: ignore[attr-defined]
    assert kinds["IsReady"] is NodeKind.CONDITION
    misfit = [w for w in loaded.warnings if "does not fit" in w]
    assert len(misfit) == 1 and str(models) in misfit[0] and "tree.xml:2" in misfit[0]
    assert "timeout" in misfit[0]
    assert any("my_tree_nodes.xml (found beside it)" in w for w in loaded.warnings)
    refused = api.load(tree, options={"no_profiles": True})
    assert not any("my_tree_nodes" in w for w in refused.warnings)
    assert {n.type: n.kind for _, n in refused.model.nodes()}["IsReady"] is NodeKind.ACTION  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    "hostile",
    [
        '<!DOCTYPE r [<!ENTITY a "x">]>\n<root><TreeNodesModel/></root>',
        "<root><TreeNodesModel><!--" + "x" * 3000 + '--><Condition ID="IsReady"/>'
        "</TreeNodesModel></root>",
    ],
    ids=["entity-declaration", "over-max-input-bytes"],
)
def test_a_found_model_file_the_input_rules_refuse_is_passed_over(
    tmp_path: Path, hostile: str
) -> None:
    """docs/security.md: a node-model file found beside the tree is read as any input (size
    limit, hardened XML parser); one those refuse is not applied and does not stop the read."""
    (tmp_path / "x_tree_nodes.xml").write_text(hostile, encoding="utf-8")
    tree = tmp_path / "tree.xml"
    tree.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>\n'
        "<IsReady/><Go/></Sequence></BehaviorTree></root>",
        encoding="utf-8",
    )
    with limits.changed(max_input_bytes=2000):
        loaded = api.load(tree)
    assert not any("x_tree_nodes" in w for w in loaded.warnings)
    assert {n.type: n.kind for _, n in loaded.model.nodes()}["IsReady"] is NodeKind.ACTION  # type: ignore[attr-defined]


def test_cli_no_profiles_flag_refuses_the_found_profile() -> None:
    path = _corpus("nav2/navigate_w_replanning_time.xml")

    def validate(*flags: str) -> str:
        done = subprocess.run(
            [sys.executable, "-m", "fsmbt.cli", "validate", str(path), *flags],
            capture_output=True,
            text=True,
            timeout=120,
        )
        return done.stdout + done.stderr

    assert "read with the Nav2 profile" in validate()
    assert "read with the Nav2 profile" not in validate("--no-profiles")


#: The setting the corpus figures compare with (benchmarks/corpus_coverage.py "profiles").
def _profile_options(source: str, path: Path) -> dict[str, object]:
    nodes: list[str] = ["nav2", "moveit_pro"]
    if source == "btcpp_tutorials":
        nodes.append(str(LIBRARIES / "btcpp_tutorials.yaml"))
    for prefix, name in (
        ("IntelligentRoboticsLabs_robocup2020_", "robocup2020.yaml"),
        ("julienbayle_stardust_", "stardust.yaml"),
        ("kmi-robots_hans-ros-supervisor_", "hans_ros_supervisor.yaml"),
    ):
        if path.name.startswith(prefix):
            nodes.append(str(LIBRARIES / name))
    options: dict[str, object] = {"nodes": nodes}
    if source == "nav2":
        options["node_models"] = [str(NAV2_MODELS)]
    return options


def _ok(path: Path, options: dict[str, object]) -> bool:
    try:
        return api.convert_file(path, **{"options": options}).equivalent is True
    except InputError:
        return False


def test_corpus_sample_converts_with_no_option_as_with_the_profiles() -> None:
    """A seeded sample of the corpus BT files (outside bt/btcpp, whose ``../`` include needs
    --include-root): each converts with no option exactly when it does with the profiles."""
    if not BT.is_dir():
        pytest.skip("corpus not available (set FSMBT_CORPUS)")
    files = sorted(
        p
        for p in BT.rglob("*.xml")
        if "models" not in p.parts
        and "_malformed" not in p.parts
        and p.relative_to(BT).parts[0] not in ("btcpp",)
        and "routing" not in p.name  # 20 s alone: in the benchmark's figure
        and "r2_bt" not in p.name  # beyond the state limit with --abstract: in the benchmark
    )
    rng = random.Random(26)
    by_source: dict[str, list[Path]] = {}
    for path in files:
        by_source.setdefault(path.relative_to(BT).parts[0], []).append(path)
    sample = [rng.choice(paths) for _source, paths in sorted(by_source.items())]
    mismatched = []
    for path in sample:
        source = path.relative_to(BT).parts[0]
        if _ok(path, {}) != _ok(path, _profile_options(source, path)):
            mismatched.append(path.name)
    assert not mismatched, mismatched
    # the sample holds a tree the profiles matter for (refused without them)
    nav2 = [p for p in sample if p.relative_to(BT).parts[0] == "nav2"]
    assert nav2 and not _ok(nav2[0], {"no_profiles": True}) and _ok(nav2[0], {})


def test_comments_with_double_hyphens_read_as_tinyxml2_reads_them() -> None:
    """BehaviorTree.CPP (tinyxml2) loads ``<!------->`` and ``<!-- a -- b -->``; libxml2
    refuses them. fsmbt reads them with one warning, lines unchanged; the entity check still
    refuses entities; the other XML formats stay strict."""
    text = (
        '<root BTCPP_format="4">\n<!------->\n<!-- a -- b -->\n<BehaviorTree ID="T">\n'
        "<Sequence><A/><B/></Sequence>\n</BehaviorTree>\n</root>\n"
    )
    loaded = api.load_text(text, "btcpp")
    assert any("2 comment(s) hold '--'" in w for w in loaded.warnings)
    assert [n.location.line for _, n in loaded.model.nodes()] == [5, 5, 5]  # type: ignore[attr-defined, union-attr]
    with pytest.raises(InputError, match="[Cc]omment"):
        from fsmbt.formats.xml_safe import parse_xml

        parse_xml("<x><!-- a -- b --></x>", "x.xml")  # strict without notes
    behaviortreepy = pytest.importorskip("behaviortreepy")  # BehaviorTree.CPP 4.8.2 itself
    factory = behaviortreepy.BehaviorTreeFactory()
    factory.register_simple_action("A", lambda _node: behaviortreepy.NodeStatus.SUCCESS)
    factory.register_simple_action("B", lambda _node: behaviortreepy.NodeStatus.SUCCESS)
    factory.register_behavior_tree_from_text(text)
    assert "T" in factory.registered_behavior_trees()
    bomb = '<!DOCTYPE r [<!ENTITY a "x">]>\n' + text
    with pytest.raises(InputError, match="entities"):
        api.load_text(bomb, "btcpp")


def test_translate_of_a_declared_v4_file_keeps_it_byte_for_byte(tmp_path: Path) -> None:
    """Nothing to change (v4, main tree named, every custom node declared): the translation
    writes the user's bytes - comments, attribute order, spacing; a file with an undeclared
    node is rewritten (its declaration added)."""
    text = (
        "<?xml version='1.0'?>\n<!-- mine -->\n"
        '<root main_tree_to_execute="T"  BTCPP_format="4">\n'
        '  <BehaviorTree ID="T">\n    <Sequence name="s">\n'
        '      <Go  target="{t}"  speed="1"/>\n'
        "    </Sequence>\n  </BehaviorTree>\n"
        '  <TreeNodesModel><Action ID="Go"><input_port name="speed"/>'
        '<input_port name="target"/></Action></TreeNodesModel>\n</root>\n'
    )
    source = tmp_path / "mine.xml"
    source.write_text(text, encoding="utf-8")
    _loaded, result, report = api.translate(source, to="btcpp")
    assert result.text == text and report is not None and report.equivalent
    undeclared = tmp_path / "undeclared.xml"
    undeclared.write_text(text.replace('<Action ID="Go">', '<Action ID="Other">'), "utf-8")
    _loaded, rewritten, _report = api.translate(undeclared, to="btcpp")
    assert rewritten.text != undeclared.read_text(encoding="utf-8")
    assert 'ID="Go"' in rewritten.text
