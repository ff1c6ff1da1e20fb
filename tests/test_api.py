"""The library API (fsmbt.api): one pipeline that every layer calls.

What is pinned here: an outcome carries both models, the verdict and timings; the destination
is refused before any work; a result that is not equivalent is not written unless asked for;
writes are atomic; a text is read without touching the disk.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.convert import ConversionResult, register_engine
from fsmbt.convert.engines import _ENGINES
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.verify.mutations import mutants

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PAPER_FSM = EXAMPLES / "paper_fsm.xml"
ROBOT_BT = EXAMPLES / "robot_bt.xml"


def test_convert_file_gives_one_outcome_with_models_verdict_and_timings(tmp_path: Path) -> None:
    out = tmp_path / "sub" / "paper_bt.xml"
    outcome = api.convert_file(PAPER_FSM, out)
    assert isinstance(outcome.source.model, FSM)
    assert isinstance(outcome.result, BTDocument)
    assert outcome.source.format == "paper-xml"
    assert outcome.equivalent is True and outcome.verdict == api.EQUIVALENT
    assert outcome.written and out.read_text(encoding="utf-8") == outcome.text
    assert outcome.output_format == "btcpp"
    assert set(outcome.timings) == {"read", "convert", "verify", "load", "write"}
    assert outcome.load is not None and outcome.load.loaded
    summary = outcome.to_dict()
    assert summary["verdict"] == "EQUIVALENT" and summary["direction"] == "fsm->bt"
    assert all(summary["properties"].values()) and len(summary["properties"]) == 5


def test_convert_file_bt_to_fsm_without_output_keeps_the_text() -> None:
    outcome = api.convert_file(ROBOT_BT)
    assert outcome.output is None and not outcome.written
    assert outcome.output_format == "scxml" and outcome.text.lstrip().startswith("<")
    assert outcome.equivalent is True


def test_stages_are_announced_in_order(tmp_path: Path) -> None:
    seen: list[str] = []
    api.convert_file(PAPER_FSM, tmp_path / "x.xml", on_stage=seen.append)
    assert seen == ["read", "convert", "verify", "load", "write"]
    seen.clear()
    api.convert_file(PAPER_FSM, verify=False, on_stage=seen.append)
    assert seen == ["read", "convert", "load"]
    seen.clear()
    api.convert_file(PAPER_FSM, verify=False, load_check=False, on_stage=seen.append)
    assert seen == ["read", "convert"]


def test_existing_destination_is_refused_before_any_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "taken.xml"
    out.write_text("the user's file", encoding="utf-8")

    def must_not_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("the conversion ran although the destination is refused")

    monkeypatch.setattr(api, "load", must_not_run)
    monkeypatch.setattr(api, "load_for_llm", must_not_run)
    with pytest.raises(api.DestinationExists) as caught:
        api.convert_file(PAPER_FSM, out)
    assert "taken.xml" in str(caught.value)
    assert out.read_text(encoding="utf-8") == "the user's file"
    with pytest.raises(InputError, match="is a folder"):
        api.convert_file(PAPER_FSM, tmp_path)


@pytest.fixture
def wrong_engine():
    """An engine whose FSM -> BT result is a behaviour-changing mutant of the right one."""

    def fsm_to_bt(model: FSM, **options: object) -> ConversionResult:
        right = api.convert_model(model, "rules")
        for mutant in mutants(right.model, seed=3):
            report = api.verify_models(model, mutant.model)
            if not report.equivalent:
                return ConversionResult(mutant.model, "wrong", right.direction)
        raise AssertionError("no behaviour-changing mutant found")

    register_engine("wrong-for-test", fsm_to_bt, None, "a deliberately wrong engine")
    yield "wrong-for-test"
    _ENGINES.pop("wrong-for-test", None)


def test_not_equivalent_result_is_not_written_unless_asked(
    tmp_path: Path, wrong_engine: str
) -> None:
    out = tmp_path / "bt.xml"
    outcome = api.convert_file(PAPER_FSM, out, engine=wrong_engine)
    assert outcome.equivalent is False and outcome.verdict == api.NOT_EQUIVALENT
    assert not outcome.written and not out.exists()
    assert outcome.text  # the user can still see what was produced
    kept = api.convert_file(PAPER_FSM, out, engine=wrong_engine, keep_not_equivalent=True)
    assert kept.written and out.read_text(encoding="utf-8") == kept.text


def test_unverified_result_is_written(tmp_path: Path) -> None:
    out = tmp_path / "bt.xml"
    outcome = api.convert_file(PAPER_FSM, out, verify=False)
    assert outcome.report is None and outcome.verdict == api.NOT_VERIFIED and out.exists()


def test_write_text_is_atomic_and_leaves_no_temporary_files(tmp_path: Path) -> None:
    target = tmp_path / "model.json"
    api.write_text("first", target)
    with pytest.raises(api.DestinationExists):
        api.write_text("second", target)
    assert target.read_text(encoding="utf-8") == "first"
    api.write_text("second", target, overwrite=True)
    assert target.read_text(encoding="utf-8") == "second"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.json"]


def test_write_refuses_a_format_that_cannot_hold_the_model(tmp_path: Path) -> None:
    fsm = api.load(PAPER_FSM).model
    with pytest.raises(InputError, match="cannot hold"):
        api.write(fsm, tmp_path / "x.xml", "btcpp")
    assert list(tmp_path.iterdir()) == []


def test_load_text_detects_the_format_and_never_opens_the_filename(tmp_path: Path) -> None:
    text = PAPER_FSM.read_text(encoding="utf-8")
    loaded = api.load_text(text, filename="../../etc/passwd.xml")
    assert loaded.path is None and loaded.kind == "fsm" and loaded.format == "paper-xml"
    with pytest.raises(InputError):
        api.load_text("this is not a model", filename="notes.txt")


def test_verify_files_reads_both_and_reports(tmp_path: Path) -> None:
    out = tmp_path / "bt.xml"
    api.convert_file(PAPER_FSM, out)
    first, second, report = api.verify_files(PAPER_FSM, out)
    assert first.kind == "fsm" and second.kind == "bt" and report.equivalent


def test_llm_engine_input_read_by_a_parser_keeps_its_format_and_warnings() -> None:
    # hybrid asks the LLM only when no parser reads the file: here the paper's XML reader does
    loaded, client = api.load_for_llm(PAPER_FSM, api.ConvertRequest(engine="hybrid"))
    assert client is None
    assert loaded.format == "paper-xml" and not loaded.extracted_by_llm
    assert loaded.warnings == api.load(PAPER_FSM).warnings


def test_written_results_honour_the_umask_and_keep_a_replaced_files_mode(tmp_path: Path) -> None:
    import os
    import stat

    previous = os.umask(0o022)
    try:
        fresh = api.write_text("x", tmp_path / "fresh.txt")
        assert stat.S_IMODE(fresh.stat().st_mode) == 0o644
        kept = tmp_path / "kept.txt"
        kept.write_text("old", encoding="utf-8")
        kept.chmod(0o640)
        api.write_text("new", kept, overwrite=True)
        assert stat.S_IMODE(kept.stat().st_mode) == 0o640
        assert kept.read_text(encoding="utf-8") == "new"
    finally:
        os.umask(previous)
