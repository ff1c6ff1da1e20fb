"""User-facing errors: every problem with an input names the place and the cause.

The CLI turns any ``FsmbtError`` into one line on stderr and exit code 2 (bad input); nothing
else in the library should let a raw exception reach the user.
"""

from __future__ import annotations

from dataclasses import dataclass


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
    ) -> None:
        super().__init__(message)
        self.message = message
        self.location = location
        self.element = element

    def __str__(self) -> str:
        prefix = f"{self.location}: " if self.location is not None else ""
        where = f"{self.element}: " if self.element else ""
        return f"{prefix}{where}{self.message}"


class InputError(FsmbtError):
    """The input cannot be read or is not a valid model (CLI exit code 2)."""


class UnsupportedError(InputError):
    """The input is valid in its own format but uses a feature fsmbt cannot honour."""

    def __init__(self, message: str, **kwargs: object) -> None:
        if not message.startswith("unsupported"):
            message = f"unsupported: {message}"
        super().__init__(message, **kwargs)  # type: ignore[arg-type]
