"""The generate -> parse -> check -> verify -> feedback loop against scripted answers.

Plumbing only: the scripted answers are written here, the verdicts come from the project's
checker, and no figure about any real model's accuracy follows from these tests.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from fsmbt.formats.registry import loads
from fsmbt.llm.client import LLMClient
from fsmbt.llm.config import LLMSettings, LLMUnavailableError
from fsmbt.llm.engine import LLMConversionError, _run
from fsmbt.llm.log import read_records
from fsmbt.llm.pipeline import convert_with_llm
from fsmbt.model.bt import BTDocument
from support.scripted_server import ScriptedServer

BT_XML = """<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence>
<Condition ID="IsReady" name="IsReady"/><Action ID="Work" name="Work"/></Sequence></BehaviorTree>
<TreeNodesModel><Condition ID="IsReady"/><Action ID="Work"/></TreeNodesModel></root>"""

STATES = (
    '[{"name": "IsReady", "action": "IsReady"}, {"name": "Work", "action": "Work"}, '
    '{"name": "SUCCESS", "action": "SUCCESS", "final": true}, '
    '{"name": "FAILURE", "action": "FAILURE", "final": true}]'
)


def fsm_answer(work_failure_target: str = "FAILURE", states: str = STATES) -> str:
    return (
        '{"kind": "fsm", "initial": "IsReady", "states": ' + states + ', "transitions": ['
        '{"source": "IsReady", "event": "success", "target": "Work"},'
        '{"source": "IsReady", "event": "failure", "target": "FAILURE"},'
        '{"source": "Work", "event": "success", "target": "SUCCESS"},'
        f'{{"source": "Work", "event": "failure", "target": "{work_failure_target}"}},'
        '{"source": "Work", "event": "running", "target": "Work"}]}'
    )


GOOD = "Here is the HFSM:\n```json\n" + fsm_answer() + "\n```\nIt follows the rules."
WRONG = fsm_answer(work_failure_target="SUCCESS")


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
        timeout_s=5.0,
        max_regenerations=2,
        log_path=tmp_path / "llm.jsonl",
    )
    return LLMClient(replace(settings, **changes))


def test_first_pass_success_is_verified_and_logged(bt: BTDocument, tmp_path: Path) -> None:
    with ScriptedServer([{"content": GOOD}]) as server:
        outcome = convert_with_llm(bt, client_for(server, tmp_path), source_name="seq.xml")
    assert outcome.equivalent and outcome.report is not None
    assert len(server.requests) == 1
    (record,) = read_records(tmp_path / "llm.jsonl")
    assert record["first_pass_success"] is True and record["regenerations"] == 0
    assert record["verdict"] == "equivalent" and record["task"] == "bt_to_fsm"
    assert record["tokens_in"] == 101 and record["tokens_out"] > 0 and record["latency_s"] >= 0
    assert (
        record["source"] == "seq.xml" and "k" not in json.dumps(record).split('"api_key"')[0][-3:]
    )
    # the prompt has the four parts and the model
    text = server.user_texts(0)
    system = server.requests[0]["body"]["messages"][0]
    assert system["role"] == "system" and "conversion engineer" in system["content"]
    for part in ("# Task", "# Stepwise Conversion Procedure", "# Constraints", "Condition IsReady"):
        assert part in text


def test_wrong_answer_is_corrected_after_feedback_with_the_counterexample(
    bt: BTDocument, tmp_path: Path
) -> None:
    with ScriptedServer([{"content": WRONG}, {"content": GOOD}]) as server:
        outcome = convert_with_llm(bt, client_for(server, tmp_path))
    assert outcome.equivalent
    assert len(server.requests) == 2
    second = server.requests[1]["body"]["messages"]
    assert second[-2] == {"role": "assistant", "content": WRONG}  # its own answer is sent back
    feedback = second[-1]["content"]
    assert "completeness fails" in feedback
    assert "Counterexample:" in feedback
    assert "leaf outcome failure: source ran [FAILURE]" in feedback
    assert "yours ran [SUCCESS]" in feedback
    record = outcome.record
    assert not record.first_pass_success and record.regenerations == 1
    assert [r.stage for r in record.rounds] == ["verify", "ok"]


def test_structural_problems_are_fed_back_before_verification(
    bt: BTDocument, tmp_path: Path
) -> None:
    missing_leaf = fsm_answer(
        states=STATES.replace(
            '{"name": "Work", "action": "Work"}', '{"name": "Work", "action": "Wrok"}'
        )
    )
    with ScriptedServer([{"content": missing_leaf}, {"content": GOOD}]) as server:
        outcome = convert_with_llm(bt, client_for(server, tmp_path))
    assert outcome.equivalent
    feedback = server.requests[1]["body"]["messages"][-1]["content"]
    assert "leaf Work occurs 1 time(s) in the tree but has 0 state(s)" in feedback
    assert "'Wrok', which is not a leaf" in feedback
    assert outcome.record.rounds[0].stage == "structure"


def test_garbage_is_retried_then_fails_clearly(bt: BTDocument, tmp_path: Path) -> None:
    with ScriptedServer(
        [
            {"content": "I am sorry, I cannot do that."},
            {"content": "{not json at all"},
            {"content": ""},
        ]
    ) as server:
        client = client_for(server, tmp_path)
        outcome = convert_with_llm(bt, client)
        assert outcome.result is None and not outcome.equivalent
        assert outcome.record.verdict == "invalid_answer"
        assert len(server.requests) == 3  # 1 + max_regenerations
        assert "holds no JSON object" in server.requests[1]["body"]["messages"][-1]["content"]
        with pytest.raises(LLMConversionError, match=r"unreadable answer after 3 round\(s\)"):
            _run("llm", bt, True, {"client": client})


def test_not_equivalent_after_all_rounds_is_an_error_not_a_result(
    bt: BTDocument, tmp_path: Path
) -> None:
    with ScriptedServer([{"content": WRONG}]) as server:
        client = client_for(server, tmp_path, max_regenerations=1)
        with pytest.raises(LLMConversionError, match="not equivalent after 2 round"):
            _run("llm", bt, True, {"client": client})
    records = read_records(tmp_path / "llm.jsonl")
    assert records[-1]["verdict"] == "not_equivalent"


def test_nllm_sends_the_same_request_without_the_scp(bt: BTDocument, tmp_path: Path) -> None:
    with ScriptedServer([{"content": GOOD}]) as server:
        convert_with_llm(bt, client_for(server, tmp_path), scp=False)
        convert_with_llm(bt, client_for(server, tmp_path))
    nllm, llm = server.user_texts(0), server.user_texts(1)
    assert "Stepwise Conversion Procedure" not in nllm and "Stepwise Conversion Procedure" in llm
    assert set(nllm.splitlines()) <= set(llm.splitlines())  # nothing else differs
    records = read_records(tmp_path / "llm.jsonl")
    assert [r["engine"] for r in records] == ["nllm", "llm"]


def test_timeout_is_logged_and_raised(bt: BTDocument, tmp_path: Path) -> None:
    with ScriptedServer([{"delay": 60.0, "content": GOOD}]) as server:  # never in time
        with pytest.raises(LLMUnavailableError):
            convert_with_llm(bt, client_for(server, tmp_path, timeout_s=0.4))
    (record,) = read_records(tmp_path / "llm.jsonl")
    assert record["verdict"] == "endpoint_unavailable" and "error" in record["extra"]


def test_server_errors_inside_the_pipeline_are_retried(bt: BTDocument, tmp_path: Path) -> None:
    with ScriptedServer([{"status": 429}, {"status": 500}, {"content": GOOD}]) as server:
        outcome = convert_with_llm(bt, client_for(server, tmp_path))
    assert outcome.equivalent and outcome.record.rounds[0].attempts == 3
    assert outcome.record.regenerations == 0
