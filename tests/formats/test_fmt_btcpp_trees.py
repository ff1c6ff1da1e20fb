"""SubTrees defined in other files: the ``trees`` option (``--trees``), the lookup in the
referencing file's folder, and ``include_root`` (``--include-root``); docs/formats/btcpp.md."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api, limits
from fsmbt.model.errors import InputError
from fsmbt.semantics.bt_interpreter import BTInterpreter
from support.corpus import CORPUS

SRC = Path(__file__).resolve().parents[2] / "src"


def tree_file(path: Path, tree_id: str, body: str, extra: str = "") -> Path:
    path.write_text(
        f'<root BTCPP_format="4">{extra}<BehaviorTree ID="{tree_id}">{body}</BehaviorTree></root>',
        encoding="utf-8",
    )
    return path


def main_file(folder: Path, *refs: str) -> Path:
    subtrees = "".join(f'<SubTree ID="{r}"/>' for r in refs)
    return tree_file(
        folder / "main.xml",
        "Main",
        f"<Sequence><Check/>{subtrees}</Sequence>",
    )


def test_folder_lookup_finds_the_tree_and_warns_naming_the_file(tmp_path: Path) -> None:
    main = main_file(tmp_path, "Sub")
    other = tree_file(tmp_path / "other.xml", "Sub", "<Grasp/>")
    tree_file(tmp_path / "unrelated.xml", "Unused", "<Broken><A/><B/></Broken>")
    warnings: list[str] = []
    loaded = api.load(main)
    doc, warnings = loaded.model, loaded.warnings
    assert set(doc.trees) == {"Main", "Sub"}  # the unreached tree of the folder is not taken
    assert str(other) in " ".join(warnings) and "--trees" in " ".join(warnings)
    assert doc.trees["Sub"].root is not None and doc.trees["Sub"].root.type == "Grasp"
    BTInterpreter(doc)  # compiles: the SubTree resolves


def test_folder_lookup_follows_references_of_the_found_file(tmp_path: Path) -> None:
    main = main_file(tmp_path, "A")
    tree_file(tmp_path / "a.xml", "A", '<Sequence><SubTree ID="B"/><Go/></Sequence>')
    tree_file(tmp_path / "b.xml", "B", "<Stop/>")
    assert set(api.load(main).model.trees) == {"Main", "A", "B"}


def test_folder_lookup_refuses_an_id_defined_twice_naming_both(tmp_path: Path) -> None:
    main = main_file(tmp_path, "Sub")
    one = tree_file(tmp_path / "one.xml", "Sub", "<Grasp/>")
    two = tree_file(tmp_path / "two.xml", "Sub", "<Drop/>")
    with pytest.raises(InputError) as info:
        api.load(main)
    message = str(info.value)
    assert str(one) in message and str(two) in message and "main.xml:1" in message


def test_folder_lookup_never_leaves_the_folder(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    main = main_file(tmp_path / "sub", "Sub")
    tree_file(tmp_path / "outside.xml", "Sub", "<Grasp/>")  # the parent folder: not searched
    (tmp_path / "nested").mkdir()
    warnings: list[str] = []
    loaded = api.load(main)
    doc, warnings = loaded.model, loaded.warnings
    assert "Sub" not in doc.trees
    assert any("--trees" in w and "'Sub'" in w for w in warnings)
    with pytest.raises(InputError, match="unknown tree 'Sub'.*--trees"):
        BTInterpreter(doc)


def test_folder_lookup_skips_unreadable_files_and_names_them(tmp_path: Path) -> None:
    main = main_file(tmp_path, "Sub")
    (tmp_path / "broken.xml").write_text("<root><BehaviorTree ID='Sub'>", encoding="utf-8")
    (tmp_path / "notbt.xml").write_text("<scxml/>", encoding="utf-8")
    warnings: list[str] = []
    warnings = api.load(main).warnings
    text = " ".join(warnings)
    assert "broken.xml" in text and "notbt.xml" in text and "2 unreadable" in text


def test_folder_lookup_is_bounded_by_max_tree_files(tmp_path: Path) -> None:
    main = main_file(tmp_path, "Sub")
    for i in range(4):
        tree_file(tmp_path / f"t{i}.xml", f"T{i}", "<A/>")
    with limits.changed(max_tree_files=3):
        with pytest.raises(InputError, match="FSMBT_MAX_TREE_FILES"):
            api.load(main)


def test_folder_lookup_obeys_the_size_limit(tmp_path: Path) -> None:
    main = main_file(tmp_path, "Sub")
    big = tree_file(tmp_path / "big.xml", "Sub", "<A/>" + " " * 5000)
    with limits.changed(max_input_bytes=len(main.read_bytes()) + 50):
        warnings: list[str] = []
        loaded = api.load(main)
        doc, warnings = loaded.model, loaded.warnings
    assert "Sub" not in doc.trees and big.name in " ".join(warnings)


def test_folder_lookup_refuses_hostile_xml_as_unreadable(tmp_path: Path) -> None:
    main = main_file(tmp_path, "Sub")
    (tmp_path / "bomb.xml").write_text(
        '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>'
        '<root><BehaviorTree ID="Sub">&b;</BehaviorTree></root>',
        encoding="utf-8",
    )
    warnings: list[str] = []
    loaded = api.load(main)
    doc, warnings = loaded.model, loaded.warnings
    assert "Sub" not in doc.trees and "bomb.xml" in " ".join(warnings)


def test_trees_option_files_and_folders(tmp_path: Path) -> None:
    (tmp_path / "lib").mkdir()
    main = main_file(tmp_path, "A", "B")
    tree_file(tmp_path / "lib" / "a.xml", "A", "<Go/>")
    b = tree_file(tmp_path / "b_elsewhere.xml", "B", "<Stop/>")
    # a file in the main file's folder would be found, but --trees is given: only its files
    tree_file(tmp_path / "a_decoy.xml", "A", "<Decoy/>")
    warnings: list[str] = []
    loaded = api.load(main, options={"trees": [str(tmp_path / "lib"), str(b)]})
    doc, warnings = loaded.model, loaded.warnings
    assert set(doc.trees) == {"Main", "A", "B"}
    assert doc.trees["A"].root is not None and doc.trees["A"].root.type == "Go"
    assert not any("taken from" in w for w in warnings)  # named by the caller: no warning


def test_trees_option_refuses_duplicates_and_missing_paths(tmp_path: Path) -> None:
    main = main_file(tmp_path, "A")
    one = tree_file(tmp_path / "x1.xml", "A", "<Go/>")
    two = tree_file(tmp_path / "x2.xml", "A", "<Stop/>")
    with pytest.raises(InputError) as info:
        api.load(main, options={"trees": [str(one), str(two)]})
    assert str(one) in str(info.value) and str(two) in str(info.value)
    with pytest.raises(InputError, match="no such file"):
        api.load(main, options={"trees": [str(tmp_path / "nope.xml")]})
    (tmp_path / "junk.xml").write_text("not xml", encoding="utf-8")
    with pytest.raises(InputError, match="junk.xml"):
        api.load(main, options={"trees": [str(tmp_path / "junk.xml")]})


def test_trees_option_for_text_input(tmp_path: Path) -> None:
    sub = tree_file(tmp_path / "sub.xml", "S", "<Go/>")
    text = '<root BTCPP_format="4"><BehaviorTree ID="M"><SubTree ID="S"/></BehaviorTree></root>'
    assert set(api.load_text(text, "btcpp", options={"trees": str(sub)}).model.trees) == {"M", "S"}


def test_include_root_reaches_a_parent_folder_and_stays_bounded(tmp_path: Path) -> None:
    (tmp_path / "child").mkdir()
    tree_file(tmp_path / "parent.xml", "P", "<Go/>")
    child = tree_file(
        tmp_path / "child" / "c.xml",
        "C",
        '<Sequence><SubTree ID="P"/><Stop/></Sequence>',
        extra='<include path="../parent.xml"/>',
    )
    with pytest.raises(InputError, match="--include-root"):
        api.load(child)
    assert set(api.load(child, options={"include_root": str(tmp_path)}).model.trees) == {"C", "P"}
    with pytest.raises(InputError, match="outside the folder"):
        api.load(child, options={"include_root": str(tmp_path / "child")})


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    return subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )


def test_cli_trees_and_include_root(tmp_path: Path) -> None:
    (tmp_path / "elsewhere").mkdir()
    main = main_file(tmp_path, "Sub")
    tree_file(tmp_path / "elsewhere" / "sub.xml", "Sub", "<Grasp/>")
    out = tmp_path / "out.scxml"
    refused = _cli("convert", str(main), "-o", str(out))
    assert (
        refused.returncode != 0
        and "--trees" in refused.stderr
        and "Traceback" not in (refused.stderr)
    )
    done = _cli("convert", str(main), "-o", str(out), "--trees", str(tmp_path / "elsewhere"))
    assert done.returncode == 0, done.stderr
    assert "EQUIVALENT" in done.stdout + done.stderr and out.exists()


@pytest.mark.skipif(not (CORPUS / "bt").is_dir(), reason="corpus not present")
def test_corpus_multi_file_trees_convert() -> None:
    tut = CORPUS / "bt" / "btcpp_tutorials"
    outcome = api.convert_file(
        tut / "t07_load_multiple_xml.xml",
        options={
            "trees": [
                str(tut / "t07_load_multiple_xml_2.xml"),
                str(tut / "t07_load_multiple_xml_3.xml"),
            ]
        },
    )
    assert outcome.equivalent is True
    moveit = CORPUS / "bt" / "moveit_pro" / "kinova_sim__move_along_path_admittance.xml"
    outcome = api.convert_file(moveit, options={"nodes": ["nav2", "moveit_pro"]})
    assert outcome.equivalent is True
    assert any("kinova_sim__re_zero_force_torque_sensors.xml" in w for w in outcome.warnings)
    child = CORPUS / "bt" / "btcpp" / "trees" / "child" / "child_include_parent.xml"
    outcome = api.convert_file(child, options={"include_root": str(child.parents[1])})
    assert outcome.equivalent is True


def test_batch_passes_trees_and_include_root_to_the_reader(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    from fsmbt.cli import main

    (tmp_path / "in" / "sub").mkdir(parents=True)
    (tmp_path / "lib").mkdir()
    tree_file(tmp_path / "lib" / "s.xml", "Sub", "<Grasp/>")
    tree_file(tmp_path / "in" / "common.xml", "C", "<Go/>")
    main_file(tmp_path / "in" / "sub", "Sub")
    tree_file(
        tmp_path / "in" / "sub" / "child.xml",
        "Child",
        '<Sequence><SubTree ID="C"/><Stop/></Sequence>',
        extra='<include path="../common.xml"/>',
    )
    inputs = [str(tmp_path / "in" / "sub" / n) for n in ("main.xml", "child.xml")]
    args = ["batch", *inputs, "-o", str(tmp_path / "out"), "--quiet", "--json", "-j", "1"]
    assert main(args) == 2  # without the options: one dangling SubTree, one include refused
    capsys.readouterr()
    extra = ["--trees", str(tmp_path / "lib"), "--include-root", str(tmp_path / "in")]
    args2 = ["batch", *inputs, "-o", str(tmp_path / "out2"), "--quiet", "--json", "-j", "1"]
    assert main([*args2, *extra]) == 0
    rows = json.loads(capsys.readouterr().out)["results"]
    assert sorted(r["status"] for r in rows) == ["equivalent", "equivalent"]


def test_a_found_file_does_not_replace_the_files_own_trees(tmp_path: Path) -> None:
    main = main_file(tmp_path, "Sub")
    (tmp_path / "other.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Main"><Decoy/></BehaviorTree>'
        '<BehaviorTree ID="Sub"><Grasp/></BehaviorTree></root>',
        encoding="utf-8",
    )
    warnings: list[str] = []
    loaded = api.load(main)
    doc, warnings = loaded.model, loaded.warnings
    assert doc.trees["Main"].root is not None and doc.trees["Main"].root.type == "Sequence"
    assert set(doc.trees) == {"Main", "Sub"}
    assert any("'Main'" in w and "not taken" in w for w in warnings)
