"""User-facing errors: every problem with an input names the place and the cause.

The CLI turns any ``FsmbtError`` into one line on stderr and exit code 2 (bad input); nothing
else in the library should let a raw exception reach the user.

An error may carry ``hints``: ways past it, named in the library's terms (``Hint``), never as a
command-line flag. ``str(error)`` words them with ``HINT_TEXT``; a front end words them its own
way through ``FsmbtError.text(wording)`` (the CLI's wording, with its flags, is
``fsmbt.cli.hints``).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum


class Hint(str, Enum):
    """A way past an error: the choice a caller of the library can change."""

    INPUT_FORMAT = "input_format"  # name the input's format instead of detecting it
    OUTPUT_FORMAT = "output_format"  # name the output's format
    OVERWRITE = "overwrite"  # allow replacing an existing file
    NATIVE_VERIFIER = "native_verifier"  # verify with the native checker
    RULES_ENGINE = "rules_engine"  # convert with the rules engine
    LLM_ENGINE = "llm_engine"  # let an LLM engine extract the model from the input
    MAX_NODES = "max_nodes"  # raise a picture's node limit
    MAX_STATES = "max_states"  # raise the explored / checked state limit
    STATISTICS = "statistics"  # read a model's structure from its statistics instead
    NO_EXPANSION = "no_expansion"  # draw without expanding SubTree references
    LLM_BASE_URL = "llm_base_url"  # give the LLM endpoint
    LLM_MODEL = "llm_model"  # give the LLM model name
    NUSMV_LIMITS = "nusmv_limits"  # raise NuSMV's time or memory cap
    CHECKER_TIME = "checker_time"  # raise the native checker's time limit


#: Each hint in the library's own words (``str(error)``).
HINT_TEXT: Mapping[Hint, str] = {
    Hint.INPUT_FORMAT: "name its format (fmt=...)",
    Hint.OUTPUT_FORMAT: "name the output format (fmt=...)",
    Hint.OVERWRITE: "pass overwrite=True to replace it",
    Hint.NATIVE_VERIFIER: "verify with engine='native'",
    Hint.RULES_ENGINE: "convert with engine='rules'",
    Hint.LLM_ENGINE: "convert with engine='llm', 'nllm' or 'hybrid', which extract the model",
    Hint.MAX_NODES: "raise max_nodes",
    Hint.MAX_STATES: "raise max_states",
    Hint.STATISTICS: "read its structure from fsmbt.model.stats",
    Hint.NO_EXPANSION: "draw with expand_subtrees=False",
    Hint.LLM_BASE_URL: "pass base_url=...",
    Hint.LLM_MODEL: "pass model=...",
    Hint.NUSMV_LIMITS: "raise the cap with fsmbt.limits.use(limits.current().with_changes(...))",
    Hint.CHECKER_TIME: "raise checker_max_seconds (fsmbt.limits, FSMBT_MAX_CHECKER_SECONDS)",
}

_LINE_BREAKS = re.compile(r"\s*[\r\n\v\f\x1c-\x1e\x85\u2028\u2029]+\s*")


def one_line(text: str) -> str:
    """``text`` with every line break (and the blanks around it) replaced by one space.

    Messages quote pieces of the input (a token, a parser's complaint); the CLI promises a
    one-line cause, so no quoted newline may split it.
    """
    return _LINE_BREAKS.sub(" ", text).strip()


@dataclass(frozen=True)
class SourceLocation:
    """Where something came from: file, and line/column where the format has them.

    Attributes:
        file: The file name (``None``: text with no file, shown as ``<input>``).
        line: 1-based line, when the format has lines.
        column: 1-based column, when known.
    """

    file: str | None = None
    line: int | None = None
    column: int | None = None

    def __str__(self) -> str:
        parts = [self.file or "<input>"]
        if self.line is not None:
            parts.append(str(self.line))
            if self.column is not None:
                parts.append(str(self.column))
        return ":".join(parts)


class FsmbtError(Exception):
    """Base class of every error fsmbt reports to a user.

    Shown as ``file:line:col: element: message``, each part only when known.

    Args:
        message: The cause, in words a user can act on.
        location: Where in the input.
        element: The state, node or element concerned.
    """

    def __init__(
        self,
        message: str,
        *,
        location: SourceLocation | None = None,
        element: str | None = None,
        hints: tuple[Hint, ...] = (),
    ) -> None:
        message = one_line(message)
        super().__init__(message)
        self.message = message
        self.location = location
        self.element = one_line(element) if element else element
        self.hints = hints

    def text(self, wording: Mapping[Hint, str] = HINT_TEXT) -> str:
        """The one-line report: location, element, message, then the hints in ``wording``.

        Args:
            wording: the words for each hint (a hint missing from it falls back to
                ``HINT_TEXT``).

        Returns:
            ``file:line:column: element: message; hint or hint``.
        """
        prefix = f"{self.location}: " if self.location is not None else ""
        where = f"{self.element}: " if self.element else ""
        advice = " or ".join(wording.get(h, HINT_TEXT[h]) for h in self.hints)
        return f"{prefix}{where}{self.message}" + (f"; {advice}" if advice else "")

    def __str__(self) -> str:
        return self.text()


class InputError(FsmbtError):
    """The input cannot be read or is not a valid model (CLI exit code 2)."""


class LimitError(InputError):
    """The model is too large for a bound in force (``fsmbt.limits``): reachable states,
    distinct data values, the checker's time. Not malformed input: raising the limit may let
    it through. Every explorer's ``StateLimitError`` is one, so callers (the batch runner) tell
    all of them apart with one class."""


class UnsupportedError(InputError):
    """The input is valid in its own format but uses a feature fsmbt cannot honour."""

    def __init__(self, message: str, **kwargs: object) -> None:
        if not message.startswith("unsupported"):
            message = f"unsupported: {message}"
        super().__init__(message, **kwargs)  # type: ignore[arg-type]
