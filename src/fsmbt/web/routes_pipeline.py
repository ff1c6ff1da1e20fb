"""The pipeline's endpoints: inspect, convert, verify, export, the runtime files. Each parses its
body (``bodies``) and runs one library call in a worker process (``service``, ``workers``) under
the server's time limits (docs/web.md), unless the same request's answer is in the
content-addressed cache (``answers``)."""

from __future__ import annotations

import json
from typing import Any

from fastapi import APIRouter, Request
from fastapi.responses import Response

from fsmbt.web import service
from fsmbt.web.answers import request_key
from fsmbt.web.bodies import body_doc, model_body, pair_body
from fsmbt.web.errors import ApiError
from fsmbt.web.routes_reference import llm_engines
from fsmbt.web.schemas import ConvertBody, ExportBody, ModelText, PictureBody, VerifyBody
from fsmbt.web.workers import Busy, CpuTimeout, WorkerCrashed, WorkTimeout

router = APIRouter()
#: Seconds a refused-as-busy client is asked to wait (``Retry-After``).
RETRY_AFTER_S = 2


async def work(request: Request, function: Any, argument: Any, encode: bool = False) -> Any:
    """``function(argument)`` in a worker; its refusal as a 400; the wall-time limit as 408, the
    CPU-time limit as 422 (each naming the limit), too many waiting requests as 503 with
    ``Retry-After`` (docs/web.md, 'Limits')."""
    settings = request.app.state.settings
    cache = request.app.state.cache
    name = getattr(function, "__name__", str(function))
    key = request_key(f"{name}.json" if encode else name, argument)
    answer: tuple[str, Any] | None = cache.get(key) if cache is not None else None
    try:
        if answer is None:
            answer = await request.app.state.workers.run(function, argument)
            if encode and answer[0] == "ok":
                answer = ("ok", encoded(answer[1]))
            if cache is not None:
                cache.put(key, answer)
    except WorkTimeout:
        raise ApiError(
            408,
            f"over the wall-time limit of {settings.timeout_s:g} s per request (--timeout); "
            "the model is too large for the page: use the command line "
            "(fsmbt convert / fsmbt verify)",
        ) from None
    except CpuTimeout:
        raise ApiError(
            422,
            f"over the CPU-time limit of {settings.cpu_limit_s:g} s per request (--cpu-limit); "
            "the model is too large for the page: use the command line "
            "(fsmbt convert / fsmbt verify)",
        ) from None
    except Busy:
        raise ApiError(
            503,
            "the server is busy (too many requests waiting for a worker, --max-waiting); "
            "try again shortly",
            headers={"retry-after": str(RETRY_AFTER_S)},
        ) from None
    except WorkerCrashed:
        raise ApiError(500, "internal error (logged on the server)") from None
    status: str = answer[0]
    value: Any = answer[1]
    if status == "error":
        raise ApiError(400, value["error"], value["where"])
    return value


async def json_work(request: Request, function: Any, argument: Any) -> Response:
    """``work`` for a call answering a JSON object: the answer is encoded once (as FastAPI's
    ``JSONResponse`` would) and the encoded bytes are what the cache keeps, so a repeated
    request costs a lookup, not a new serialisation of both pictures."""
    value = await work(request, function, argument, encode=True)
    return Response(value, media_type="application/json")


def encoded(value: Any) -> bytes:
    return json.dumps(
        value, ensure_ascii=False, allow_nan=False, indent=None, separators=(",", ":")
    ).encode("utf-8")


@router.post(
    "/api/inspect", summary="Read and validate one model", openapi_extra=body_doc(ModelText)
)
async def inspect(request: Request) -> Any:
    body = await model_body(request, ModelText)
    return await json_work(request, service.inspect, body)


@router.post(
    "/api/convert",
    summary="Convert a model, verify the result, draw both",
    openapi_extra=body_doc(ConvertBody),
)
async def convert(request: Request) -> Any:
    body = await model_body(request, ConvertBody)
    engine = str(body.get("engine") or "rules")
    if engine not in service.PLAIN_ENGINES and engine not in llm_engines():
        known = ", ".join([*service.PLAIN_ENGINES, *llm_engines()])
        raise ApiError(400, f"engine '{engine}' is not offered here (offered: {known})", "engine")
    return await json_work(request, service.convert, body)


@router.post(
    "/api/verify",
    summary="Check two models against each other",
    openapi_extra=body_doc(VerifyBody),
)
async def verify(request: Request) -> Any:
    body = await pair_body(request, VerifyBody)
    return await json_work(request, service.verify, body)


@router.post(
    "/api/picture",
    summary="One model's picture with a fold opened (a BT subtree, an FSM composite state)",
    openapi_extra=body_doc(PictureBody),
)
async def picture(request: Request) -> Any:
    body = await model_body(request, PictureBody)
    return await json_work(request, service.picture, body)


@router.post(
    "/api/export",
    summary="A model in another format (download)",
    openapi_extra=body_doc(ExportBody),
)
async def export(request: Request) -> Response:
    body = await model_body(request, ExportBody)
    data, name, media = await work(request, service.export, body)
    return Response(
        data,
        media_type=media,
        headers={"content-disposition": f'attachment; filename="{name}"'},
    )


@router.get("/api/runtime/{kind}", summary="The runtime files (zip) for converted trees")
async def runtime(request: Request, kind: str) -> Response:
    if kind not in ("cpp", "python"):
        raise ApiError(404, f"no runtime '{kind}' (cpp or python)", "kind")
    data, name = await work(request, service.runtime_zip, kind)
    return Response(
        data,
        media_type="application/zip",
        headers={"content-disposition": f'attachment; filename="{name}"'},
    )
