"""``fsmbt convert`` with the LLM engines: --llm-base-url / --llm-model reach the endpoint, and
prose goes through the LLM's extraction step (scripted local server: plumbing only)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsmbt.cli import main
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
def clean_env(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    for name in (
        "FSMBT_LLM_BASE_URL",
        "FSMBT_LLM_MODEL",
        "FSMBT_LLM_API_KEY",
        "OPENAI_API_KEY",
        "FSMBT_LLM_CONFIG",
        "FSMBT_LLM_TIMEOUT",
    ):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("FSMBT_LLM_LOG", str(tmp_path / "llm.jsonl"))
    monkeypatch.setenv("FSMBT_LLM_API_KEY", "k")


def test_hybrid_reads_prose_through_the_llm_and_passes_url_and_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    notes = tmp_path / "notes.txt"
    notes.write_text(
        "A door is Closed until pushed open; pulling closes it again.\n", encoding="utf-8"
    )
    out = tmp_path / "door.xml"
    with ScriptedServer([{"content": json.dumps(FSM_JSON)}]) as server:
        code = main(
            [
                "convert",
                "--engine",
                "hybrid",
                str(notes),
                "-o",
                str(out),
                "--llm-base-url",
                server.base_url,
                "--llm-model",
                "my-model",
            ]
        )
    assert code == 0
    assert len(server.requests) == 1
    assert server.requests[0]["body"]["model"] == "my-model"
    assert "Extract the behavior model" in server.user_texts(0)
    text = capsys.readouterr().out
    assert "verdict: EQUIVALENT" in text and "extracted_by_llm=True" in text
    assert "<DispatchEntry" in out.read_text(encoding="utf-8")  # the rules default: dispatch


def test_hybrid_on_a_parsed_file_asks_no_llm(tmp_path: Path) -> None:
    source = tmp_path / "door.json"
    source.write_text(json.dumps(FSM_JSON), encoding="utf-8")
    assert (
        main(["convert", "--engine", "hybrid", str(source), "-o", str(tmp_path / "door.xml")]) == 0
    )  # no endpoint configured: none was needed


def test_llm_engine_gets_base_url_and_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from fsmbt import api
    from fsmbt.convert import convert
    from fsmbt.formats import dumps

    source = tmp_path / "door.json"
    source.write_text(json.dumps(FSM_JSON), encoding="utf-8")
    answer = dumps(convert(api.load(source).model, style="lebt").model, "btcpp")  # LLMs write LEBTs
    with ScriptedServer([{"content": answer}]) as server:
        code = main(
            [
                "convert",
                "--engine",
                "llm",
                str(source),
                "-o",
                str(tmp_path / "o.xml"),
                "--llm-base-url",
                server.base_url,
                "--llm-model",
                "other-model",
            ]
        )
    assert code == 0
    assert [r["body"]["model"] for r in server.requests] == ["other-model"]
    assert "verdict: EQUIVALENT" in capsys.readouterr().out


def test_hierarchy_option_of_the_cli(tmp_path: Path) -> None:
    door = Path(__file__).resolve().parents[2] / "examples" / "door_hfsm.scxml"
    for mode, trees in (("subtrees", 2), ("flatten", 1)):
        out = tmp_path / f"door_{mode}.xml"
        command = ["convert", str(door), "-o", str(out), "--style", "lebt", "--hierarchy", mode]
        assert main(command) == 0  # --hierarchy shapes the LEBT
        assert out.read_text(encoding="utf-8").count("<BehaviorTree ") == trees
    assert main(["convert", str(door), "--hierarchy", "bogus"]) == 2
