"""The web API's errors: every refusal is ``{"error": "<one line>", "where": ...}`` with a 4xx
(bad input), 503 (time limit, busy) or 500 (a bug, logged) - never a traceback - and bodies over
the server's limit are refused (413) before they are read whole (docs/web.md)."""

from __future__ import annotations

import json
import logging
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

LOG = logging.getLogger("fsmbt.web")


class ApiError(Exception):
    """A refused request: status and the one-line cause."""

    def __init__(self, status: int, error: str, where: Any = None) -> None:
        super().__init__(error)
        self.status = status
        self.body = {"error": error, "where": where}


class BodyLimit:
    """ASGI middleware refusing bodies over ``limit`` bytes (declared or streamed) with 413."""

    def __init__(self, app: ASGIApp, limit: int) -> None:
        self.app = app
        self.limit = limit

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        for name, value in scope.get("headers", []):
            if name == b"content-length" and value.isdigit() and int(value) > self.limit:
                await self._refuse(send)
                return
        seen = 0

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                if seen > self.limit:
                    raise TooLarge()
            return message

        try:
            await self.app(scope, counted, send)
        except TooLarge:
            await self._refuse(send)

    async def _refuse(self, send: Send) -> None:
        body = json.dumps(
            {
                "error": f"request body larger than {self.limit} bytes (the server's "
                "limit); convert large models with the command line "
                "(fsmbt convert)",
                "where": None,
            }
        ).encode()
        await send(
            {
                "type": "http.response.start",
                "status": 413,
                "headers": [
                    (b"content-type", b"application/json"),
                    (b"content-length", str(len(body)).encode()),
                ],
            }
        )
        await send({"type": "http.response.body", "body": body})


class TooLarge(Exception):
    """A body went over the limit while it was read (``BodyLimit`` answers 413)."""


def install_handlers(app: FastAPI) -> None:
    """Answer every error of ``app`` as ``{"error", "where"}`` JSON with its status."""

    @app.exception_handler(ApiError)
    async def api_error(_: Request, exc: ApiError) -> JSONResponse:
        return JSONResponse(exc.body, status_code=exc.status)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(_: Request, exc: StarletteHTTPException) -> JSONResponse:
        return JSONResponse({"error": str(exc.detail), "where": None}, status_code=exc.status_code)

    @app.exception_handler(RequestValidationError)
    async def validation_error(_: Request, exc: RequestValidationError) -> JSONResponse:
        first = exc.errors()[0] if exc.errors() else {}
        where = ".".join(str(p) for p in first.get("loc", ()))
        return JSONResponse(
            {"error": f"bad request: {first.get('msg', 'invalid')}", "where": where or None},
            status_code=422,
        )

    @app.exception_handler(Exception)
    async def any_error(_: Request, exc: Exception) -> JSONResponse:
        LOG.exception("unexpected error")
        return JSONResponse(
            {"error": "internal error (logged on the server)", "where": None}, status_code=500
        )
