"""The web page: convert, see both models side by side, step through a counterexample.

``create_app(settings)`` (``fsmbt.web.app``) is the FastAPI application ``fsmbt serve`` runs;
``fsmbt.web.service`` holds what each API call computes (library calls only) and
``fsmbt.web.workers`` runs it in worker processes with a time limit. docs/web.md describes the
page, the API and the limits.

``create_app`` and ``WebSettings`` are imported on first use (module ``__getattr__``): the
command line imports ``fsmbt.web.answers`` for a default, and importing FastAPI with it would
add about 0.3 s to every ``fsmbt`` command.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fsmbt.web.app import create_app
    from fsmbt.web.settings import WebSettings

__all__ = ["WebSettings", "create_app"]


def __getattr__(name: str) -> Any:
    if name == "create_app":
        from fsmbt.web.app import create_app

        return create_app
    if name == "WebSettings":
        from fsmbt.web.settings import WebSettings

        return WebSettings
    raise AttributeError(f"module 'fsmbt.web' has no attribute {name!r}")
