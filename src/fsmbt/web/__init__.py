"""The web page: convert, see both models side by side, step through a counterexample.

``create_app(settings)`` (``fsmbt.web.app``) is the FastAPI application ``fsmbt serve`` runs;
``fsmbt.web.service`` holds what each API call computes (library calls only) and
``fsmbt.web.workers`` runs it in worker processes with a time limit. docs/web.md describes the
page, the API and the limits.
"""

from fsmbt.web.app import create_app
from fsmbt.web.settings import WebSettings

__all__ = ["WebSettings", "create_app"]
