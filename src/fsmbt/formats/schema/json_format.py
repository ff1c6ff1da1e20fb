"""fsmbt's JSON form (schema in docs/formats.md; dictionaries from ``model.serialize``).

Nesting is bounded by ``limits.current().max_json_depth`` (``FSMBT_MAX_JSON_DEPTH``), checked
with an explicit stack after parsing; the standard parser itself recurses, so a document deeper
than Python's recursion limit is refused by it first, with the same kind of message.
"""

from __future__ import annotations

import json

from fsmbt import limits
from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model import Model
from fsmbt.model.errors import InputError
from fsmbt.model.serialize import model_from_dict, model_to_dict


def read_json(text: str, ctx: ReadContext) -> Model:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"invalid JSON: {exc.msg}", location=ctx.location(exc.lineno, exc.colno)
        ) from None
    except RecursionError:  # the parser recurses; Python's recursion limit stopped it first
        raise InputError(
            limits.exceeded(
                "JSON nesting deeper than the parser allows",
                "max_json_depth",
                limits.current().max_json_depth,
            ),
            location=ctx.location(),
        ) from None
    _check_depth(data, ctx)
    try:
        return model_from_dict(data, where="$")
    except InputError as exc:
        exc.location = exc.location or ctx.location()
        raise


def _check_depth(data: object, ctx: ReadContext) -> None:
    """Refuse JSON nested deeper than ``max_json_depth`` (explicit stack; O(values))."""
    max_depth = limits.current().max_json_depth
    stack: list[tuple[object, int]] = [(data, 1)]
    while stack:
        value, depth = stack.pop()
        if isinstance(value, (dict, list)):
            if depth > max_depth:
                raise InputError(
                    limits.exceeded(
                        f"JSON nested deeper than {max_depth} levels", "max_json_depth", max_depth
                    ),
                    location=ctx.location(),
                )
            children = value.values() if isinstance(value, dict) else value
            stack.extend((child, depth + 1) for child in children)


def write_json(model: Model) -> str:
    return json.dumps(model_to_dict(model), indent=2, ensure_ascii=False) + "\n"


def _sniff(text: str) -> bool:
    head = text.lstrip()[:4096]
    return head.startswith("{") and '"kind"' in head


register(
    Format(
        "json",
        (".json",),
        frozenset({"fsm", "bt"}),
        "fsmbt JSON (either model)",
        read_json,
        write_json,
        _sniff,
        priority=20,
    )
)
