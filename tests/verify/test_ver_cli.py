"""``fsmbt verify``: exit codes 0/1/2/3, the readable report and the JSON report."""

from __future__ import annotations

import copy
import json

import pytest

import fsmbt.verify as verify_module
from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.verify.report import PROPERTIES
from support.ver_models import PAPER_EDGES, paper_fsm


@pytest.fixture()
def files(tmp_path):
    source = paper_fsm()
    mutated = copy.deepcopy(source)
    mutated.transitions[PAPER_EDGES.index("BC")].target = "D"
    paths = {
        "source": api.write(source, tmp_path / "source.json"),
        "copy": api.write(copy.deepcopy(source), tmp_path / "copy.json"),
        "mutated": api.write(mutated, tmp_path / "mutated.json"),
        "lebt": api.write(fsm_to_lebt(source).model, tmp_path / "lebt.json"),
    }
    return {k: str(v) for k, v in paths.items()}


def test_equivalent_pair_exits_0(files, capsys):
    assert main(["verify", files["source"], files["copy"]]) == 0
    out = capsys.readouterr().out
    assert "EQUIVALENT" in out and "NOT EQUIVALENT" not in out
    assert out.count("PASS") == len(PROPERTIES)


def test_fsm_against_its_lebt_exits_0(files):
    assert main(["verify", files["source"], files["lebt"]]) == 0


def test_not_equivalent_exits_1_with_a_counterexample_table(files, capsys):
    assert main(["verify", files["source"], files["mutated"]]) == 1
    out = capsys.readouterr().out
    assert "NOT EQUIVALENT" in out
    assert "shortest counterexample" in out
    assert "eventBC" in out and "FAIL" in out


def test_json_report(files, capsys):
    assert main(["verify", files["source"], files["mutated"], "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["equivalent"] is False
    assert set(data["properties"]) == set(PROPERTIES)
    completeness = data["properties"]["completeness"]
    assert completeness["holds"] is False
    steps = completeness["counterexample"]
    assert [s["input"] for s in steps] == [None, "eventStartA", "eventAB", "eventBC"]
    assert steps[-1]["source_outputs"] == ["C"] and steps[-1]["result_outputs"] == ["D"]
    assert data["stats"]["product_states"] > 0


def test_missing_file_is_bad_input(files, tmp_path, capsys):
    assert main(["verify", files["source"], str(tmp_path / "nope.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1


def test_unknown_engine_is_bad_input(files, capsys):
    assert main(["verify", files["source"], files["copy"], "--engine", "magic"]) == 2
    assert "unknown verification engine" in capsys.readouterr().err


def test_engine_disagreement_exits_3(files, monkeypatch, capsys):
    def flipped_nusmv(source, result, loop, *_pairing, **_options):
        report = verify_module.verify(source, result)
        report.properties["deadlock_absence"].holds = False
        return report

    monkeypatch.setattr(verify_module, "_nusmv", flipped_nusmv)
    assert main(["verify", files["source"], files["copy"], "--engine", "both"]) == 3
    assert "ENGINES DISAGREE" in capsys.readouterr().err


def test_engine_both_agreeing_exits_like_native(files, monkeypatch):
    monkeypatch.setattr(
        verify_module,
        "_nusmv",
        lambda source, result, loop, *_pairing, **_options: verify_module.verify(source, result),
    )
    assert main(["verify", files["source"], files["mutated"], "--engine", "both"]) == 1


def test_nusmv_engine_answers_or_says_it_is_missing(files, capsys):
    code = main(["verify", files["source"], files["copy"], "--engine", "nusmv"])
    if code == 2:
        assert "NuSMV" in capsys.readouterr().err
    else:
        assert code == 0
