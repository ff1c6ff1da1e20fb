"""One chat request to an OpenAI-compatible endpoint, with the paper's settings and bounded retries.

We use the official ``openai`` package with its own retries switched off and retry here, because
the pipeline must know how many attempts a request took and must stop at one deadline: the whole
request, retries and back-off included, never takes longer than ``settings.timeout_s``. Retried:
connection errors, timeouts, HTTP 429 and 5xx (``Retry-After`` honoured when it fits the
deadline). Anything else (401, 404, 400...) fails at once with the endpoint's own message.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import openai

from fsmbt.llm.config import LLMSettings, LLMUnavailableError

if TYPE_CHECKING:
    from openai.types.chat import ChatCompletionMessageParam

Message = dict[str, Any]
MAX_RETRY_AFTER_S = 60.0


@dataclass
class Completion:
    """The model's answer and what it cost."""

    text: str
    tokens_in: int
    tokens_out: int
    latency_s: float
    attempts: int
    usage_reported: bool  # False: the endpoint sent no usage; counts are local tiktoken counts


class LLMClient:
    """A chat-completions caller bound to one endpoint and model."""

    def __init__(
        self,
        settings: LLMSettings,
        *,
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.settings = settings
        self._sleep = sleep
        self._clock = clock
        self._client = openai.OpenAI(base_url=settings.base_url, api_key=settings.api_key,
                                     timeout=settings.timeout_s, max_retries=0)

    def complete(self, messages: list[Message]) -> Completion:
        """Send ``messages``; return the first choice's text. Raises ``LLMUnavailableError``."""
        s = self.settings
        start = self._clock()
        deadline = start + s.timeout_s
        attempts = 0
        last_problem = ""
        while True:
            attempts += 1
            remaining = deadline - self._clock()
            if remaining <= 0:
                raise self._give_up(f"no answer within {s.timeout_s:g} s ({last_problem})", attempts - 1)
            try:
                response = self._client.chat.completions.create(
                    model=s.model,
                    messages=cast("list[ChatCompletionMessageParam]", messages),
                    temperature=s.temperature, top_p=s.top_p,
                    seed=s.seed, timeout=remaining,
                    max_tokens=s.max_output_tokens if s.max_output_tokens else openai.omit,
                )
            except openai.APITimeoutError:
                last_problem = "request timed out"
                delay = None
            except openai.APIConnectionError as exc:
                last_problem = f"cannot connect: {_root_cause(exc)}"
                delay = None
            except openai.APIStatusError as exc:
                status = exc.status_code
                if status != 429 and status < 500:
                    raise LLMUnavailableError(
                        f"the LLM endpoint {s.base_url} refused the request: HTTP {status} "
                        f"{_short(_strip_code(exc.message))}") from None
                last_problem = f"HTTP {status}"
                delay = _retry_after(exc)
            except openai.OpenAIError as exc:  # malformed responses and the like
                raise LLMUnavailableError(
                    f"the LLM endpoint {s.base_url} answered something unusable: {_short(str(exc))}"
                ) from None
            else:
                return self._completion(response, messages, self._clock() - start, attempts)
            if attempts > s.max_retries:
                raise self._give_up(last_problem, attempts)
            wait = delay if delay is not None else s.backoff_s * (2 ** (attempts - 1))
            if self._clock() + wait >= deadline:
                raise self._give_up(f"{last_problem}; the next retry would pass the "
                                    f"{s.timeout_s:g} s timeout", attempts)
            self._sleep(wait)

    def _give_up(self, problem: str, attempts: int) -> LLMUnavailableError:
        return LLMUnavailableError(
            f"the LLM endpoint {self.settings.base_url} failed after {attempts} attempt(s): {problem}")

    def _completion(self, response: Any, messages: list[Message], latency: float,
                    attempts: int) -> Completion:
        choices = getattr(response, "choices", None) or []
        text = ""
        if choices and getattr(choices[0], "message", None) is not None:
            text = choices[0].message.content or ""
        usage = getattr(response, "usage", None)
        if usage is not None and usage.prompt_tokens is not None:
            return Completion(text, int(usage.prompt_tokens), int(usage.completion_tokens or 0),
                              latency, attempts, True)
        from fsmbt.llm.tokens import count_messages, count_text

        return Completion(text, count_messages(messages), count_text(text), latency, attempts, False)


def _retry_after(exc: openai.APIStatusError) -> float | None:
    try:
        value = float(exc.response.headers.get("retry-after", ""))
    except (AttributeError, ValueError):
        return None
    return min(max(value, 0.0), MAX_RETRY_AFTER_S)


def _strip_code(message: str) -> str:
    """openai prefixes "Error code: 401 - "; the status is already in our message."""
    head, sep, tail = str(message).partition(" - ")
    return tail if sep and head.startswith("Error code:") else str(message)


def _root_cause(exc: BaseException) -> str:
    cause: BaseException = exc
    while cause.__cause__ is not None:
        cause = cause.__cause__
    text = str(cause) or type(cause).__name__
    return _short(text)


def _short(text: str, limit: int = 200) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."
