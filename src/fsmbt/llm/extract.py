"""Models from what a person has: files fsmbt reads, and everything else via the LLM.

``read_input`` reads a file with the project's parsers whenever one recognises it (no LLM
involved, errors reported as usual). Only when no parser claims the text (prose, a table in a
shape no reader knows, an unseen notation), when the file is a PNG/JPEG picture of a diagram,
or when the caller forces it (``--from llm``), the LLM is asked to write the model in fsmbt's
JSON. That JSON then goes through the same JSON reader (and validator) as a file would, so an
extracted model is trusted exactly as much as a typed one; a rejected extraction is sent back
with the reader's message, up to ``max_regenerations`` times.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from fsmbt.formats.registry import (
    Format,
    decode,
    format_for_path,
    formats,
    get_format,
    loads,
)
from fsmbt.llm.client import LLMClient, Message
from fsmbt.llm.config import LLMUnavailableError
from fsmbt.llm.log import (
    EXTRACTED,
    INVALID_ANSWER,
    UNAVAILABLE,
    ConversionRecord,
    RoundRecord,
    append_record,
)
from fsmbt.llm.parsing import AnswerError, extract_json
from fsmbt.llm.prompts import DEFAULT_VERSION, extraction_messages, feedback_message
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError, Hint, InputError, SourceLocation
from fsmbt.model.files import read_bounded
from fsmbt.model.fsm import FSM

Model = FSM | BTDocument

#: Pictures the LLM can read (magic bytes -> MIME type).
IMAGE_SIGNATURES = ((b"\x89PNG\r\n\x1a\n", "image/png"), (b"\xff\xd8\xff", "image/jpeg"))
#: ``--from`` values that force LLM extraction of a text input.
LLM_FORMATS = ("llm", "prose", "text")


class LLMExtractionError(FsmbtError):
    """The LLM gave no valid model for the input after every allowed round (exit 2)."""


@dataclass
class InputOutcome:
    model: Model
    extracted: bool  # True when the LLM wrote the model
    record: ConversionRecord | None = None
    format: str = "llm"  # the parser's format name when a parser read it
    warnings: list[str] = field(default_factory=list)  # that parser's documented warnings


def image_mime(data: bytes) -> str | None:
    for signature, mime in IMAGE_SIGNATURES:
        if data.startswith(signature):
            return mime
    return None


def _parser_for(text: str, path: Path, fmt: str | None) -> tuple[Format | None, bool]:
    """The reader for ``text`` and whether its verdict is final (``--from`` or content sniffed)
    rather than a guess from the file name, which prose in a ``.txt`` file can trip."""
    if fmt is not None:
        return get_format(fmt), True
    for candidate in formats():
        if candidate.read is not None and candidate.sniff is not None and candidate.sniff(text):
            return candidate, True
    return format_for_path(path), False


def needs_llm(path: str | Path, fmt: str | None = None) -> bool:
    """Whether ``read_input`` would call the LLM for this file (no LLM call is made here)."""
    path = Path(path)
    data = _read_bytes(path)
    if (fmt is not None and fmt.lower() in LLM_FORMATS) or image_mime(data) is not None:
        return True
    text = decode(data, str(path))
    parser, final = _parser_for(text, path, fmt)
    if parser is None:
        return True
    if final:
        return False
    try:
        loads(text, parser.name, path=path)
    except InputError:
        return True
    return False


def read_input(
    path: str | Path,
    fmt: str | None = None,
    *,
    client: LLMClient | None = None,
    kind: str | None = None,
    max_regenerations: int | None = None,
) -> InputOutcome:
    """Read ``path`` with a parser when one knows it; otherwise let the LLM extract it.

    A reader chosen by ``--from`` or by the content has the last word (its errors are reported);
    one guessed only from the extension that fails hands the text to the LLM when a ``client``
    is given. ``kind`` ("fsm"/"bt") tells the model what to expect when the caller knows it.
    """
    path = Path(path)
    data = _read_bytes(path)
    mime = image_mime(data)
    if mime is None and (fmt is None or fmt.lower() not in LLM_FORMATS):
        text = decode(data, str(path))
        parser, final = _parser_for(text, path, fmt)
        if parser is not None:
            try:
                warnings: list[str] = []
                model = loads(text, parser.name, path=path, warnings=warnings)
                return InputOutcome(model, False, format=parser.name, warnings=warnings)
            except InputError as exc:
                if final:
                    raise
                if client is None:
                    raise InputError(
                        f"{exc.message} (read as {parser.name} from the file name; if "
                        "it is prose or another notation, an LLM can extract the "
                        "model)",
                        location=exc.location,
                        element=exc.element,
                        hints=(*exc.hints, Hint.LLM_ENGINE),
                    ) from None
        elif client is None:
            raise InputError(
                "no reader knows this input; an LLM can extract the model from it",
                location=SourceLocation(str(path)),
                hints=(Hint.LLM_ENGINE,),
            )
    if client is None:
        raise InputError(
            "this input needs an LLM to extract the model (configure one: docs/llm.md)",
            location=SourceLocation(str(path)),
        )
    if mime is not None:
        return extract_model(
            client,
            image=data,
            image_mime_type=mime,
            kind=kind,
            source_name=str(path),
            max_regenerations=max_regenerations,
        )
    return extract_model(
        client,
        text=decode(data, str(path)),
        kind=kind,
        source_name=str(path),
        max_regenerations=max_regenerations,
    )


def extract_model(
    client: LLMClient,
    *,
    text: str | None = None,
    image: bytes | None = None,
    image_mime_type: str | None = None,
    kind: str | None = None,
    source_name: str = "<input>",
    max_regenerations: int | None = None,
) -> InputOutcome:
    """Ask the LLM for the model in fsmbt JSON and read it like a JSON file."""
    settings = client.settings
    rounds_allowed = 1 + (
        settings.max_regenerations if max_regenerations is None else max_regenerations
    )
    prompt = extraction_messages(text=text, image=image, image_mime=image_mime_type, kind=kind)
    record = ConversionRecord(
        engine="extract",
        task="extract",
        prompt=f"extract.v{DEFAULT_VERSION}" + ("+image" if image else ""),
        model=settings.model,
        source=source_name,
    )
    conversation: list[Message] = list(prompt)
    try:
        for round_no in range(rounds_allowed):
            completion = client.complete(conversation)
            try:
                model = read_extracted(completion.text, kind=kind)
            except AnswerError as exc:
                problems = [str(exc)]
                record.add_round(
                    RoundRecord(
                        round_no,
                        "parse",
                        problems,
                        completion.tokens_in,
                        completion.tokens_out,
                        round(completion.latency_s, 4),
                        completion.attempts,
                    )
                )
                conversation = prompt + [
                    {"role": "assistant", "content": completion.text},
                    feedback_message(problems, None, "fsmbt JSON"),
                ]
                continue
            record.add_round(
                RoundRecord(
                    round_no,
                    "ok",
                    [],
                    completion.tokens_in,
                    completion.tokens_out,
                    round(completion.latency_s, 4),
                    completion.attempts,
                )
            )
            record.verdict = EXTRACTED
            append_record(settings.log_path, record)
            return InputOutcome(model, True, record)
    except LLMUnavailableError as exc:
        record.verdict = UNAVAILABLE
        record.extra["error"] = str(exc)
        append_record(settings.log_path, record)
        raise
    record.verdict = INVALID_ANSWER
    append_record(settings.log_path, record)
    last = record.rounds[-1].problems[0] if record.rounds else "no answer"
    raise LLMExtractionError(
        f"the LLM gave no valid model after {len(record.rounds)} round(s); last problem: {last}",
        location=SourceLocation(source_name),
    )


def read_extracted(answer: str, *, kind: str | None = None) -> Model:
    """The answer's JSON read by the JSON format reader, then validated like any input."""
    payload = extract_json(answer)
    try:
        data = json.loads(payload)
    except json.JSONDecodeError as exc:
        raise AnswerError(
            f"invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
        ) from None
    if isinstance(data, dict) and "kind" not in data:
        data["kind"] = kind or ("bt" if "trees" in data else "fsm")
    if kind is not None and isinstance(data, dict) and data.get("kind") != kind:
        raise AnswerError(f'expected "kind": "{kind}"')
    try:
        model = loads(json.dumps(data), "json")
        _validate(model)
    except FsmbtError as exc:
        raise AnswerError(str(exc)) from None
    return model


def _validate(model: Model) -> None:
    """The project's model validator when present (every reader's last step)."""
    try:
        from fsmbt.model import validate as validation
    except ImportError:
        return
    for name in ("validate", "validate_model"):
        func = getattr(validation, name, None)
        if callable(func):
            func(model)
            return


def _read_bytes(path: Path) -> bytes:
    try:
        return read_bounded(path)
    except OSError as exc:
        raise InputError(
            f"cannot read: {exc.strerror}", location=SourceLocation(str(path))
        ) from None
