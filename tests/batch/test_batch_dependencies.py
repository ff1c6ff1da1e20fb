"""A batch row remembers the other files its model was made of (docs/batch.md, "Resume"):
a changed, created or deleted include, SubTree or node file re-runs exactly that row, replacing
the batch's own output; an output someone edited since is theirs and is refused."""

from __future__ import annotations

import sqlite3
from pathlib import Path

from fsmbt.batch import ResultStore, make_jobs, run_jobs
from fsmbt.batch.jobs import content_hash

MAIN = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="sub.xml"/>
  <BehaviorTree ID="Main">
    <Sequence><Action ID="Start"/><SubTree ID="Sub"/></Sequence>
  </BehaviorTree>
</root>
"""


def _sub(*leaves: str) -> str:
    body = "".join(f'<Action ID="{leaf}"/>' for leaf in leaves)
    return (
        '<root BTCPP_format="4"><BehaviorTree ID="Sub">'
        f"<Sequence>{body}</Sequence></BehaviorTree></root>\n"
    )


def _setup(tmp_path: Path, sub: str | None) -> tuple[Path, Path]:
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "main.xml").write_text(MAIN, encoding="utf-8")
    if sub is not None:
        (folder / "sub.xml").write_text(sub, encoding="utf-8")
    return folder / "main.xml", tmp_path / "out"


def test_a_changed_include_reruns_its_row_and_replaces_the_batchs_own_output(
    tmp_path: Path,
) -> None:
    main, out = _setup(tmp_path, _sub("Grasp"))
    jobs = make_jobs([main], out)
    with ResultStore(out) as store:
        (first,) = run_jobs(jobs, store=store)
        assert first.status == "equivalent", first.error_message
        sub = str((main.parent / "sub.xml").resolve())
        assert first.dependencies == {sub: content_hash(sub)}
        output = Path(first.output or "")
        assert "Lift" not in output.read_text(encoding="utf-8")
        assert run_jobs(jobs, store=store) == []  # nothing changed: nothing runs

        (main.parent / "sub.xml").write_text(_sub("Grasp", "Lift"), encoding="utf-8")
        (second,) = run_jobs(make_jobs([main], out), store=store)
        assert second.status == "equivalent", second.error_message
        assert second.key == first.key  # the input itself is the same file
        assert second.dependencies[sub] == content_hash(sub) != first.dependencies[sub]
        assert "Lift" in output.read_text(encoding="utf-8")  # the new Sub's leaf, as a state
        assert len(store.results()) == 1
        assert run_jobs(jobs, store=store) == []


def test_a_missing_include_is_a_dependency_too(tmp_path: Path) -> None:
    main, out = _setup(tmp_path, None)
    with ResultStore(out) as store:
        (first,) = run_jobs(make_jobs([main], out), store=store)
        assert first.status == "bad_input", first
        assert "sub.xml" in (first.error_message or "")
        assert run_jobs(make_jobs([main], out), store=store) == []
        (main.parent / "sub.xml").write_text(_sub("Grasp"), encoding="utf-8")
        (second,) = run_jobs(make_jobs([main], out), store=store)
        assert second.status == "equivalent", second.error_message


def test_an_output_edited_since_is_not_replaced_when_a_dependency_changes(
    tmp_path: Path,
) -> None:
    main, out = _setup(tmp_path, _sub("Grasp"))
    with ResultStore(out) as store:
        (first,) = run_jobs(make_jobs([main], out), store=store)
        output = Path(first.output or "")
        output.write_text("the user's own edit", encoding="utf-8")
        (main.parent / "sub.xml").write_text(_sub("Grasp", "Lift"), encoding="utf-8")
        (second,) = run_jobs(make_jobs([main], out), store=store)
        assert second.status == "refused" and second.error_class == "DestinationExists"
        assert output.read_text(encoding="utf-8") == "the user's own edit"


def test_a_changed_node_library_file_reruns_the_row(tmp_path: Path) -> None:
    folder = tmp_path / "in"
    folder.mkdir()
    tree = folder / "tree.xml"
    tree.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Main">'
        '<Negation><Action ID="Go"/></Negation></BehaviorTree></root>\n',
        encoding="utf-8",
    )
    nodes = tmp_path / "nodes.yaml"
    nodes.write_text("nodes:\n  Negation: {alias: Inverter}\n", encoding="utf-8")
    out = tmp_path / "out"
    options = {"nodes": [str(nodes)]}
    with ResultStore(out) as store:
        (first,) = run_jobs(make_jobs([folder], out, options=options), store=store)
        assert first.status == "equivalent", first.error_message
        assert str(nodes.resolve()) in first.dependencies
        inverted = Path(first.output or "").read_text(encoding="utf-8")
        assert run_jobs(make_jobs([folder], out, options=options), store=store) == []
        nodes.write_text("nodes:\n  Negation: {alias: ForceSuccess}\n", encoding="utf-8")
        (second,) = run_jobs(make_jobs([folder], out, options=options), store=store)
        assert second.status == "equivalent", second.error_message
        # Go's failure now ends the tree in success: another machine, verified against the
        # tree as the new library reads it
        assert Path(second.output or "").read_text(encoding="utf-8") != inverted


def test_a_subtree_file_added_to_the_folder_a_lookup_scanned_reruns_the_row(
    tmp_path: Path,
) -> None:
    folder = tmp_path / "in"
    folder.mkdir()
    main = folder / "main.xml"
    main.write_text(MAIN.replace('  <include path="sub.xml"/>\n', ""), encoding="utf-8")
    out = tmp_path / "out"
    with ResultStore(out) as store:
        (first,) = run_jobs(make_jobs([main], out), store=store)
        assert first.status == "bad_input" and "Sub" in (first.error_message or "")
        assert str(folder.resolve()) in first.dependencies  # the folder the lookup scanned
        (folder / "trees.xml").write_text(_sub("Grasp"), encoding="utf-8")
        (second,) = run_jobs(make_jobs([main], out), store=store)
        assert second.status == "equivalent", second.error_message


def test_a_store_written_before_dependencies_were_kept_opens_and_resumes(
    tmp_path: Path,
) -> None:
    main, out = _setup(tmp_path, _sub("Grasp"))
    jobs = make_jobs([main], out)
    with ResultStore(out) as store:
        run_jobs(jobs, store=store)
        path = store.path
    db = sqlite3.connect(path)  # back to the version 1 layout: no dependencies column
    db.execute("ALTER TABLE results DROP COLUMN dependencies")
    db.execute("UPDATE meta SET value = '1' WHERE name = 'schema_version'")
    db.commit()
    db.close()
    with ResultStore(out) as store:
        (row,) = store.results()
        assert row.status == "equivalent" and row.dependencies == {}
        assert run_jobs(jobs, store=store) == []  # an old row has no dependency to check
    version = sqlite3.connect(path).execute("SELECT value FROM meta").fetchone()
    assert version == ("2",)
