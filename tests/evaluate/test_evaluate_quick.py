"""``fsmbt evaluate --quick``: the report's shape and the numbers that must hold.

Rules and baselines are correct by construction, so every generated model they convert must be
proven equivalent (100 %); the FSM->BT element counts must lie within ``FORMULA_BAND`` of our
exact formulas on generated models; LLM methods must read "not run: no endpoint", never a
number; a second run resumes and runs nothing again.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest

from fsmbt.cli import main
from fsmbt.evaluate import EvaluationSettings, evaluate
from fsmbt.evaluate.analysis import FORMULA_BAND
from fsmbt.evaluate.dataset import build
from fsmbt.evaluate.paper import NOT_RECORDED, paper_edit
from fsmbt.evaluate.plan import (
    NOT_RUN,
    NUSMV_EXAMPLES,
    NUSMV_MAX_NODES,
    NUSMV_MAX_STATES,
    nusmv_models,
)
from fsmbt.evaluate.stats import fit_slope, wilson

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("evaluation")
    settings = EvaluationSettings(
        output=out, quick=True, count=3, nusmv_sample=0, workers=1, corpus=None, examples=EXAMPLES
    )
    evaluate(settings)
    return out


def test_report_folder_shape(report: Path) -> None:
    for name in (
        "report.md",
        "report.html",
        "rows.csv",
        "rows.json",
        "tables.json",
        "run.json",
        "results.sqlite",
        "dataset/manifest.json",
        "dataset/manifest.csv",
    ):
        assert (report / name).is_file(), name
    for plot in ("accuracy", "elements", "time"):
        assert (report / "plots" / f"{plot}.png").stat().st_size > 1000
        assert (report / "plots" / f"{plot}.svg").read_text().lstrip().startswith("<?xml")
    page = (report / "report.html").read_text()
    assert page.count("<svg") == 3 and 'src="http' not in page
    run = json.loads((report / "run.json").read_text())
    assert run["command"] and run["versions"]["matplotlib"]


def test_rules_and_baselines_fully_verified(report: Path) -> None:
    tables = json.loads((report / "tables.json").read_text())
    for row in tables["accuracy"]:
        if row["method"] in ("rules", "bsd", "chds") and row["group"] in ("basic", "robot", "game"):
            assert row["produced"] == 6 and row["equivalent"] == 6, row
        if row["method"].startswith(("llm", "nllm")):
            assert row == {"method": row["method"], "group": row["group"], "text": NOT_RUN}


def test_structured_is_a_method_of_its_own_on_the_smach_example(report: Path) -> None:
    tables = json.loads((report / "tables.json").read_text())
    (row,) = [r for r in tables["accuracy"] if r["method"] == "structured" and r["group"] == "all"]
    assert row["produced"] >= 1 and row["equivalent"] == row["produced"], row
    formulas = [f for f in tables["formulas"] if f["method"] == "structured"]
    assert formulas and all("LEBT, beside" in f["paper_formula"] for f in formulas)


def test_elements_within_band_of_formulas(report: Path) -> None:
    rows = json.loads((report / "rows.json").read_text())
    generated_fsm = {r["model"] for r in rows if r["source"] == "generated" and r["kind"] == "fsm"}
    assert len(generated_fsm) == 9
    formulas = {
        (f["direction"], f["method"]): f
        for f in json.loads((report / "tables.json").read_text())["formulas"]
    }
    assert formulas[("fsm->bt", "bsd")]["max_abs_deviation_from_ours"] <= FORMULA_BAND
    assert formulas[("fsm->bt", "rules")]["within_band"] >= 0.9
    assert formulas[("fsm->bt", "chds")]["max_abs_deviation_from_ours"] <= FORMULA_BAND


def test_consistency_and_manifest(report: Path) -> None:
    tables = json.loads((report / "tables.json").read_text())
    rules = [r for r in tables["consistency"] if r["method"] == "rules"]
    assert {r["model"] for r in rules} == {"example_robot_bt.xml", "example_predator_fsm.csv"}
    assert all(r["reachability"] and r["termination_consistency"] for r in rules)
    manifest = json.loads((report / "dataset/manifest.json").read_text())["models"]
    assert all(len(m["sha256"]) == 64 for m in manifest)
    assert len(tables["edit_distances"]) == 18


def test_every_table_sets_the_paper_beside_ours(report: Path) -> None:
    markdown = (report / "report.md").read_text()
    sections = markdown.split("\n## ")[1:]
    tables = [s for s in sections if not s.startswith("Dataset")]
    assert len(tables) == 9
    for section in tables:
        assert "paper" in section.lower(), section.splitlines()[0]
    heads = json.loads((report / "tables.json").read_text())["paper"]
    assert all(h["ours"] for h in heads)
    accuracy = [h for h in heads if h["source"] == "Tables I/VI"]
    assert len(accuracy) == 4 and all(h["paper"] == NOT_RECORDED for h in accuracy)
    assert accuracy[0]["ours"] == NOT_RUN  # the LLM: no endpoint in the tests
    assert accuracy[1]["ours"].startswith("rules 100.0 %")
    edits = [h for h in heads if h["figure"].startswith("edit distance")]
    assert len(edits) == 6 and all("as written" in h["ours"] for h in edits)


def test_edit_rows_give_both_distances_and_the_paper(report: Path) -> None:
    rows = json.loads((report / "tables.json").read_text())["edit_distances"]
    for row in rows:
        assert row["verified"] == "EQUIVALENT", row
        assert row["paper"] == paper_edit(row["scenario"], row["case"], row["method"], row["k"])
        assert row["lower_bound"] <= row["distance"]
        assert row["flat_distance"] is not None
        if row["method"] == "bsd":
            assert row["k"] == row["k_base"] == 0  # BSD's result is flat
    by = {(r["case"], r["method"]): r for r in rows}
    # the measure as written separates the methods; flattened they coincide
    safe = "Safe-Move-To behaviour"
    assert by[(safe, "rules")]["lower_bound"] > by[(safe, "bsd")]["distance"]
    assert by[(safe, "chds")]["lower_bound"] > by[(safe, "bsd")]["distance"]
    assert len({by[(safe, m)]["flat_distance"] for m in ("rules", "bsd", "chds")}) == 1


def test_nusmv_sample_names_the_examples(tmp_path: Path) -> None:
    entries = build(tmp_path, seed=0, count=4, examples=EXAMPLES, corpus=None)
    chosen = nusmv_models(entries, seed=0, count=3)
    assert [e.id for e in chosen[:2]] == list(NUSMV_EXAMPLES)
    assert len(chosen) == 5 and all(e.source == "generated" for e in chosen[2:])
    for e in chosen[2:]:
        limit = e.size["states"] <= NUSMV_MAX_STATES if e.kind == "fsm" else None
        assert limit if limit is not None else e.size["nodes"] <= NUSMV_MAX_NODES
    assert chosen == nusmv_models(entries, seed=0, count=3)
    assert nusmv_models(entries, seed=0, count=0) == []


def test_resume_runs_nothing_again(report: Path) -> None:
    code = main(
        [
            "evaluate",
            "-o",
            str(report),
            "--quick",
            "--count",
            "3",
            "--nusmv",
            "0",
            "--workers",
            "1",
            "--no-report",
            "--quiet",
            "--examples",
            str(EXAMPLES),
            "--corpus",
            str(report / "no-corpus"),
        ]
    )
    assert code == 0
    last = json.loads((report / "runs.jsonl").read_text().splitlines()[-1])
    assert last["ran"] == 0 and last["before"] == last["after"] == last["jobs"]


def test_resume_after_lost_rows_runs_exactly_those(tmp_path: Path) -> None:
    settings = EvaluationSettings(
        output=tmp_path, count=2, nusmv_sample=0, workers=2, corpus=None, examples=None
    )
    first = evaluate(settings, report=False)
    assert first["before"] == 0 and first["ran"] == first["after"] == first["jobs"] == 36
    # a run killed mid-way: the rows it had not stored yet are missing
    with sqlite3.connect(tmp_path / "results.sqlite") as db:
        db.execute("DELETE FROM results WHERE rowid % 3 = 0")
        left = db.execute("SELECT COUNT(*) FROM results").fetchone()[0]
    calls: list[tuple[str, int, int]] = []
    second = evaluate(settings, report=False, on_progress=lambda *call: calls.append(call))
    assert second["before"] == left and second["ran"] == 36 - left and second["after"] == 36
    # the progress hook: each method starts at what the store held and ends at its total
    first_seen: dict[str, int] = {}
    last: dict[str, tuple[int, int]] = {}
    for label, done, total in calls:
        first_seen.setdefault(label, done)
        last[label] = (done, total)
    assert sum(first_seen.values()) == left
    assert all(done == total for done, total in last.values())
    assert sum(total for _done, total in last.values()) == 36
    assert len(calls) == len(last) + (36 - left)
    with sqlite3.connect(tmp_path / "results.sqlite") as db:
        assert db.execute("SELECT COUNT(*), COUNT(DISTINCT key) FROM results").fetchone() == (
            36,
            36,
        )


def test_dataset_is_reproducible(tmp_path: Path) -> None:
    one = build(tmp_path / "a", seed=5, count=4, examples=None, corpus=None)
    two = build(tmp_path / "b", seed=5, count=4, examples=None, corpus=None)
    other = build(tmp_path / "c", seed=6, count=4, examples=None, corpus=None)
    assert [e.sha256 for e in one] == [e.sha256 for e in two]
    assert [e.sha256 for e in one] != [e.sha256 for e in other]
    shapes = [e.shape for e in one if e.kind == "fsm"]
    assert shapes[:3] == ["chain", "tree", "loop"]
    assert all(2 <= e.size["states"] <= 30 for e in one if e.kind == "fsm")
    assert all(2 <= e.size["depth"] <= 10 for e in one if e.kind == "bt")


def test_wilson_and_fit() -> None:
    low, high = wilson(20, 20)
    assert high == 1.0 and 0.83 < low < 0.85
    slope, error, intercept = fit_slope([1, 2, 3, 4], [3, 5, 7, 9])
    assert slope == pytest.approx(2.0) and error == pytest.approx(0.0) and intercept == 1.0
