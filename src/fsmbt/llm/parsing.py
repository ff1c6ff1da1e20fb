"""Getting the model out of an LLM answer: tolerant of wrapping, strict on content.

Tolerated: Markdown code fences (with or without a language tag), chatter before and after,
a missing ``"kind"`` in an FSM answer. Not tolerated: anything wrong inside the model itself;
that goes through the same readers (BT.CPP XML, fsmbt JSON) as a file would, and their error
message becomes the feedback for the next round.
"""

from __future__ import annotations

import json
import re

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.model.serialize import model_from_dict
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE

_FENCE = re.compile(r"```[ \t]*([A-Za-z0-9_+-]*)[^\n]*\n(.*?)```", re.S)
#: The BT.CPP XML reader's registry name.
BTCPP_FORMAT = "btcpp"


class AnswerError(Exception):
    """The answer holds no usable model; ``str(self)`` is sent back as feedback."""


def _fenced_blocks(text: str) -> list[tuple[str, str]]:
    return [(m.group(1).lower(), m.group(2).strip()) for m in _FENCE.finditer(text)]


def extract_xml(text: str) -> str:
    """The ``<root>...</root>`` document in the answer (a fenced block preferred)."""
    candidates = [body for lang, body in _fenced_blocks(text) if "<root" in body]
    source = candidates[0] if candidates else text
    start = source.find("<root")
    end = source.rfind("</root>")
    if start < 0 or end < start:
        raise AnswerError("the answer holds no BT.CPP XML document (<root ...>...</root>)")
    header = source[:start]
    declaration = header[header.rfind("<?xml") :] if "<?xml" in header else ""
    return (declaration.strip() + "\n" if declaration else "") + source[
        start : end + len("</root>")
    ]


def extract_json(text: str) -> str:
    """The JSON object in the answer (a fenced block preferred; else first '{' to last '}')."""
    blocks = [body for lang, body in _fenced_blocks(text) if body.lstrip().startswith("{")]
    source = blocks[0] if blocks else text
    start, end = source.find("{"), source.rfind("}")
    if start < 0 or end < start:
        raise AnswerError("the answer holds no JSON object")
    return source[start : end + 1]


def parse_json_model(text: str, *, default_kind: str | None = None) -> FSM | BTDocument:
    payload = extract_json(text)
    try:
        data = json.loads(payload)
    except json.JSONDecodeError as exc:
        raise AnswerError(
            f"invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
        ) from None
    except RecursionError:
        raise AnswerError("JSON nested too deeply") from None
    if isinstance(data, dict) and "kind" not in data and default_kind is not None:
        data["kind"] = default_kind
    try:
        return model_from_dict(data, where="$")
    except FsmbtError as exc:
        raise AnswerError(str(exc)) from None


def parse_fsm_answer(text: str) -> FSM:
    model = parse_json_model(text, default_kind="fsm")
    if not isinstance(model, FSM):
        raise AnswerError('expected an FSM ("kind": "fsm"), got a behavior tree')
    return model


def parse_bt_answer(text: str) -> BTDocument:
    """Read BT.CPP XML with the project's reader; LEBT leaves get their kinds if undeclared."""
    from fsmbt.formats.registry import loads

    payload = extract_xml(text)
    try:
        model = loads(payload, BTCPP_FORMAT)
    except FsmbtError as exc:
        raise AnswerError(str(exc)) from None
    if not isinstance(model, BTDocument):
        raise AnswerError("expected a behavior tree")
    for _, node in model.nodes():
        if node.type == GUARD_TYPE:
            node.kind, node.kind_declared = NodeKind.CONDITION, True
        elif node.type == STATE_TYPE:
            node.kind, node.kind_declared = NodeKind.ACTION, True
    return model
