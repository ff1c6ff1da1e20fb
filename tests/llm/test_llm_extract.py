"""Inputs a person has: parsed files skip the LLM; prose, tables, unseen notations and images
are extracted by it and then read like any JSON file (plumbing only, scripted answers)."""

from __future__ import annotations

import base64
import json
from pathlib import Path

import pytest

from fsmbt.llm.client import LLMClient
from fsmbt.llm.config import LLMSettings
from fsmbt.llm.extract import LLMExtractionError, needs_llm, read_input
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from support.scripted_server import ScriptedServer

TURNSTILE = {
    "kind": "fsm",
    "name": "turnstile",
    "initial": "Locked",
    "states": [{"name": "Locked", "action": "lock"}, {"name": "Unlocked", "action": "unlock"}],
    "transitions": [
        {"source": "Locked", "event": "coin", "target": "Unlocked"},
        {"source": "Unlocked", "event": "push", "target": "Locked"},
    ],
}
PROSE = "The turnstile starts Locked (it locks). A coin unlocks it; pushing it locks it again.\n"
# the smallest valid PNG header bytes are enough: the model never sees them here
PNG = b"\x89PNG\r\n\x1a\n" + b"\x00\x00\x00\rIHDR" + bytes(range(40))


def client_for(server: ScriptedServer, tmp_path: Path) -> LLMClient:
    return LLMClient(
        LLMSettings(
            base_url=server.base_url,
            model="vision",
            api_key="k",
            backoff_s=0.01,
            timeout_s=5.0,
            max_regenerations=1,
            log_path=tmp_path / "log.jsonl",
        )
    )


def test_a_file_a_parser_reads_never_reaches_the_llm(tmp_path: Path) -> None:
    path = tmp_path / "t.json"
    path.write_text(json.dumps(TURNSTILE), encoding="utf-8")
    assert not needs_llm(path)
    outcome = read_input(path, client=None)
    assert isinstance(outcome.model, FSM) and not outcome.extracted


def test_prose_without_an_llm_is_a_clear_input_error(tmp_path: Path) -> None:
    path = tmp_path / "turnstile.notes"
    path.write_text(PROSE, encoding="utf-8")
    assert needs_llm(path)
    with pytest.raises(InputError, match="no reader knows this input"):
        read_input(path, client=None)
    # a reader guessed from the extension alone reports its error and points at the LLM path
    named = tmp_path / "turnstile.txt"
    named.write_text(PROSE, encoding="utf-8")
    assert needs_llm(named)
    with pytest.raises(InputError, match="an LLM can extract the model"):
        read_input(named, client=None)


def test_a_reader_chosen_by_content_has_the_last_word(tmp_path: Path) -> None:
    path = tmp_path / "broken.json"
    path.write_text('{"kind": "fsm", "states": [{"action": "x"}]}', encoding="utf-8")
    assert not needs_llm(path)
    with ScriptedServer([{"content": json.dumps(TURNSTILE)}]) as server:
        with pytest.raises(InputError, match="a state needs a string 'name'"):
            read_input(path, client=client_for(server, tmp_path))
    assert server.requests == []


def test_prose_is_extracted_and_read_as_json(tmp_path: Path) -> None:
    path = tmp_path / "turnstile.txt"
    path.write_text(PROSE, encoding="utf-8")
    answer = "The model:\n```json\n" + json.dumps(TURNSTILE) + "\n```"
    with ScriptedServer([{"content": answer}]) as server:
        outcome = read_input(path, client=client_for(server, tmp_path), kind="fsm")
    assert outcome.extracted and isinstance(outcome.model, FSM)
    assert set(outcome.model.states) == {"Locked", "Unlocked"}
    assert PROSE.strip() in server.user_texts(0)
    assert "It is a state machine." in server.user_texts(0)
    assert outcome.record is not None and outcome.record.verdict == "extracted"


def test_an_invalid_extraction_is_sent_back_with_the_readers_message(tmp_path: Path) -> None:
    path = tmp_path / "unseen.fsmx"
    path.write_text("Locked -coin-> Unlocked ; Unlocked -push-> Locked\n", encoding="utf-8")
    bad = json.dumps({"kind": "fsm", "states": [{"action": "no name"}]})
    with ScriptedServer([{"content": bad}, {"content": json.dumps(TURNSTILE)}]) as server:
        outcome = read_input(path, client=client_for(server, tmp_path))
    assert isinstance(outcome.model, FSM)
    feedback = server.requests[1]["body"]["messages"][-1]["content"]
    assert "a state needs a string 'name'" in feedback


def test_extraction_gives_up_with_a_clear_error(tmp_path: Path) -> None:
    path = tmp_path / "unseen.txt"
    path.write_text("@@@ ??? @@@\n", encoding="utf-8")
    with ScriptedServer([{"content": "I see no model."}]) as server:
        with pytest.raises(LLMExtractionError, match=r"no valid model after 2 round\(s\)"):
            read_input(path, client=client_for(server, tmp_path))
        assert len(server.requests) == 2


def test_an_image_is_sent_as_a_base64_data_url_part(tmp_path: Path) -> None:
    path = tmp_path / "diagram.png"
    path.write_bytes(PNG)
    assert needs_llm(path)
    with ScriptedServer([{"content": json.dumps(TURNSTILE)}]) as server:
        outcome = read_input(path, client=client_for(server, tmp_path))
    assert isinstance(outcome.model, FSM) and outcome.extracted
    user = server.requests[0]["body"]["messages"][1]
    assert user["role"] == "user" and isinstance(user["content"], list)
    text_part, image_part = user["content"]
    assert text_part["type"] == "text" and "diagram in the image" in text_part["text"]
    assert image_part["type"] == "image_url"
    url = image_part["image_url"]["url"]
    prefix = "data:image/png;base64,"
    assert url.startswith(prefix) and base64.b64decode(url[len(prefix) :]) == PNG
    assert server.requests[0]["body"]["model"] == "vision"


def test_jpeg_is_recognised_by_its_bytes_not_its_name(tmp_path: Path) -> None:
    path = tmp_path / "photo.bin"
    path.write_bytes(b"\xff\xd8\xff\xe0" + bytes(64))
    with ScriptedServer([{"content": json.dumps(TURNSTILE)}]) as server:
        read_input(path, client=client_for(server, tmp_path))
    url = server.requests[0]["body"]["messages"][1]["content"][1]["image_url"]["url"]
    assert url.startswith("data:image/jpeg;base64,")


def test_hybrid_lets_the_llm_extract_and_the_rules_convert(tmp_path: Path) -> None:
    from fsmbt.convert.engines import converter_for
    from fsmbt.model.bt import BTDocument

    path = tmp_path / "turnstile.txt"
    path.write_text(PROSE, encoding="utf-8")
    with ScriptedServer([{"content": json.dumps(TURNSTILE)}]) as server:
        loaded = read_input(path, client=client_for(server, tmp_path))
    result = converter_for("hybrid", loaded.model)(loaded.model, extracted_by_llm=loaded.extracted)
    assert isinstance(result.model, BTDocument)
    assert (
        result.engine == "hybrid" and result.stats["verified"] and result.stats["extracted_by_llm"]
    )
    assert len(server.requests) == 1  # the conversion itself asked the LLM nothing
