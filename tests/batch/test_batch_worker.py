"""run_job: every problem of a model is a row with its status, class and located message.

The equivalent rows are checked again here: the written output is read back and verified
against its source by the native checker (nothing is taken from the row itself).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.batch import Job, make_jobs, run_job
from fsmbt.generate import DatasetSpec, generate_models

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_an_equivalent_result_is_written_and_verifies_on_reading_back(tmp_path: Path) -> None:
    jobs = make_jobs([EXAMPLES], tmp_path / "out")
    trees = 0
    for job in jobs:
        result = run_job(job)
        assert result.status == "equivalent", result.error_message
        assert result.output == job.output and result.verdict == api.EQUIVALENT
        assert set(result.properties) and all(result.properties.values())
        assert result.stats["product_states"] > 0 and result.timings["total"] > 0
        if result.stats["output_format"] == "btcpp":  # every written tree is loaded
            trees += 1
            assert result.stats["loads"].startswith("loads in BehaviorTree.CPP 4.8.2") and (
                result.stats["loads"].endswith(": yes")
            )
        source = api.load(job.input).model
        written = api.load(result.output).model
        assert api.verify_either_order(source, written).equivalent
    assert trees > 0


@pytest.mark.parametrize(
    ("name", "text", "cause"),
    [
        ("broken.xml", "<root><BehaviorTree><Sequence></root>", "broken.xml"),
        (
            "bomb.xml",
            '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaa">'
            '<!ENTITY b "&a;&a;&a;&a;">]><root>&b;</root>',
            "bomb.xml",
        ),
        ("binary.json", "\x00\x01\x02 not text", "binary.json"),
    ],
)
def test_malformed_and_hostile_inputs_are_bad_input_rows(
    tmp_path: Path, name: str, text: str, cause: str
) -> None:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    result = run_job(Job(str(path), str(tmp_path / "out.scxml")))
    assert result.status == "bad_input"
    assert result.error_class is not None and cause in (result.error_message or "")
    assert not (tmp_path / "out.scxml").exists()


def test_a_missing_file_a_folder_and_a_fifo_are_rows(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.xml"
    os.mkfifo(fifo)
    for path in (tmp_path / "missing.xml", tmp_path, fifo):
        result = run_job(Job(str(path), None))
        assert result.status == "bad_input" and str(path) in (result.error_message or "")


def test_a_too_large_input_is_a_row(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from fsmbt import limits

    # the limits in force, with a 100-byte input cap (monkeypatch restores them afterwards)
    monkeypatch.setattr(limits, "_current", limits.current().with_changes(max_input_bytes=100))
    big = tmp_path / "big.json"
    big.write_text((EXAMPLES / "paper_fsm.json").read_text(encoding="utf-8"), encoding="utf-8")
    result = run_job(Job(str(big), None))
    assert result.status == "bad_input" and "limit" in (result.error_message or "")


def test_a_model_the_engine_cannot_convert_exactly_is_a_refused_row(tmp_path: Path) -> None:
    path = tmp_path / "start.json"
    path.write_text(
        json.dumps(
            {
                "kind": "fsm",
                "name": "m",
                "initial": "__start__",
                "states": [{"name": "__start__", "action": "a"}, {"name": "B", "action": "b"}],
                "transitions": [{"source": "__start__", "event": "go", "target": "B"}],
            }
        ),
        encoding="utf-8",
    )
    # the LEBT reserves the name __start__ (the dispatch form, auto's choice here, does not)
    result = run_job(Job(str(path), None, options={"style": "lebt"}))
    assert result.status == "refused" and result.error_class == "UnsupportedError"
    assert "start pseudo-state" in (result.error_message or "")


def test_an_existing_output_is_refused_and_kept_unless_overwrite(tmp_path: Path) -> None:
    out = tmp_path / "robot_bt.scxml"
    out.write_text("mine", encoding="utf-8")
    job = Job(str(EXAMPLES / "robot_bt.xml"), str(out))
    refused = run_job(job)
    assert refused.status == "refused" and refused.error_class == "DestinationExists"
    assert refused.retry and out.read_text(encoding="utf-8") == "mine"
    forced = run_job(Job(job.input, job.output, overwrite=True))
    assert forced.status == "equivalent" and api.load(out).kind == "fsm"


def _big_fsm(tmp_path: Path) -> Path:
    spec = DatasetSpec("fsm", seed=3, min_states=30, max_states=30)
    _, model = next(generate_models(spec, 1))
    return api.write(model, tmp_path / "big.json", "json")


def test_the_state_limit_is_a_limit_row(tmp_path: Path) -> None:
    result = run_job(Job(str(_big_fsm(tmp_path)), None, options={"max_states": 5}))
    assert result.status == "limit" and result.error_class == "StateLimitError"
    assert "5" in (result.error_message or "")


def test_a_reader_s_limit_is_a_limit_row_too(tmp_path: Path) -> None:
    """An unbounded SCXML variable stops the reader with its own ``StateLimitError`` (a
    ``LimitError``, fsmbt.model.errors): recorded as over a limit, not as malformed input."""
    path = tmp_path / "counter.scxml"
    path.write_text(
        '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" datamodel="ecmascript">'
        '<datamodel><data id="n" expr="0"/></datamodel>'
        '<state id="s"><transition event="tick" target="s"><assign location="n" expr="n + 1"/>'
        '</transition><transition event="stop" cond="n == 3" target="s"/></state></scxml>'
    )
    result = run_job(Job(str(path), str(tmp_path / "out.xml")))
    assert result.status == "limit", (result.status, result.error_message)
    assert "'n'" in (result.error_message or "")


def test_the_time_limit_is_a_timeout_row(tmp_path: Path) -> None:
    result = run_job(Job(str(_big_fsm(tmp_path)), None, options={"timeout_s": 0.001}))
    assert result.status == "timeout" and result.error_class == "JobTimeout"
    assert "0.001 s" in (result.error_message or "")
    again = run_job(Job(str(tmp_path / "big.json"), None, options={"timeout_s": 120}))
    assert again.status == "equivalent"  # the alarm is cleared: a later job is not cut short


def test_no_verify_is_a_not_verified_row(tmp_path: Path) -> None:
    result = run_job(
        Job(str(EXAMPLES / "robot_bt.xml"), str(tmp_path / "r.scxml"), verify_engine="none")
    )
    assert result.status == "not_verified" and result.properties == {}
    assert Path(result.output or "").exists()


@pytest.mark.nusmv
def test_both_verifiers_in_a_batch_row(tmp_path: Path) -> None:
    from fsmbt.verify.nusmv.binary import find_nusmv

    if find_nusmv() is None:
        pytest.skip("NuSMV is not available (FSMBT_NUSMV, PATH or .cache/nusmv)")
    result = run_job(
        Job(str(EXAMPLES / "paper_fsm.xml"), str(tmp_path / "p.xml"), verify_engine="both")
    )
    assert result.status == "equivalent", result.error_message
    assert result.verify_engine == "both" and all(result.properties.values())
