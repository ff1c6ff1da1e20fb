"""Building chat messages from the versioned prompt templates in ``templates/``.

A conversion template has four parts as in the paper: Role (sent as the system message), Task,
Stepwise Conversion Procedure (SCP) and Constraints (the user message, followed by the compact
model). The SCP is made of named modules (``### module: NAME``) so ablations can drop one; the
NLLM baseline drops the whole SCP and keeps everything else identical. Templates are package
data, so a prompt change is a new file (``fsm_to_bt.v2.md``), never a silent edit of v1.
"""

from __future__ import annotations

import base64
import re
from dataclasses import dataclass, field
from importlib import resources
from string import Template
from typing import Any

from fsmbt.llm.compact import compact_bt, compact_fsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM

FSM_TO_BT = "fsm_to_bt"
BT_TO_FSM = "bt_to_fsm"
DIRECTIONS = (FSM_TO_BT, BT_TO_FSM)
DEFAULT_VERSION = 1
SCP_TITLE = "Stepwise Conversion Procedure"

#: The SCP modules each direction has (the paper's ablation units).
MODULES: dict[str, tuple[str, ...]] = {
    FSM_TO_BT: ("structure_recognition", "lebt_mapping"),
    BT_TO_FSM: ("depth_compression", "hierarchical_rules"),
}

Message = dict[str, Any]
_COMMENT = re.compile(r"<!--.*?-->\s*", re.S)


@dataclass(frozen=True)
class PromptOptions:
    """Which prompt to build: direction, with or without the SCP (NLLM), ablated modules."""

    direction: str
    scp: bool = True
    disabled_modules: frozenset[str] = field(default_factory=frozenset)
    version: int = DEFAULT_VERSION

    def __post_init__(self) -> None:
        if self.direction not in DIRECTIONS:
            raise InputError(f"unknown conversion direction {self.direction!r}")
        unknown = set(self.disabled_modules) - set(MODULES[self.direction])
        if unknown:
            raise InputError(
                f"unknown SCP module(s) {', '.join(sorted(unknown))} for "
                f"{self.direction} (known: {', '.join(MODULES[self.direction])})"
            )

    @property
    def template_id(self) -> str:
        return f"{self.direction}.v{self.version}"

    @property
    def label(self) -> str:
        """Short name for logs: ``fsm_to_bt.v1`` / ``+nllm`` / ``-lebt_mapping``."""
        if not self.scp:
            return f"{self.template_id}+nllm"
        return self.template_id + "".join(f"-{m}" for m in sorted(self.disabled_modules))


def load_template(name: str, version: int = DEFAULT_VERSION) -> str:
    """The template text without its leading comment."""
    resource = resources.files("fsmbt.llm.templates").joinpath(f"{name}.v{version}.md")
    try:
        text = resource.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"no prompt template {name}.v{version}") from None
    return _COMMENT.sub("", text, count=1)


def split_parts(template: str) -> dict[str, str]:
    """``{part title: body}`` for every ``## `` heading, in order."""
    parts: dict[str, str] = {}
    title: str | None = None
    for line in template.splitlines():
        if line.startswith("## "):
            title = line[3:].strip()
            parts[title] = ""
        elif title is not None:
            parts[title] += line + "\n"
    return {k: v.strip("\n") for k, v in parts.items()}


def select_modules(scp: str, disabled: frozenset[str]) -> str:
    """The SCP text without the disabled modules; the module headings themselves are dropped."""
    kept: list[str] = []
    keep = True
    for line in scp.splitlines():
        if line.startswith("### module: "):
            keep = line[len("### module: ") :].strip() not in disabled
            continue
        if keep:
            kept.append(line)
    return "\n".join(kept).strip("\n")


def render_model(model: FSM | BTDocument) -> str:
    if isinstance(model, FSM):
        return "Input FSM:\n" + compact_fsm(model)
    return "Input behavior tree (one node a line, children indented):\n" + compact_bt(model)


def conversion_messages(model: FSM | BTDocument, options: PromptOptions) -> list[Message]:
    """The system and user messages of one conversion request."""
    expected = FSM if options.direction == FSM_TO_BT else BTDocument
    if not isinstance(model, expected):
        raise InputError(
            f"{options.direction} needs a {'FSM' if expected is FSM else 'BT'} as input"
        )
    parts = split_parts(load_template(options.direction, options.version))
    user_parts = [f"# Task\n{parts['Task']}"]
    if options.scp:
        scp = select_modules(parts[SCP_TITLE], options.disabled_modules)
        if scp:
            user_parts.append(f"# {SCP_TITLE}\n{scp}")
    constraints = Template(parts["Constraints"]).substitute(model=render_model(model))
    user_parts.append(f"# Constraints\n{constraints}")
    return [
        {"role": "system", "content": parts["Role"]},
        {"role": "user", "content": "\n\n".join(user_parts)},
    ]


def messages_for(
    model: FSM | BTDocument, *, scp: bool = True, disabled_modules: frozenset[str] = frozenset()
) -> tuple[PromptOptions, list[Message]]:
    """The exact messages a conversion of ``model`` sends (what ``fsmbt llm prompt`` shows).

    An FSM is shown flat (hierarchy flattened first), as the conversion engines send it.

    Args:
        model: the source model; its kind gives the direction.
        scp: the structured prompt (``llm``); ``False`` is the baseline prompt (``nllm``).
        disabled_modules: SCP modules dropped for an ablation.

    Returns:
        The prompt options used and the messages.
    """
    from fsmbt.model.flatten import flatten

    direction = FSM_TO_BT if isinstance(model, FSM) else BT_TO_FSM
    options = PromptOptions(direction, scp=scp, disabled_modules=disabled_modules)
    shown = flatten(model) if isinstance(model, FSM) else model
    return options, conversion_messages(shown, options)


def feedback_message(
    problems: list[str],
    counterexample: str | None,
    output_format: str,
    version: int = DEFAULT_VERSION,
) -> Message:
    """The user message that sends the concrete errors (and a counterexample) back."""
    listed = "\n".join(f"- {p}" for p in problems)
    trace = f"Counterexample:\n{counterexample}" if counterexample else ""
    text = Template(load_template("feedback", version)).substitute(
        problems=f"Problems:\n{listed}", counterexample=trace, format=output_format
    )
    return {"role": "user", "content": re.sub(r"\n{3,}", "\n\n", text).strip()}


def extraction_messages(
    *,
    text: str | None = None,
    image: bytes | None = None,
    image_mime: str | None = None,
    kind: str | None = None,
    version: int = DEFAULT_VERSION,
) -> list[Message]:
    """Messages asking the model to write a model given as text or as a picture in fsmbt JSON.

    An image travels as an ``image_url`` part holding a base64 ``data:`` URL (the OpenAI vision
    format that vision-capable OpenAI-compatible servers accept).
    """
    if (text is None) == (image is None):
        raise ValueError("give exactly one of text and image")
    hint = {"fsm": "It is a state machine.", "bt": "It is a behavior tree."}.get(
        kind or "", "It is a state machine or a behavior tree."
    )
    parts = split_parts(load_template("extract", version))
    instructions = f"# Task\n{Template(parts['Task']).substitute(kind_hint=hint)}\n\n# Constraints\n{parts['Constraints']}"
    system = {"role": "system", "content": parts["Role"]}
    if text is not None:
        return [system, {"role": "user", "content": f"{instructions}\n\nInput:\n{text}"}]
    assert image is not None and image_mime is not None
    url = f"data:{image_mime};base64,{base64.b64encode(image).decode('ascii')}"
    return [
        system,
        {
            "role": "user",
            "content": [
                {"type": "text", "text": f"{instructions}\n\nInput: the diagram in the image."},
                {"type": "image_url", "image_url": {"url": url}},
            ],
        },
    ]
