"""fsmbt's JSON form (schema in docs/formats.md; dictionaries from ``model.serialize``)."""

from __future__ import annotations

import json

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model import Model
from fsmbt.model.errors import InputError
from fsmbt.model.serialize import model_from_dict, model_to_dict


def read_json(text: str, ctx: ReadContext) -> Model:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"invalid JSON: {exc.msg}", location=ctx.location(exc.lineno, exc.colno)) from None
    except RecursionError:
        raise InputError("JSON nested too deeply", location=ctx.location()) from None
    try:
        return model_from_dict(data, where="$")
    except InputError as exc:
        exc.location = exc.location or ctx.location()
        raise


def write_json(model: Model) -> str:
    return json.dumps(model_to_dict(model), indent=2, ensure_ascii=False) + "\n"


def _sniff(text: str) -> bool:
    head = text.lstrip()[:4096]
    return head.startswith("{") and '"kind"' in head


register(Format("json", (".json",), frozenset({"fsm", "bt"}), "fsmbt JSON (either model)",
                read_json, write_json, _sniff, priority=20))
