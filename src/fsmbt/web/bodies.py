"""Request bodies of the web API: one model (``model_body``) or two (``pair_body``), as JSON or
multipart (uploads are texts; a file name is a name, never a path), their field types checked,
and the OpenAPI text of a body read by hand (``body_doc``)."""

from __future__ import annotations

import copy
import json
from typing import Any

from fastapi import Request
from pydantic import BaseModel, ValidationError

from fsmbt.web.errors import ApiError, TooLarge


def inlined_schema(model: Any) -> dict[str, Any]:
    """``model``'s JSON schema with its ``$defs`` written in place: embedded in an operation,
    ``#/$defs/...`` would point at the OpenAPI document's root, where nothing is (schema
    fuzzers could not resolve it). An explicit work list over the (server-made, acyclic)
    schema; every ``{"$ref": "#/$defs/X", ...}`` becomes X's definition merged with the
    other keys."""
    schema: dict[str, Any] = model.model_json_schema()
    defs: dict[str, Any] = schema.pop("$defs", {})
    todo: list[Any] = [schema]
    while todo:
        node = todo.pop()
        children = node.values() if isinstance(node, dict) else node
        for child in list(children):
            if isinstance(child, dict):
                reference = child.get("$ref", "")
                if isinstance(reference, str) and reference.startswith("#/$defs/"):
                    child.pop("$ref")
                    child.update(copy.deepcopy(defs[reference.removeprefix("#/$defs/")]))
                todo.append(child)
            elif isinstance(child, list):
                todo.append(child)
    return schema


def body_doc(model: Any) -> dict[str, Any]:
    """OpenAPI text for a body read by hand (JSON, or the same fields as multipart)."""
    schema = inlined_schema(model)
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
    except TooLarge:
        raise
    except Exception as exc:  # python-multipart's parse errors
        raise ApiError(400, f"the multipart body cannot be read: {exc}"[:300]) from None


def _content_type(request: Request) -> str:
    return request.headers.get("content-type", "").split(";")[0].strip().lower()


def parsed(body: dict[str, Any], schema: type[BaseModel]) -> dict[str, Any]:
    """``body`` parsed by its schema (``fsmbt.web.schemas``): the schema is the validation; the
    first problem is a 400 naming the field. Returns the validated fields (defaults filled)."""
    try:
        return schema.model_validate(body).model_dump()
    except ValidationError as error:
        problem = error.errors()[0]
        field = ".".join(str(step) for step in problem.get("loc", ()))
        if problem.get("type") == "string_type":
            message = f"'{field}' must be a string"
        elif problem.get("type") in ("model_type", "dict_type"):
            message = f"'{field}' must be an object"
        elif problem.get("type") == "missing":
            message = f"'{field}' is missing"
        else:
            message = f"'{field}': {problem.get('msg', 'invalid')}"
        raise ApiError(400, message, field or None) from None


async def model_body(request: Request, schema: type[BaseModel]) -> dict[str, Any]:
    """One model from JSON or multipart (field ``file``, or ``text``; ``options`` as JSON),
    parsed by ``schema``."""
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
    return parsed(body, schema)


async def pair_body(request: Request, schema: type[BaseModel]) -> dict[str, Any]:
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
    if not (isinstance(body.get("first"), dict) and isinstance(body.get("second"), dict)):
        return body  # the service names the missing model ("two models")
    return parsed(body, schema)


def _check_fields(body: dict[str, Any], prefix: str = "") -> None:
    """A file name is a name, never a path (the types are the schema's: ``parsed``)."""
    name = body.get("filename")
    if (
        isinstance(name, str)
        and name
        and ("/" in name or "\\" in name or name in (".", "..") or "\x00" in name)
    ):
        raise ApiError(
            400,
            "'filename' must be a file name, not a path (the server reads no files; send the text)",
            prefix + "filename",
        )
