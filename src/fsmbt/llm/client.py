"""One chat request to an OpenAI-compatible endpoint, with the paper's settings and bounded retries.

We use the official ``openai`` package with its own retries switched off and retry here, because
the pipeline must know how many attempts a request took and must stop at one deadline: the whole
request, retries and back-off included, never takes longer than ``settings.timeout_s``. Retried:
connection errors, timeouts, HTTP 429 and 5xx (``Retry-After`` honoured when it fits the
deadline). Anything else (401, 404, 400...) fails at once with the endpoint's own message.

Two guards sit in the HTTP transport (``_GuardedTransport``), because the ``openai`` package's
own timeout is per read, not per request, and it reads a body of any size:

- the body is counted as it arrives and the download stops past
  ``fsmbt.limits.current().llm_max_response_bytes`` (``FSMBT_MAX_LLM_RESPONSE_BYTES``);
- the request's deadline is checked at every chunk, so an endpoint that trickles a byte at a
  time cannot hold a request past ``settings.timeout_s``.

Either ends the attempt like a dropped connection (retried, within the deadline). Every failed
attempt's cause is kept (``Completion.failures``, ``LLMUnavailableError.failures``) so the
pipeline's log records why each attempt failed, not only how many there were.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import httpx2
import openai

from fsmbt import limits
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
    failures: list[str] = field(default_factory=list)  # the cause of each failed attempt


class ResponseGuardError(httpx2.ReadError):
    """The response broke a guard (too large, or trickling past the deadline); a read error for
    ``openai``, so it becomes a failed, retryable attempt with this message as its cause."""


class _GuardedStream(httpx2.SyncByteStream):
    """A response body that stops past ``limit`` bytes or past the guard's deadline."""

    def __init__(self, inner: httpx2.SyncByteStream, guard: _Guard) -> None:
        self._inner = inner
        self._guard = guard

    def __iter__(self) -> Iterator[bytes]:
        received = 0
        limit = self._guard.max_bytes
        for chunk in self._inner:
            received += len(chunk)
            if received > limit:
                raise ResponseGuardError(
                    f"the response exceeded {limit} bytes and was cut off (raise the limit with "
                    f"{limits.env_name('llm_max_response_bytes')})"
                )
            if self._guard.clock() > self._guard.deadline:
                raise ResponseGuardError(
                    f"the response was still arriving after {self._guard.timeout_s:g} s "
                    f"({received} bytes so far)"
                )
            yield chunk

    def close(self) -> None:
        self._inner.close()


@dataclass
class _Guard:
    """What the transport enforces on the current request (set before each attempt)."""

    clock: Callable[[], float]
    timeout_s: float
    deadline: float = float("inf")
    max_bytes: int = 0


class _GuardedTransport(httpx2.HTTPTransport):
    def __init__(self, guard: _Guard) -> None:
        super().__init__()
        self.guard = guard

    def handle_request(self, request: httpx2.Request) -> httpx2.Response:
        response = super().handle_request(request)
        assert isinstance(response.stream, httpx2.SyncByteStream)
        return httpx2.Response(
            status_code=response.status_code,
            headers=response.headers,
            stream=_GuardedStream(response.stream, self.guard),
            extensions=response.extensions,
        )


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
        self._guard = _Guard(clock, settings.timeout_s)
        http_client = openai.DefaultHttpxClient(transport=_GuardedTransport(self._guard))
        self._client = openai.OpenAI(
            base_url=settings.base_url,
            api_key=settings.api_key,
            timeout=settings.timeout_s,
            max_retries=0,
            http_client=http_client,
        )

    def complete(self, messages: list[Message]) -> Completion:
        """Send ``messages``; return the first choice's text. Raises ``LLMUnavailableError``."""
        s = self.settings
        start = self._clock()
        deadline = start + s.timeout_s
        attempts = 0
        last_problem = ""
        failures: list[str] = []
        self._guard.deadline = deadline
        self._guard.max_bytes = limits.current().llm_max_response_bytes
        while True:
            attempts += 1
            remaining = deadline - self._clock()
            if remaining <= 0:
                raise self._give_up(
                    f"no answer within {s.timeout_s:g} s ({last_problem})", attempts - 1, failures
                )
            try:
                response = self._client.chat.completions.create(
                    model=s.model,
                    messages=cast("list[ChatCompletionMessageParam]", messages),
                    temperature=s.temperature,
                    top_p=s.top_p,
                    seed=s.seed,
                    timeout=remaining,
                    max_tokens=s.max_output_tokens if s.max_output_tokens else openai.omit,
                )
            except openai.APITimeoutError:
                last_problem = "request timed out"
                delay = None
            except openai.APIConnectionError as exc:
                guard = _guard_error(exc)
                if guard is not None:
                    last_problem = str(guard)
                elif _answered(exc):
                    last_problem = f"the connection broke during the answer: {_root_cause(exc)}"
                else:
                    last_problem = f"cannot connect: {_root_cause(exc)}"
                delay = None
            except openai.APIStatusError as exc:
                status = exc.status_code
                if status != 429 and status < 500:
                    error = LLMUnavailableError(
                        f"the LLM endpoint {s.base_url} refused the request: HTTP {status} "
                        f"{_short(_strip_code(exc.message))}"
                    )
                    error.failures = [*failures, f"HTTP {status}"]
                    raise error from None
                last_problem = f"HTTP {status}"
                delay = _retry_after(exc)
            except openai.OpenAIError as exc:  # malformed responses and the like
                last_problem = f"an unusable response: {_short(str(exc))}"
                delay = None
            except ValueError as exc:  # a body that is not JSON (truncated, another format)
                last_problem = f"an unusable response (not JSON: {_short(str(exc))})"
                delay = None
            else:
                try:
                    completion = self._completion(
                        response, messages, self._clock() - start, attempts
                    )
                except (AttributeError, TypeError, ValueError) as exc:  # not the chat shape
                    last_problem = f"a response that is not a chat completion: {_short(str(exc))}"
                    delay = None
                else:
                    completion.failures = failures
                    return completion
            failures.append(f"attempt {attempts}: {last_problem}")
            if attempts > s.max_retries:
                raise self._give_up(last_problem, attempts, failures)
            wait = delay if delay is not None else s.backoff_s * (2 ** (attempts - 1))
            if self._clock() + wait >= deadline:
                raise self._give_up(
                    f"{last_problem}; the next retry would pass the {s.timeout_s:g} s timeout",
                    attempts,
                    failures,
                )
            self._sleep(wait)

    def _give_up(self, problem: str, attempts: int, failures: list[str]) -> LLMUnavailableError:
        error = LLMUnavailableError(
            f"the LLM endpoint {self.settings.base_url} failed after {attempts} attempt(s): {problem}"
        )
        error.failures = list(failures)
        return error

    def _completion(
        self, response: Any, messages: list[Message], latency: float, attempts: int
    ) -> Completion:
        if not hasattr(response, "choices"):  # e.g. an HTML error page the SDK passed on as text
            raise TypeError(f"got {_short(repr(response), 80)}")
        choices = getattr(response, "choices", None) or []
        text = ""
        if choices and getattr(choices[0], "message", None) is not None:
            text = choices[0].message.content or ""
        if not isinstance(text, str):
            raise TypeError(f"the message content is a {type(text).__name__}, not text")
        usage = getattr(response, "usage", None)
        if usage is not None and usage.prompt_tokens is not None:
            return Completion(
                text,
                int(usage.prompt_tokens),
                int(usage.completion_tokens or 0),
                latency,
                attempts,
                True,
            )
        from fsmbt.llm.tokens import count_messages, count_text

        return Completion(
            text, count_messages(messages), count_text(text), latency, attempts, False
        )


def _guard_error(exc: BaseException) -> ResponseGuardError | None:
    cause: BaseException | None = exc
    while cause is not None:
        if isinstance(cause, ResponseGuardError):
            return cause
        cause = cause.__cause__ or cause.__context__
    return None


def _answered(exc: BaseException) -> bool:
    """Whether the failure came while reading a response (not while connecting)."""
    cause: BaseException | None = exc
    while cause is not None:
        if isinstance(cause, (httpx2.ReadError, httpx2.RemoteProtocolError)):
            return True
        cause = cause.__cause__ or cause.__context__
    return False


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
