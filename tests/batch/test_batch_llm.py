"""LLM engines in a batch, against the tests' scripted OpenAI-compatible server: a request that
keeps failing (5xx) is a row with its cause and runs again on resume; requests at once are
bounded by the concurrency limit; the per-minute window is shared through its file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.batch import ResultStore, make_jobs, run_jobs
from fsmbt.batch.ratelimit import MinuteRateLimit
from fsmbt.formats import dumps
from support.scripted_server import ScriptedServer

FSM_JSON = {
    "kind": "fsm",
    "name": "door",
    "initial": "Closed",
    "states": [{"name": "Closed", "action": "close"}, {"name": "Open", "action": "open"}],
    "transitions": [
        {"source": "Closed", "event": "push", "target": "Open"},
        {"source": "Open", "event": "pull", "target": "Closed"},
    ],
}


@pytest.fixture(autouse=True)
def llm_env(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    for name in (
        "FSMBT_LLM_BASE_URL",
        "FSMBT_LLM_MODEL",
        "OPENAI_API_KEY",
        "FSMBT_LLM_CONFIG",
        "FSMBT_LLM_TIMEOUT",
    ):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("FSMBT_LLM_API_KEY", "k")
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("FSMBT_LLM_LOG", str(tmp_path / "llm.jsonl"))


def _doors(folder: Path, n: int) -> list[Path]:
    folder.mkdir(parents=True)
    paths = []
    for index in range(n):
        path = folder / f"door{index}.json"
        path.write_text(json.dumps(FSM_JSON), encoding="utf-8")
        paths.append(path)
    return paths


def _answer() -> str:
    model = api.load_text(json.dumps(FSM_JSON), "json").model
    return dumps(api.convert_model(model, style="lebt").model, "btcpp")  # LLMs write LEBTs


def test_a_failing_endpoint_is_a_row_with_its_cause_and_runs_again_on_resume(
    tmp_path: Path,
) -> None:
    _doors(tmp_path / "in", 1)
    out = tmp_path / "out"
    with ScriptedServer([{"status": 503}]) as server:
        jobs = make_jobs(
            [tmp_path / "in"],
            out,
            engine="llm",
            options={"llm_base_url": server.base_url, "llm_model": "m", "llm_timeout": 3.0},
        )
        with ResultStore(out) as store:
            [failed] = run_jobs(jobs, store=store)
            assert failed.status == "error" and failed.error_class == "LLMUnavailableError"
            assert "503" in (failed.error_message or "") and failed.retry
            assert not store.done(jobs[0].key)
        assert len(server.requests) > 1  # the client retried the 5xx before giving up
    with ScriptedServer([{"content": _answer()}]) as server:
        jobs = make_jobs(
            [tmp_path / "in"],
            out,
            engine="llm",
            options={"llm_base_url": server.base_url, "llm_model": "m", "llm_timeout": 30.0},
        )
        with ResultStore(out) as store:
            [resumed] = run_jobs(jobs, store=store)
            assert resumed.status == "equivalent", resumed.error_message
            assert [r.status for r in store.results()] == ["equivalent"]
    source = api.load(jobs[0].input).model
    assert api.verify_either_order(source, api.load(resumed.output or "").model).equivalent


def test_requests_at_once_are_bounded_by_the_concurrency_limit(tmp_path: Path) -> None:
    _doors(tmp_path / "in", 4)
    delay = 1.0
    with ScriptedServer([{"content": _answer(), "delay": delay}]) as server:
        jobs = make_jobs(
            [tmp_path / "in"],
            tmp_path / "out",
            engine="llm",
            options={"llm_base_url": server.base_url, "llm_model": "m"},
        )
        results = run_jobs(jobs, workers=4, llm_concurrency=2)
        arrivals = sorted(request["time"] for request in server.requests)
    assert {r.status for r in results} == {"equivalent"}, [r.error_message for r in results]
    assert len(arrivals) == 4
    overlapping = max(
        sum(1 for other in arrivals if start <= other < start + delay) for start in arrivals
    )
    assert overlapping <= 2


def test_the_per_minute_window_is_shared_through_its_file(tmp_path: Path) -> None:
    now = [1000.0]
    slept: list[float] = []

    def sleep(seconds: float) -> None:
        slept.append(seconds)
        now[0] += seconds

    shared = tmp_path / "rate"
    first = MinuteRateLimit(shared, 2, clock=lambda: now[0], sleep=sleep)
    second = MinuteRateLimit(shared, 2, clock=lambda: now[0], sleep=sleep)  # another worker
    assert first.acquire() == 0.0
    now[0] += 10
    assert second.acquire() == 0.0
    waited = first.acquire()  # the window holds 2 starts: wait until the oldest leaves it
    assert waited == pytest.approx(50.0) and slept == [pytest.approx(50.0)]
    assert second.acquire() == pytest.approx(10.0)
