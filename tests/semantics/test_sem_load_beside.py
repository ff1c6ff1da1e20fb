"""The load check beside the proof (``fsmbt.semantics.engines.load_beside``): a large SCXML
result is loaded by python-statemachine in a child process while the proof runs, with the same
answer as the check in process; a check nobody reads is stopped, its child killed and its file
removed; a child that gives no answer is a refusal that says so."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.formats import dumps
from fsmbt.semantics.engines import load_beside
from fsmbt.semantics.engines.btcpp_load import LoadCheck
from fsmbt.semantics.engines.scxml_load import check_scxml_loads
from support.chains import chain

pytest.importorskip("statemachine")

BROKEN_SCXML = (
    '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="nowhere">'
    '<state id="a"/></scxml>'
)


@pytest.fixture
def every_scxml_in_a_child(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(load_beside, "BESIDE_BYTES", 0)


@pytest.mark.usefixtures("every_scxml_in_a_child")
def test_a_child_gives_the_same_answer_as_the_check_in_process() -> None:
    text = dumps(chain(40), "scxml")
    pending = load_beside.start_load_check(text, "scxml")
    assert pending.in_child
    assert pending.result() == check_scxml_loads(text)
    assert pending.result() is not None and pending.result().loaded  # type: ignore[union-attr]
    refused = load_beside.start_load_check(BROKEN_SCXML, "scxml")
    answer = refused.result()
    assert answer is not None and not answer.loaded and "nowhere" in answer.error
    assert answer == check_scxml_loads(BROKEN_SCXML)


def test_a_small_document_is_checked_in_process() -> None:
    pending = load_beside.start_load_check(dumps(chain(5), "scxml"), "scxml")
    assert not pending.in_child
    assert pending.result() is not None and pending.result().loaded  # type: ignore[union-attr]
    assert load_beside.start_load_check("anything", "mermaid").result() is None


@pytest.mark.usefixtures("every_scxml_in_a_child")
def test_cancel_kills_the_child_and_removes_its_file(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(load_beside, "CHILD_COMMAND", ("-c", "import time; time.sleep(60)"))
    pending = load_beside.start_load_check(dumps(chain(5), "scxml"), "scxml")
    child, file = pending._child, pending._file  # noqa: SLF001 - what cancel must clean
    assert child is not None and file is not None and Path(file).exists()
    pending.cancel()
    assert child.poll() is not None  # killed and reaped: no process left behind
    assert not Path(file).exists()


@pytest.mark.usefixtures("every_scxml_in_a_child")
def test_a_child_without_an_answer_is_a_refusal(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(
        load_beside, "CHILD_COMMAND", ("-c", "import sys; sys.stderr.write('boom'); sys.exit(3)")
    )
    answer = load_beside.start_load_check(dumps(chain(5), "scxml"), "scxml").result()
    assert answer is not None and not answer.loaded
    assert "gave no answer" in answer.error and "boom" in answer.error


@pytest.mark.usefixtures("every_scxml_in_a_child")
def test_convert_checks_beside_the_proof_and_stops_the_check_when_the_proof_fails(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    robot = Path(__file__).resolve().parents[2] / "examples" / "robot_bt.xml"
    outcome = api.convert_file(robot, tmp_path / "robot.scxml")
    assert outcome.written and outcome.equivalent
    assert outcome.load is not None and outcome.load.loaded

    started: list[load_beside.PendingLoad] = []

    def recording(text: str, fmt: str) -> load_beside.PendingLoad:
        started.append(load_beside.PendingLoad(fmt, text))
        return started[-1]

    def failing(*_args: object, **_kwargs: object) -> None:
        raise RuntimeError("the proof broke")

    monkeypatch.setattr(api, "start_load_check", recording)
    monkeypatch.setattr(api, "verify_models", failing)
    with pytest.raises(RuntimeError, match="the proof broke"):
        api.convert_file(robot, tmp_path / "again.scxml")
    assert len(started) == 1
    child = started[0]._child  # noqa: SLF001
    assert child is not None and child.poll() is not None
    assert not (tmp_path / "again.scxml").exists()


@pytest.mark.usefixtures("every_scxml_in_a_child")
def test_a_child_that_cannot_start_leaves_the_check_to_this_process(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def no_process(*_args: object, **_kwargs: object) -> None:
        raise OSError("no process for you")

    monkeypatch.setattr(load_beside.subprocess, "Popen", no_process)
    text = dumps(chain(5), "scxml")
    pending = load_beside.start_load_check(text, "scxml")
    assert not pending.in_child and pending._file is None  # noqa: SLF001 - its file removed
    assert pending.result() == check_scxml_loads(text)


def test_the_child_answers_one_json_line_with_the_collector_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``scxml_load.main`` (what the child runs) turns Python's cyclic collector off before the
    load (the engine's objects all live until the process ends; the collector's passes cost
    more than the load: ``benchmarks/bench_load_check.py``) and answers as the check does."""
    import gc
    import json

    from fsmbt.semantics.engines import scxml_load

    text = dumps(chain(8), "scxml")
    (tmp_path / "c.scxml").write_text(text, encoding="utf-8")
    monkeypatch.setattr(scxml_load.sys, "argv", ["scxml_load", str(tmp_path / "c.scxml")])

    def exit_here(status: int) -> None:
        raise SystemExit(status)

    monkeypatch.setattr(scxml_load.os, "_exit", exit_here)
    assert gc.isenabled()
    try:
        with pytest.raises(SystemExit) as ended:
            scxml_load.main()
        assert not gc.isenabled()
    finally:
        gc.enable()
    assert ended.value.code == 0
    answer = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert check_scxml_loads(text) == LoadCheck(**answer)
    assert answer["loaded"] is True
