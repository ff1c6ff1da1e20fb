"""The FastAPI application: the page, its JSON API, read-only report browsing (docs/web.md).

``create_app(settings)`` builds it from one ``APIRouter`` per concern: ``routes_reference``
(the page, formats, engines, examples), ``routes_pipeline`` (inspect, convert, verify, export,
runtime files), ``routes_reports`` (read-only report browsing); request bodies are parsed in
``bodies``, errors answered in ``errors``. The page (``templates/index.html`` + ``static/app.js``) only
calls the API below, so everything it shows is available to any client:

- ``GET /api/formats``, ``GET /api/engines``, ``GET /api/examples``, ``GET /api/examples/{name}``
- ``POST /api/inspect`` (read + validate), ``/api/convert``, ``/api/verify``, ``/api/export``,
  ``GET /api/runtime/{cpp|python}``
- with ``reports_dir``: ``GET /api/reports``, ``GET /reports/{path}``, ``GET /api/batch/{path}``

Rules: bodies over ``max_body_bytes`` are refused (413) before they are read whole; JSON or
multipart only (415 otherwise); no request names a server path (uploads are texts, examples are
picked by name from a listing, report files are resolved inside ``reports_dir`` and refused
outside it); a client over its rate gets 429 with ``Retry-After`` (``admission``); every error
is ``{"error": "<one line>", "where": ...}`` with a 4xx (bad input; 408/422 past the
wall/CPU-time limit; 429 over the client's rate), 503 with ``Retry-After`` (busy) or 500 (a bug,
logged) - never a traceback.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from pathlib import Path

from fastapi import FastAPI
from fastapi.staticfiles import StaticFiles

from fsmbt.web import routes_pipeline, routes_reference, routes_reports
from fsmbt.web.admission import ClientRateLimit
from fsmbt.web.answers import AnswerCache
from fsmbt.web.errors import BodyLimit, install_handlers
from fsmbt.web.headers import SecurityHeaders
from fsmbt.web.settings import WebSettings
from fsmbt.web.workers import Workers

HERE = Path(__file__).parent


def create_app(settings: WebSettings | None = None) -> FastAPI:
    """The web application.

    Args:
        settings: limits and folders (``WebSettings.default()`` when ``None``).

    Returns:
        The FastAPI app (its OpenAPI page is ``/docs``); ``app.state.settings`` holds the
        settings and, while it runs, ``app.state.workers`` the worker processes.
    """
    settings = settings or WebSettings.default()

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        app.state.workers = Workers(
            settings.workers,
            settings.timeout_s,
            max_waiting=settings.max_waiting,
            cpu_seconds=settings.cpu_limit_s,
        )
        yield
        app.state.workers.close()

    app = FastAPI(
        title="fsmbt",
        version="0.1.0",
        lifespan=lifespan,
        description="Convert behavior models between FSMs and behavior trees and "
        "prove the result equivalent (docs/web.md).",
    )
    app.state.settings = settings
    app.state.cache = (
        AnswerCache(settings.cache_bytes, settings.cache_dir) if settings.cache_bytes > 0 else None
    )
    app.add_middleware(  # inside BodyLimit: a refused client's body is bounded when drained
        ClientRateLimit,
        rate=settings.rate_limit,
        burst=settings.rate_burst,
        trusted=settings.trusted_proxies,
        limit_loopback=settings.rate_limit_loopback,
    )
    app.add_middleware(BodyLimit, limit=settings.max_body_bytes, drain_cap=settings.drain_cap_bytes)
    app.add_middleware(SecurityHeaders)  # outermost: the 413s carry them too
    app.mount("/static", StaticFiles(directory=HERE / "static"), name="static")
    install_handlers(app)
    app.include_router(routes_reference.router)
    app.include_router(routes_pipeline.router)
    app.include_router(routes_reports.router)
    return app
