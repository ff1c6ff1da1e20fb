"""LLM fault injection against the scripted server: every fault is a failed attempt or a failed
round with its cause in the log, the conversion goes on to the next attempt or round (or, when
the endpoint never recovers, the next conversion), and nothing already obtained is lost.

Faults: truncated JSON (in the model's answer, and in the HTTP body itself), a reply in another
format (YAML instead of JSON; an HTML error page instead of a chat completion), a reply that
names unknown states, 10 MB of text, a slow trickle, and a connection reset mid-reply. Plumbing
only: the answers are written here and the verdicts come from the project's checker.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from fsmbt import limits
from fsmbt.formats.registry import loads
from fsmbt.llm.client import LLMClient
from fsmbt.llm.config import LLMSettings, LLMUnavailableError
from fsmbt.llm.log import read_records
from fsmbt.llm.pipeline import LLMOutcome, convert_with_llm
from fsmbt.model.bt import BTDocument
from support.scripted_server import ScriptedServer

BT_XML = """<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence>
<Condition ID="IsReady" name="IsReady"/><Action ID="Work" name="Work"/></Sequence></BehaviorTree>
<TreeNodesModel><Condition ID="IsReady"/><Action ID="Work"/></TreeNodesModel></root>"""

GOOD = (
    '{"kind": "fsm", "initial": "IsReady", "states": [{"name": "IsReady", "action": '
    '"IsReady"}, {"name": "Work", "action": "Work"}, {"name": "SUCCESS", "action": "SUCCESS", '
    '"final": true}, {"name": "FAILURE", "action": "FAILURE", "final": true}], '
    '"transitions": [{"source": "IsReady", "event": "success", "target": "Work"}, '
    '{"source": "IsReady", "event": "failure", "target": "FAILURE"}, '
    '{"source": "Work", "event": "success", "target": "SUCCESS"}, '
    '{"source": "Work", "event": "failure", "target": "FAILURE"}, '
    '{"source": "Work", "event": "running", "target": "Work"}]}'
)
WRONG = GOOD.replace(
    '{"source": "Work", "event": "failure", "target": "FAILURE"}',
    '{"source": "Work", "event": "failure", "target": "SUCCESS"}',
)


@pytest.fixture
def bt() -> BTDocument:
    model = loads(BT_XML, "btcpp")
    assert isinstance(model, BTDocument)
    return model


def client_for(server: ScriptedServer, tmp_path: Path, **changes: object) -> LLMClient:
    settings = LLMSettings(
        base_url=server.base_url,
        model="scripted",
        api_key="k",
        backoff_s=0.01,
        timeout_s=8.0,
        max_retries=2,
        max_regenerations=2,
        log_path=tmp_path / "llm.jsonl",
    )
    return LLMClient(replace(settings, **changes))


def logged(tmp_path: Path) -> list[dict[str, object]]:
    return read_records(tmp_path / "llm.jsonl")


# -- faults in the model's answer: a failed round, fed back, the next round succeeds -------------
@pytest.mark.parametrize(
    ("name", "answer", "cause"),
    [
        ("truncated JSON", GOOD[: len(GOOD) // 2], "holds no JSON object|invalid JSON"),
        (
            "another format",
            "kind: fsm\ninitial: IsReady\nstates:\n  - name: IsReady\n",
            "holds no JSON object",
        ),
        ("unknown states", GOOD.replace('"target": "SUCCESS"}', '"target": "Nowhere"}'), "Nowhere"),
    ],
)
def test_a_bad_answer_is_a_failed_round_with_its_cause_and_the_next_round_runs(
    bt: BTDocument, tmp_path: Path, name: str, answer: str, cause: str
) -> None:
    with ScriptedServer([{"content": answer}, {"content": GOOD}]) as server:
        outcome = convert_with_llm(bt, client_for(server, tmp_path))
    assert outcome.equivalent, name
    first, second = outcome.record.rounds
    assert first.stage in ("parse", "structure") and second.stage == "ok"
    assert any(__import__("re").search(cause, p) for p in first.problems), first.problems
    feedback = server.requests[1]["body"]["messages"][-1]["content"]
    assert any(p in feedback for p in first.problems)  # the cause went back to the model
    (record,) = logged(tmp_path)
    assert record["verdict"] == "equivalent" and record["regenerations"] == 1
    assert record["rounds"][0]["problems"] == first.problems  # the cause is in the log


# -- faults in the transport: a failed attempt with its cause, retried in the same round ---------
def _attempt_fault_then_good(
    fault: dict[str, object], bt: BTDocument, tmp_path: Path, **settings: object
) -> tuple[LLMOutcome, list[str]]:
    with ScriptedServer([fault, {"content": GOOD}]) as server:
        outcome = convert_with_llm(bt, client_for(server, tmp_path, **settings))
        assert len(server.requests) == 2
    assert outcome.equivalent
    (only_round,) = outcome.record.rounds
    assert only_round.stage == "ok" and only_round.attempts == 2
    assert len(only_round.failures) == 1
    (record,) = logged(tmp_path)
    assert record["rounds"][0]["failures"] == only_round.failures  # the cause is logged
    return outcome, only_round.failures


def test_ten_megabytes_of_text_is_cut_off_at_the_limit_and_retried(
    bt: BTDocument, tmp_path: Path
) -> None:
    huge = {"content": "x" * (10 * 1024 * 1024)}
    _, failures = _attempt_fault_then_good(huge, bt, tmp_path)
    limit = limits.current().llm_max_response_bytes
    assert f"exceeded {limit} bytes" in failures[0]
    assert "FSMBT_MAX_LLM_RESPONSE_BYTES" in failures[0]


def test_the_response_limit_is_the_one_in_fsmbt_limits(bt: BTDocument, tmp_path: Path) -> None:
    with limits.changed(llm_max_response_bytes=200):
        with ScriptedServer([{"content": GOOD}]) as server:
            with pytest.raises(LLMUnavailableError, match="exceeded 200 bytes"):
                convert_with_llm(bt, client_for(server, tmp_path, max_retries=0))


def test_truncated_json_body_is_a_failed_attempt(bt: BTDocument, tmp_path: Path) -> None:
    _, failures = _attempt_fault_then_good({"raw": '{"id": "x", "choices": [{"mess'}, bt, tmp_path)
    assert "unusable response" in failures[0] or "not a chat completion" in failures[0]


def test_an_html_page_instead_of_a_completion_is_a_failed_attempt(
    bt: BTDocument, tmp_path: Path
) -> None:
    page = {"raw": "<html><body>502 Bad Gateway</body></html>", "content_type": "text/html"}
    _, failures = _attempt_fault_then_good(page, bt, tmp_path)
    assert "attempt 1:" in failures[0]


def test_connection_reset_mid_reply_is_a_failed_attempt(bt: BTDocument, tmp_path: Path) -> None:
    _, failures = _attempt_fault_then_good({"content": GOOD, "reset_after": 40}, bt, tmp_path)
    assert "connection broke during the answer" in failures[0]


def test_a_slow_trickle_cannot_hold_the_request_past_its_deadline(
    bt: BTDocument, tmp_path: Path
) -> None:
    import time

    trickle = {"content": GOOD, "trickle": 0.05, "chunk": 1}  # ~40 s for the whole body
    with ScriptedServer([trickle, {"content": WRONG}, {"content": GOOD}]) as server:
        started = time.monotonic()
        with pytest.raises(LLMUnavailableError, match="still arriving after 1.5 s") as caught:
            convert_with_llm(
                bt, client_for(server, tmp_path, timeout_s=1.5), source_name="first.xml"
            )
        assert time.monotonic() - started < 6.0
        # nothing lost: the record is logged with the failed round and its cause, and the
        # partial outcome travels on the exception
        outcome = caught.value.outcome
        assert isinstance(outcome, LLMOutcome)
        assert outcome.record.rounds[-1].stage == "unavailable"
        assert "still arriving" in outcome.record.rounds[-1].failures[0]
        # the run goes on: the next conversion with the same client and server works
        second = convert_with_llm(bt, client_for(server, tmp_path), source_name="second.xml")
    assert second.equivalent and [r.stage for r in second.record.rounds] == ["verify", "ok"]
    first_record, second_record = logged(tmp_path)
    assert first_record["source"] == "first.xml"
    assert first_record["verdict"] == "endpoint_unavailable"
    assert "still arriving" in first_record["rounds"][-1]["failures"][0]
    assert second_record["source"] == "second.xml" and second_record["verdict"] == "equivalent"


def test_a_failed_later_round_keeps_the_earlier_rounds_and_their_result(
    bt: BTDocument, tmp_path: Path
) -> None:
    # round 1: a wrong (but parsed and verified) answer; round 2: the endpoint keeps resetting
    steps = [{"content": WRONG}] + [{"content": GOOD, "reset_after": 10}] * 3
    with ScriptedServer(steps) as server:
        with pytest.raises(LLMUnavailableError, match="failed after 3 attempt") as caught:
            convert_with_llm(bt, client_for(server, tmp_path))
    outcome = caught.value.outcome
    assert isinstance(outcome, LLMOutcome)
    assert outcome.result is not None and outcome.report is not None  # round 1's result
    assert not outcome.report.equivalent
    stages = [r.stage for r in outcome.record.rounds]
    assert stages == ["verify", "unavailable"]
    assert len(outcome.record.rounds[1].failures) == 3
    (record,) = logged(tmp_path)
    assert [r["stage"] for r in record["rounds"]] == stages
    assert all("connection broke" in f for f in record["rounds"][1]["failures"])
