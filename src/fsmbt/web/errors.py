"""The web API's errors: every refusal is ``{"error": "<one line>", "where": ...}`` with a 4xx
(bad input; 408/422 past the wall/CPU-time limit), 503 (busy) or 500 (a bug, logged) - never a
traceback - and bodies over the server's limit are refused (413) before they are read whole
(docs/web.md)."""

from __future__ import annotations

import json
import logging
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from fsmbt.web.settings import DEFAULT_DRAIN_CAP_BYTES

LOG = logging.getLogger("fsmbt.web")


class ApiError(Exception):
    """A refused request: status and the one-line cause."""

    def __init__(
        self, status: int, error: str, where: Any = None, headers: dict[str, str] | None = None
    ) -> None:
        super().__init__(error)
        self.status = status
        self.body = {"error": error, "where": where}
        self.headers = headers or {}


class BodyLimit:
    """ASGI middleware refusing bodies over ``limit`` bytes with 413 and the API's JSON error.

    Rules (docs/web.md, 'Limits'; docs/security.md):

    - A declared ``Content-Length`` over the limit is refused before any byte of the body is
      read or parsed. A client that sent ``Expect: 100-continue`` gets the 413 at once (the
      server never sends ``100 Continue`` because the body is never asked for).
    - Any other client is still sending: answering and closing with its bytes unread makes the
      kernel reset the connection, and the client sees a reset instead of the 413. So the
      body is read and thrown away (never kept, never parsed) up to ``drain_cap`` bytes, then
      the 413 is sent on a connection that stays usable. Past ``drain_cap`` the 413 is sent
      with ``connection: close`` and the server stops reading (a reset is then possible; it
      only happens to bodies over ``drain_cap``).
    - A body without a length (chunked) is counted while the application reads it; over the
      limit the rest is drained the same way and the 413 answered.

    Cost: discarding is a loop over the server's receive buffer, no copy kept: memory is one
    chunk, time is the transfer of at most ``drain_cap`` bytes.
    """

    def __init__(self, app: ASGIApp, limit: int, drain_cap: int = DEFAULT_DRAIN_CAP_BYTES) -> None:
        self.app = app
        self.limit = limit
        self.drain_cap = max(drain_cap, limit)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared: int | None = None
        expects_continue = False
        for name, value in scope.get("headers", []):
            if name == b"content-length" and value.isdigit():
                declared = int(value)
            elif name == b"expect" and value.lower() == b"100-continue":
                expects_continue = True
        if declared is not None and declared > self.limit:
            if expects_continue:
                await self._refuse(send, close=True)
            else:
                drained = await self._drain(receive, 0)
                await self._refuse(send, close=not drained)
            return
        seen = 0
        started = False

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                if seen > self.limit:
                    raise TooLarge(seen, more=bool(message.get("more_body", False)))
            return message

        async def watched(message: Message) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        try:
            await self.app(scope, counted, watched)
        except TooLarge as too_large:
            if started:
                raise
            drained = (not too_large.more) or await self._drain(receive, too_large.seen)
            await self._refuse(send, close=not drained)

    async def _drain(self, receive: Receive, seen: int) -> bool:
        """Read and drop the rest of the body; ``False`` when it went past ``drain_cap`` (or
        the client left) before its end."""
        while seen <= self.drain_cap:
            message = await receive()
            if message["type"] != "http.request":
                return False
            seen += len(message.get("body", b""))
            if not message.get("more_body", False):
                return seen <= self.drain_cap
        return False

    async def _refuse(self, send: Send, close: bool) -> None:
        body = json.dumps(
            {
                "error": f"request body larger than {self.limit} bytes (the server's "
                "limit); convert large models with the command line "
                "(fsmbt convert)",
                "where": None,
            }
        ).encode()
        headers = [
            (b"content-type", b"application/json"),
            (b"content-length", str(len(body)).encode()),
        ]
        if close:
            headers.append((b"connection", b"close"))
        await send({"type": "http.response.start", "status": 413, "headers": headers})
        await send({"type": "http.response.body", "body": body})


class TooLarge(Exception):
    """A body went over the limit while it was read (``BodyLimit`` answers 413).

    Attributes:
        seen: bytes read so far.
        more: whether the client is still sending (the rest is drained before the answer).
    """

    def __init__(self, seen: int = 0, more: bool = False) -> None:
        super().__init__(f"body over the limit after {seen} bytes")
        self.seen = seen
        self.more = more


def install_handlers(app: FastAPI) -> None:
    """Answer every error of ``app`` as ``{"error", "where"}`` JSON with its status."""

    @app.exception_handler(ApiError)
    async def api_error(_: Request, exc: ApiError) -> JSONResponse:
        return JSONResponse(exc.body, status_code=exc.status, headers=exc.headers)

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
