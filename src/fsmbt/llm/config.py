"""Where the LLM endpoint, model and key come from, and the paper's sampling settings.

Precedence, highest first: explicit arguments (the CLI's ``--llm-*`` flags), the environment
(``FSMBT_LLM_BASE_URL``, ``FSMBT_LLM_MODEL``, ``FSMBT_LLM_API_KEY`` falling back to
``OPENAI_API_KEY``, ``FSMBT_LLM_TIMEOUT``, ``FSMBT_LLM_LOG`` (``off`` disables the log)), then a TOML file: ``$FSMBT_LLM_CONFIG``,
else ``./fsmbt.toml`` (its ``[llm]`` table), else ``~/.config/fsmbt/llm.toml`` (top level or ``[llm]``).
The base URL may be a provider name (``openai``, ``deepseek``, ``qwen``/``dashscope``,
``ollama``, ``vllm``) or a URL. Nothing here opens a connection: ``resolve_settings`` only
decides, and raises ``LLMConfigError`` (exit 2) when the endpoint, model or key is missing, so
the rules engine is never affected by an absent LLM.
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from fsmbt.model.errors import Hint, InputError


class LLMConfigError(InputError):
    """The LLM path cannot run: no endpoint, model or key (CLI exit 2; rules still work)."""


class LLMUnavailableError(InputError):
    """The endpoint could not be reached or kept failing (CLI exit 2, one line).

    ``failures`` holds the cause of each failed attempt (for the log); ``outcome`` is set by the
    pipeline to what the conversion had produced before the endpoint failed (nothing is lost).
    """

    failures: list[str]
    outcome: object | None

    def __init__(self, message: str, **kwargs: object) -> None:
        super().__init__(message, **kwargs)  # type: ignore[arg-type]
        self.failures = []
        self.outcome = None


@dataclass(frozen=True)
class Provider:
    name: str
    base_url: str
    default_model: str | None
    needs_key: bool = True


#: Known OpenAI-compatible providers. Local servers (Ollama, vLLM) take any key.
PROVIDERS: dict[str, Provider] = {
    "openai": Provider("openai", "https://api.openai.com/v1", "gpt-4o"),
    "deepseek": Provider("deepseek", "https://api.deepseek.com/v1", "deepseek-chat"),
    "qwen": Provider("qwen", "https://dashscope.aliyuncs.com/compatible-mode/v1", "qwen-plus"),
    "ollama": Provider("ollama", "http://localhost:11434/v1", None, needs_key=False),
    "vllm": Provider("vllm", "http://localhost:8000/v1", None, needs_key=False),
}
PROVIDERS["dashscope"] = PROVIDERS["qwen"]

#: The key sent to local servers that ignore it (the client library insists on one).
PLACEHOLDER_KEY = "not-needed"


@dataclass(frozen=True)
class LLMSettings:
    """Everything one conversion needs to talk to a model. Defaults are the paper's settings."""

    base_url: str
    model: str
    api_key: str = field(repr=False)
    provider: str | None = None
    temperature: float = 0.1
    top_p: float = 0.9
    seed: int = 42
    timeout_s: float = 180.0
    max_retries: int = 3  # transport retries per request (429, 5xx, connection, timeout)
    backoff_s: float = 1.0  # first retry delay; doubles each time
    max_regenerations: int = 3  # feedback rounds after the first answer
    max_output_tokens: int | None = None
    log_path: Path | None = None

    def with_overrides(self, **changes: Any) -> LLMSettings:
        return replace(self, **{k: v for k, v in changes.items() if v is not None})

    def describe(self) -> str:
        """For logs and messages: never includes the key."""
        return f"{self.model} at {self.base_url}"


def default_log_path(env: Mapping[str, str]) -> Path:
    state = env.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(state) / "fsmbt" / "llm.jsonl"


def load_config_file(
    env: Mapping[str, str], cwd: Path | None = None
) -> tuple[dict[str, Any], Path | None]:
    """The ``[llm]`` settings of the first config file found, and its path."""
    candidates: list[tuple[Path, bool]] = []  # (path, must_exist)
    if env.get("FSMBT_LLM_CONFIG"):
        candidates.append((Path(env["FSMBT_LLM_CONFIG"]), True))
    candidates.append(((cwd or Path.cwd()) / "fsmbt.toml", False))
    config_home = env.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    candidates.append((Path(config_home) / "fsmbt" / "llm.toml", False))
    for path, must_exist in candidates:
        if not path.is_file():
            if must_exist:
                raise LLMConfigError(f"FSMBT_LLM_CONFIG names {path}, which is not a file")
            continue
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise LLMConfigError(f"cannot read LLM config {path}: {exc}") from None
        table = data.get("llm", data if path.name == "llm.toml" else {})
        if not isinstance(table, dict):
            raise LLMConfigError(f"{path}: [llm] must be a table")
        if table:
            return table, path
    return {}, None


def resolve_base_url(value: str) -> tuple[str, Provider | None]:
    """A provider name or a URL to ``(base URL, provider or None)``."""
    provider = PROVIDERS.get(value.strip().lower())
    if provider is not None:
        return provider.base_url, provider
    if not value.startswith(("http://", "https://")):
        known = ", ".join(sorted(PROVIDERS))
        raise LLMConfigError(f"LLM base URL {value!r} is neither a URL nor a provider ({known})")
    return value.rstrip("/"), None


def resolve_settings(
    *,
    base_url: str | None = None,
    model: str | None = None,
    api_key: str | None = None,
    timeout_s: float | None = None,
    max_regenerations: int | None = None,
    log_path: str | Path | None = None,
    env: Mapping[str, str] | None = None,
    cwd: Path | None = None,
) -> LLMSettings:
    """Settings from arguments, environment and config file (in that order of precedence)."""
    env = os.environ if env is None else env
    file_cfg, file_path = load_config_file(env, cwd)

    def pick(arg: Any, env_name: str | None, key: str) -> Any:
        if arg is not None and arg != "":
            return arg
        if env_name and env.get(env_name):
            return env[env_name]
        return file_cfg.get(key)

    raw_url = pick(base_url, "FSMBT_LLM_BASE_URL", "base_url") or pick(None, None, "provider")
    if not raw_url:
        raise LLMConfigError(
            "no LLM endpoint configured (the rules engine needs none): set FSMBT_LLM_BASE_URL "
            f"(a URL or one of {', '.join(sorted(PROVIDERS))}) or base_url in fsmbt.toml [llm]",
            hints=(Hint.LLM_BASE_URL, Hint.RULES_ENGINE),
        )
    url, provider = resolve_base_url(str(raw_url))
    chosen_model = pick(model, "FSMBT_LLM_MODEL", "model") or (
        provider.default_model if provider else None
    )
    if not chosen_model:
        raise LLMConfigError(
            f"no LLM model configured for {url}: set FSMBT_LLM_MODEL", hints=(Hint.LLM_MODEL,)
        )
    key = pick(api_key, "FSMBT_LLM_API_KEY", "api_key") or env.get("OPENAI_API_KEY")
    if not key:
        if provider is not None and not provider.needs_key:
            key = PLACEHOLDER_KEY
        else:
            raise LLMConfigError(
                f"no API key for {url}: set FSMBT_LLM_API_KEY (or OPENAI_API_KEY); "
                "for a keyless local server use any value, e.g. FSMBT_LLM_API_KEY=none"
            )
    settings = LLMSettings(
        base_url=url,
        model=str(chosen_model),
        api_key=str(key),
        provider=provider.name if provider else None,
    )
    numeric: dict[str, Any] = {}
    for name, conv in (
        ("temperature", float),
        ("top_p", float),
        ("seed", int),
        ("max_retries", int),
        ("backoff_s", float),
        ("max_regenerations", int),
        ("max_output_tokens", int),
        ("timeout_s", float),
    ):
        if name in file_cfg:
            numeric[name] = _convert(file_cfg[name], conv, name, file_path)
    env_timeout = env.get("FSMBT_LLM_TIMEOUT")
    if env_timeout:
        numeric["timeout_s"] = _convert(env_timeout, float, "FSMBT_LLM_TIMEOUT", None)
    if timeout_s is not None:
        numeric["timeout_s"] = float(timeout_s)
    if max_regenerations is not None:
        numeric["max_regenerations"] = int(max_regenerations)
    settings = replace(settings, **numeric)
    if settings.timeout_s <= 0:
        raise LLMConfigError(f"LLM timeout must be positive, not {settings.timeout_s}")
    if settings.max_regenerations < 0 or settings.max_retries < 0:
        raise LLMConfigError("LLM retry and regeneration counts must be >= 0")
    chosen_log = pick(log_path, "FSMBT_LLM_LOG", "log")
    if str(chosen_log or "").lower() in ("off", "none"):
        return replace(settings, log_path=None)
    settings = replace(settings, log_path=Path(chosen_log) if chosen_log else default_log_path(env))
    return settings


def _convert(value: Any, conv: type, name: str, path: Path | None) -> Any:
    try:
        return conv(value)
    except (TypeError, ValueError):
        where = f"{path}: " if path else ""
        raise LLMConfigError(f"{where}{name} must be a {conv.__name__}, not {value!r}") from None
