"""The FastAPI application: the page, its JSON API, read-only report browsing (docs/web.md).

``create_app(settings)`` builds it. The page (``templates/index.html`` + ``static/app.js``) only
calls the API below, so everything it shows is available to any client:

- ``GET /api/formats``, ``GET /api/engines``, ``GET /api/examples``, ``GET /api/examples/{name}``
- ``POST /api/inspect`` (read + validate), ``/api/convert``, ``/api/verify``, ``/api/export``,
  ``GET /api/runtime/{cpp|python}``
- with ``reports_dir``: ``GET /api/reports``, ``GET /reports/{path}``, ``GET /api/batch/{path}``

Rules: bodies over ``max_body_bytes`` are refused (413) before they are read whole; JSON or
multipart only (415 otherwise); no request names a server path (uploads are texts, examples are
picked by name from a listing, report files are resolved inside ``reports_dir`` and refused
outside it); every error is ``{"error": "<one line>", "where": ...}`` with a 4xx (bad input),
503 (time limit) or 500 (a bug, logged) - never a traceback.
"""

from __future__ import annotations

import json
import logging
import sqlite3
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse, Response
from fastapi.staticfiles import StaticFiles
from fastapi.templating import Jinja2Templates
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from fsmbt.formats import detect_format
from fsmbt.model.errors import FsmbtError
from fsmbt.web import service
from fsmbt.web.schemas import ConvertRequest, ExportRequest, ModelText, VerifyRequest
from fsmbt.web.settings import WebSettings
from fsmbt.web.workers import Busy, WorkerCrashed, Workers, WorkTimeout

LOG = logging.getLogger("fsmbt.web")
HERE = Path(__file__).parent
#: Files in the examples folder that are not models.
NOT_EXAMPLES = ("README.md",)
#: Most rows of one table shown from a batch store.
MAX_BATCH_ROWS = 500
#: How deep report browsing looks for report folders and batch stores.
MAX_REPORT_DEPTH = 4


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
                    raise _TooLarge()
            return message

        try:
            await self.app(scope, counted, send)
        except _TooLarge:
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


class _TooLarge(Exception):
    pass


def create_app(settings: WebSettings | None = None) -> FastAPI:
    """The web application.

    Args:
        settings: limits and folders (``WebSettings.default()`` when ``None``).

    Returns:
        The FastAPI app (its OpenAPI page is ``/docs``).
    """
    settings = settings or WebSettings.default()
    state: dict[str, Workers] = {}

    @asynccontextmanager
    async def lifespan(_: FastAPI):  # type: ignore[no-untyped-def]
        state["workers"] = Workers(settings.workers, settings.timeout_s)
        yield
        state.pop("workers").close()

    app = FastAPI(
        title="fsmbt",
        version="0.1.0",
        lifespan=lifespan,
        description="Convert behavior models between FSMs and behavior trees and "
        "prove the result equivalent (docs/web.md).",
    )
    app.add_middleware(BodyLimit, limit=settings.max_body_bytes)
    app.mount("/static", StaticFiles(directory=HERE / "static"), name="static")
    templates = Jinja2Templates(directory=str(HERE / "templates"))

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

    async def work(function: Any, argument: Any) -> Any:
        try:
            status, value = await state["workers"].run(function, argument)
        except WorkTimeout:
            raise ApiError(
                503,
                f"took longer than {settings.timeout_s:g} s, the page's limit; "
                "the model is too large for the page: use the command line "
                "(fsmbt convert / fsmbt verify)",
            ) from None
        except Busy:
            raise ApiError(
                503, "the server is busy (too many requests waiting); try again shortly"
            ) from None
        except WorkerCrashed:
            raise ApiError(500, "internal error (logged on the server)") from None
        if status == "error":
            raise ApiError(400, value["error"], value["where"])
        return value

    # -- page ---------------------------------------------------------------------------------
    @app.get("/", response_class=HTMLResponse, include_in_schema=False)
    async def page(request: Request) -> Response:
        return templates.TemplateResponse(
            request, "index.html", {"reports": settings.reports_dir is not None}
        )

    # -- reference data -----------------------------------------------------------------------
    @app.get("/api/formats", summary="Every format fsmbt reads or writes")
    async def get_formats() -> list[dict[str, Any]]:
        return service.format_list()

    @app.get("/api/engines", summary="The conversion engines this server offers")
    async def get_engines() -> dict[str, Any]:
        return {
            "engines": list(service.PLAIN_ENGINES) + _llm_engines(),
            "hierarchies": list(service.HIERARCHIES),
            "styles": list(service.STYLES),
            "runtimes": service.runtime_kinds(),
        }

    @app.get("/api/examples", summary="The example models (by name)")
    async def get_examples() -> list[dict[str, str]]:
        return [{"name": name, "format": fmt} for name, fmt in _examples(settings).items()]

    @app.get("/api/examples/{name}", summary="One example model's text")
    async def get_example(name: str) -> dict[str, str]:
        listing = _examples(settings)
        if name not in listing or settings.examples_dir is None:
            raise ApiError(404, f"no example named '{name}'", "name")
        text = (settings.examples_dir / name).read_text(encoding="utf-8")
        return {"name": name, "format": listing[name], "text": text}

    # -- the pipeline -------------------------------------------------------------------------
    @app.post(
        "/api/inspect", summary="Read and validate one model", openapi_extra=_body_doc(ModelText)
    )
    async def inspect(request: Request) -> Any:
        body = await _model_body(request)
        return await work(service.inspect, body)

    @app.post(
        "/api/convert",
        summary="Convert a model, verify the result, draw both",
        openapi_extra=_body_doc(ConvertRequest),
    )
    async def convert(request: Request) -> Any:
        body = await _model_body(request)
        engine = str(body.get("engine") or "rules")
        if engine not in service.PLAIN_ENGINES and engine not in _llm_engines():
            known = ", ".join([*service.PLAIN_ENGINES, *_llm_engines()])
            raise ApiError(
                400, f"engine '{engine}' is not offered here (offered: {known})", "engine"
            )
        return await work(service.convert, body)

    @app.post(
        "/api/verify",
        summary="Check two models against each other",
        openapi_extra=_body_doc(VerifyRequest),
    )
    async def verify(request: Request) -> Any:
        body = await _pair_body(request)
        return await work(service.verify, body)

    @app.post(
        "/api/export",
        summary="A model in another format (download)",
        openapi_extra=_body_doc(ExportRequest),
    )
    async def export(request: Request) -> Response:
        body = await _model_body(request)
        data, name, media = await work(service.export, body)
        return Response(
            data,
            media_type=media,
            headers={"content-disposition": f'attachment; filename="{name}"'},
        )

    @app.get("/api/runtime/{kind}", summary="The runtime files (zip) for converted trees")
    async def runtime(kind: str) -> Response:
        if kind not in ("cpp", "python"):
            raise ApiError(404, f"no runtime '{kind}' (cpp or python)", "kind")
        data, name = await work(service.runtime_zip, kind)
        return Response(
            data,
            media_type="application/zip",
            headers={"content-disposition": f'attachment; filename="{name}"'},
        )

    # -- reports (read-only) ------------------------------------------------------------------
    @app.get("/api/reports", summary="Evaluation reports and batch stores under --reports")
    async def reports() -> dict[str, list[str]]:
        root = _reports_root(settings)
        found: dict[str, list[str]] = {"reports": [], "batches": []}
        stack: list[tuple[Path, int]] = [(root, 0)]
        while stack:
            folder, depth = stack.pop()
            if (folder / "index.html").is_file():
                found["reports"].append(_relative(folder / "index.html", root))
            if (folder / "results.sqlite").is_file():
                found["batches"].append(_relative(folder / "results.sqlite", root))
            if depth < MAX_REPORT_DEPTH:
                stack.extend(
                    (child, depth + 1)
                    for child in sorted(folder.iterdir(), reverse=True)
                    if child.is_dir() and not child.is_symlink()
                )
        return found

    @app.get("/reports/{path:path}", include_in_schema=False)
    async def report_file(path: str) -> Response:
        return FileResponse(_inside(_reports_root(settings), path))

    @app.get("/api/batch/{path:path}", summary="A batch store's tables (read-only)")
    async def batch(path: str) -> dict[str, Any]:
        target = _inside(_reports_root(settings), path)
        if target.name != "results.sqlite":
            raise ApiError(400, "not a batch store (results.sqlite)", path)
        return _read_store(target)

    return app


# -- helpers ------------------------------------------------------------------------------------


def _body_doc(model: Any) -> dict[str, Any]:
    """OpenAPI text for a body read by hand (JSON, or the same fields as multipart)."""
    schema = model.model_json_schema()
    return {
        "requestBody": {
            "required": True,
            "content": {
                "application/json": {"schema": schema},
                "multipart/form-data": {
                    "schema": {
                        "type": "object",
                        "properties": {
                            "file": {"type": "string", "format": "binary"},
                            **{
                                k: v for k, v in schema.get("properties", {}).items() if k != "text"
                            },
                        },
                    }
                },
            },
        }
    }


def _llm_engines() -> list[str]:
    """The LLM engines, offered only when the server's environment configures an endpoint."""
    from fsmbt.api import LLM_ENGINES
    from fsmbt.llm.config import resolve_settings

    try:
        resolve_settings()
    except FsmbtError:
        return []
    return list(LLM_ENGINES)


def _examples(settings: WebSettings) -> dict[str, str]:
    folder = settings.examples_dir
    if folder is None or not folder.is_dir():
        return {}
    found: dict[str, str] = {}
    for path in sorted(folder.iterdir()):
        if not path.is_file() or path.name in NOT_EXAMPLES or path.stat().st_size > 1_000_000:
            continue
        try:
            text = path.read_text(encoding="utf-8")
            found[path.name] = detect_format(text, path).name
        except (FsmbtError, UnicodeDecodeError, OSError):
            continue
    return found


def _json_object(raw: bytes) -> dict[str, Any]:
    try:
        data = json.loads(raw)
    except RecursionError:
        raise ApiError(400, "the JSON body is nested too deeply") from None
    except (UnicodeDecodeError, ValueError) as exc:
        raise ApiError(400, f"the body is not valid JSON: {exc}"[:300]) from None
    if not isinstance(data, dict):
        raise ApiError(400, "the JSON body must be an object")
    return data


def _decode_upload(data: bytes, field: str) -> str:
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ApiError(
            400, f"the uploaded file is not UTF-8 text (byte {exc.start})", field
        ) from None


async def _form(request: Request) -> Any:
    try:
        return await request.form(max_files=2, max_fields=20)
    except _TooLarge:
        raise
    except Exception as exc:  # python-multipart's parse errors
        raise ApiError(400, f"the multipart body cannot be read: {exc}"[:300]) from None


def _content_type(request: Request) -> str:
    return request.headers.get("content-type", "").split(";")[0].strip().lower()


async def _model_body(request: Request) -> dict[str, Any]:
    """One model from JSON or multipart (field ``file``, or ``text``; ``options`` as JSON)."""
    kind = _content_type(request)
    if kind == "application/json":
        body = _json_object(await request.body())
    elif kind == "multipart/form-data":
        form = await _form(request)
        body = {k: v for k, v in form.items() if isinstance(v, str)}
        upload = form.get("file")
        if upload is not None and not isinstance(upload, str):
            body["text"] = _decode_upload(await upload.read(), "file")
            body.setdefault("filename", upload.filename or "")
        if "options" in body:
            body["options"] = _json_object(body["options"].encode())
        if "loop" in body or "hierarchy" in body:
            options = body.setdefault("options", {})
            if "loop" in body:
                options["loop"] = body.pop("loop").lower() in ("1", "true", "on", "yes")
            if "hierarchy" in body:
                options["hierarchy"] = body.pop("hierarchy")
    else:
        raise ApiError(
            415,
            f"unsupported content type '{kind or 'none'}': send "
            "application/json or multipart/form-data",
        )
    _check_fields(body)
    return body


async def _pair_body(request: Request) -> dict[str, Any]:
    """Two models from JSON (``first``, ``second``) or multipart (files ``first``, ``second``)."""
    kind = _content_type(request)
    if kind == "application/json":
        body = _json_object(await request.body())
    elif kind == "multipart/form-data":
        form = await _form(request)
        body = {"options": {"loop": str(form.get("loop", "")).lower() in ("1", "true", "on")}}
        for side in ("first", "second"):
            upload = form.get(side)
            if upload is None or isinstance(upload, str):
                raise ApiError(400, f"missing the '{side}' file", side)
            body[side] = {
                "text": _decode_upload(await upload.read(), side),
                "filename": upload.filename or "",
                "format": form.get(f"{side}_format") or None,
            }
    else:
        raise ApiError(
            415,
            f"unsupported content type '{kind or 'none'}': send "
            "application/json or multipart/form-data",
        )
    for side in ("first", "second"):
        if isinstance(body.get(side), dict):
            _check_fields(body[side], prefix=f"{side}.")
    return body


def _check_fields(body: dict[str, Any], prefix: str = "") -> None:
    """Types of the fields a model request has; a file name is a name, never a path."""
    for key in ("text", "filename", "format", "engine", "to", "name"):
        value = body.get(key)
        if value is not None and not isinstance(value, str):
            raise ApiError(400, f"'{prefix}{key}' must be a string", prefix + key)
    name = body.get("filename")
    if name and ("/" in name or "\\" in name or name in (".", "..") or "\x00" in name):
        raise ApiError(
            400,
            "'filename' must be a file name, not a path (the server reads no files; send the text)",
            prefix + "filename",
        )
    options = body.get("options")
    if options is not None and not isinstance(options, dict):
        raise ApiError(400, f"'{prefix}options' must be an object", prefix + "options")


def _reports_root(settings: WebSettings) -> Path:
    if settings.reports_dir is None:
        raise ApiError(404, "report browsing is off (start the server with --reports DIR)")
    return settings.reports_dir.resolve()


def _inside(root: Path, path: str) -> Path:
    """``path`` resolved under ``root``; refused when it leaves it or is not a file."""
    if "\x00" in path or path.startswith(("/", "\\")):
        raise ApiError(400, "not a path inside the reports folder", path)
    target = (root / path).resolve()
    if not target.is_relative_to(root):
        raise ApiError(400, "not a path inside the reports folder", path)
    if not target.is_file():
        raise ApiError(404, "no such file in the reports folder", path)
    return target


def _relative(path: Path, root: Path) -> str:
    return path.relative_to(root).as_posix()


def _read_store(path: Path) -> dict[str, Any]:
    """Every table of a batch store, opened read-only (``mode=ro``), at most
    ``MAX_BATCH_ROWS`` rows each."""
    try:
        connection = sqlite3.connect(f"{path.as_uri()}?mode=ro", uri=True)
    except sqlite3.Error as exc:
        raise ApiError(400, f"cannot open the batch store: {exc}") from None
    try:
        names = [
            row[0]
            for row in connection.execute(
                "SELECT name FROM sqlite_master WHERE type='table' ORDER BY name"
            )
        ]
        tables = {}
        for name in names:
            cursor = connection.execute(
                f'SELECT * FROM "{name.replace(chr(34), "")}" LIMIT ?', (MAX_BATCH_ROWS,)
            )
            columns = [c[0] for c in cursor.description or ()]
            tables[name] = {
                "columns": columns,
                "rows": [[_cell(v) for v in row] for row in cursor.fetchall()],
            }
        return {"store": path.name, "tables": tables}
    except sqlite3.Error as exc:
        raise ApiError(400, f"cannot read the batch store: {exc}") from None
    finally:
        connection.close()


def _cell(value: Any) -> Any:
    return value if isinstance(value, (int, float, str)) or value is None else repr(value)[:200]
