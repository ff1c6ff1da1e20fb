"""Client and configuration plumbing against the scripted local server (no real model)."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import pytest

from fsmbt.llm.client import LLMClient
from fsmbt.llm.config import (
    PLACEHOLDER_KEY,
    LLMConfigError,
    LLMSettings,
    LLMUnavailableError,
    resolve_settings,
)
from support.scripted_server import ScriptedServer, closed_port


def settings_for(url: str, **changes: object) -> LLMSettings:
    base = LLMSettings(
        base_url=url,
        model="scripted-model",
        api_key="test-key",
        backoff_s=0.01,
        timeout_s=5.0,
        log_path=None,
    )
    return replace(base, **changes)


def test_request_carries_the_papers_settings_and_returns_usage() -> None:
    with ScriptedServer([{"content": "hello"}]) as server:
        completion = LLMClient(settings_for(server.base_url)).complete(
            [{"role": "user", "content": "hi"}]
        )
    assert completion.text == "hello"
    assert completion.attempts == 1 and completion.usage_reported
    assert completion.tokens_in == 101
    body = server.requests[0]["body"]
    assert (body["temperature"], body["top_p"], body["seed"]) == (0.1, 0.9, 42)
    assert body["model"] == "scripted-model"
    headers = {k.lower(): v for k, v in server.requests[0]["headers"].items()}
    assert headers["authorization"] == "Bearer test-key"


def test_missing_usage_is_counted_locally_with_tiktoken() -> None:
    with ScriptedServer([{"content": "hello world", "usage": False}]) as server:
        completion = LLMClient(settings_for(server.base_url)).complete(
            [{"role": "user", "content": "hi"}]
        )
    assert not completion.usage_reported
    assert completion.tokens_out == 2  # cl100k_base: "hello", " world"


@pytest.mark.parametrize("status", [429, 500, 503])
def test_rate_limit_and_server_errors_are_retried(status: int) -> None:
    with ScriptedServer(
        [{"status": status}, {"status": status}, {"content": "third time"}]
    ) as server:
        completion = LLMClient(settings_for(server.base_url)).complete(
            [{"role": "user", "content": "hi"}]
        )
    assert completion.text == "third time"
    assert completion.attempts == 3 and len(server.requests) == 3


def test_retry_after_header_is_honoured() -> None:
    waits: list[float] = []
    with ScriptedServer(
        [{"status": 429, "headers": {"Retry-After": "0.2"}}, {"content": "ok"}]
    ) as server:
        LLMClient(settings_for(server.base_url), sleep=waits.append).complete(
            [{"role": "user", "content": "hi"}]
        )
    assert waits == [0.2]


def test_retries_are_bounded_then_a_clear_error() -> None:
    with ScriptedServer([{"status": 500}]) as server:
        with pytest.raises(LLMUnavailableError, match=r"failed after 4 attempt\(s\): HTTP 500"):
            LLMClient(settings_for(server.base_url, max_retries=3)).complete(
                [{"role": "user", "content": "hi"}]
            )
    assert len(server.requests) == 4


def test_client_errors_are_not_retried() -> None:
    with ScriptedServer([{"status": 401, "message": "bad key"}]) as server:
        with pytest.raises(LLMUnavailableError, match="HTTP 401 bad key"):
            LLMClient(settings_for(server.base_url)).complete([{"role": "user", "content": "hi"}])
    assert len(server.requests) == 1


def test_a_slow_endpoint_times_out_within_the_timeout() -> None:
    # The answer would come after 60 s (stopping the server ends the wait), so ending within
    # 10 s shows the 0.5 s timeout cut the request, with room for a loaded 2-core machine.
    with ScriptedServer([{"delay": 60.0, "content": "too late"}]) as server:
        start = time.monotonic()
        with pytest.raises(LLMUnavailableError, match="timed out|within"):
            LLMClient(settings_for(server.base_url, timeout_s=0.5)).complete(
                [{"role": "user", "content": "hi"}]
            )
        elapsed = time.monotonic() - start
    assert elapsed < 10.0


def test_unreachable_endpoint_fails_fast_with_a_clear_message() -> None:
    url = f"http://127.0.0.1:{closed_port()}/v1"
    start = time.monotonic()
    with pytest.raises(LLMUnavailableError, match="cannot connect"):
        LLMClient(settings_for(url, timeout_s=1.0)).complete([{"role": "user", "content": "hi"}])
    assert time.monotonic() - start < 2.0


# -- configuration --------------------------------------------------------------------------
def test_no_endpoint_is_a_config_error_naming_the_rules_engine(tmp_path: Path) -> None:
    with pytest.raises(LLMConfigError, match="no LLM endpoint.*rules"):
        resolve_settings(env={"HOME": str(tmp_path)}, cwd=tmp_path)


def test_missing_key_is_a_config_error(tmp_path: Path) -> None:
    env = {
        "FSMBT_LLM_BASE_URL": "http://127.0.0.1:9/v1",
        "FSMBT_LLM_MODEL": "m",
        "HOME": str(tmp_path),
    }
    with pytest.raises(LLMConfigError, match="no API key"):
        resolve_settings(env=env, cwd=tmp_path)


def test_openai_api_key_is_the_fallback_and_flags_beat_the_environment(tmp_path: Path) -> None:
    env = {"FSMBT_LLM_BASE_URL": "deepseek", "OPENAI_API_KEY": "sk-fallback", "HOME": str(tmp_path)}
    settings = resolve_settings(env=env, cwd=tmp_path)
    assert settings.base_url == "https://api.deepseek.com/v1"
    assert settings.model == "deepseek-chat" and settings.api_key == "sk-fallback"
    flagged = resolve_settings(
        base_url="http://10.0.0.5:8000/v1", model="qwen2.5", env=env, cwd=tmp_path
    )
    assert flagged.base_url == "http://10.0.0.5:8000/v1" and flagged.model == "qwen2.5"
    assert "sk-fallback" not in repr(flagged)


def test_local_providers_need_no_key(tmp_path: Path) -> None:
    settings = resolve_settings(
        base_url="ollama", model="llama3.1", env={"HOME": str(tmp_path)}, cwd=tmp_path
    )
    assert settings.base_url == "http://localhost:11434/v1" and settings.api_key == PLACEHOLDER_KEY
    with pytest.raises(LLMConfigError, match="no LLM model"):
        resolve_settings(base_url="vllm", env={"HOME": str(tmp_path)}, cwd=tmp_path)


def test_config_file_supplies_settings(tmp_path: Path) -> None:
    (tmp_path / "fsmbt.toml").write_text(
        '[llm]\nbase_url = "qwen"\napi_key = "k"\ntimeout_s = 30\nmax_regenerations = 5\n'
        "temperature = 0.0\n",
        encoding="utf-8",
    )
    settings = resolve_settings(env={"HOME": str(tmp_path)}, cwd=tmp_path)
    assert settings.base_url.startswith("https://dashscope")
    assert (settings.timeout_s, settings.max_regenerations, settings.temperature) == (30.0, 5, 0.0)
    assert settings.top_p == 0.9  # untouched defaults stay the paper's


def test_bad_config_values_are_reported(tmp_path: Path) -> None:
    (tmp_path / "fsmbt.toml").write_text(
        '[llm]\nbase_url = "openai"\napi_key="k"\ntimeout_s = "soon"\n', encoding="utf-8"
    )
    with pytest.raises(LLMConfigError, match="timeout_s must be a float"):
        resolve_settings(env={"HOME": str(tmp_path)}, cwd=tmp_path)
    with pytest.raises(LLMConfigError, match="neither a URL nor a provider"):
        resolve_settings(base_url="gemini", env={"HOME": str(tmp_path)}, cwd=tmp_path)
