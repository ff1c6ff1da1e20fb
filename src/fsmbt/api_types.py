"""The typed requests of the library API: one definition of every option the pipeline takes.

Why: the command line, the web page, the batch runner, the evaluation and the simulations all
ask the same pipeline (``fsmbt.api``) the same questions. Each option is declared here once,
with its type, default and meaning; every layer builds one of these objects (the web page parses
its JSON bodies straight into them, so these models *are* the API's validation), and the API
reads nothing else. An unknown field is an error, never silently ignored.

- ``ReadOptions``: how a file is read (format, node libraries, abstractions, SubTree files...).
- ``VerifyRequest``: which checker, the loop mode and the state limit.
- ``ConvertRequest``: the engine, its style and options, the output format, whether to
  verify, what may be overwritten; it holds a ``ReadOptions`` and a ``VerifyRequest``'s
  fields.

The models are frozen pydantic models: a request is a value, passed down unchanged; a layer that
needs a variant makes a copy (``request.model_copy(update=...)``). Limits (``max_states``) left
``None`` are read from ``fsmbt.limits.current()`` at the moment of use, in one place
(``checker_limit``), so ``FSMBT_MAX_CHECKER_STATES`` governs every layer alike.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from fsmbt import limits
from fsmbt.model.errors import InputError

#: Checkers ``verify`` and ``convert`` accept.
VerifyEngine = Literal["native", "nusmv", "both"]
#: FSM -> BT of a hierarchical FSM: one SubTree per composite state, or the flattened machine.
Hierarchy = Literal["subtrees", "flatten"]
#: The reader option names (``ReadOptions`` fields that readers receive in their context).
READER_FIELDS = (
    "node_models",
    "nodes",
    "abstract",
    "data",
    "trees",
    "include_root",
    "machine",
    "behaviour",
    "initial",
    "strict",
    "no_profiles",
)


def _as_list(value: object) -> object:
    """Accept one string, a comma list or a sequence for a list-of-strings option."""
    if value is None:
        return []
    if isinstance(value, str):
        return [part.strip() for part in value.split(",") if part.strip()]
    if isinstance(value, (list, tuple)):
        return [str(item) for item in value]
    return value


class _Request(BaseModel):
    """Frozen, no unknown fields: a misspelt option is an error naming it."""

    model_config = ConfigDict(frozen=True, extra="forbid", arbitrary_types_allowed=True)


class ReadOptions(_Request):
    """How a model file is read (docs/cli.md, "Options every reading command takes")."""

    format: str | None = Field(
        default=None, description="the input's format name; detected from content and name"
    )
    node_models: list[str] = Field(
        default_factory=list,
        description="files with <TreeNodesModel> declarations of custom BT nodes",
    )
    nodes: list[str] = Field(
        default_factory=list,
        description="node libraries: profiles (nav2, moveit_pro) or YAML/JSON node files",
    )
    abstract: list[str] = Field(
        default_factory=list,
        description="node families modelled as environment inputs: time, blackboard",
    )
    data: str | None = Field(
        default=None,
        description="SCXML: 'inputs' reads data-dependent conditions as environment inputs",
    )
    trees: list[str] = Field(
        default_factory=list, description="BehaviorTree.CPP files/folders SubTrees may name"
    )
    include_root: str | None = Field(
        default=None, description="the folder <include path> may resolve anywhere under"
    )
    machine: str | None = Field(
        default=None, description="SMACH: which top-level container to read"
    )
    behaviour: str | None = Field(default=None, description="FlexBE: which Behavior class to read")
    initial: str | None = Field(
        default=None, description="tables: the initial state (default: the first row's source)"
    )
    strict: bool = Field(
        default=False,
        description="refuse what a reader would otherwise read as an approximation with a "
        "warning (FlexBE: an embedded behaviour whose file is not found)",
    )

    no_profiles: bool = Field(
        default=False,
        description="do not apply the node profiles and node-model files fsmbt finds by itself "
        "(a known project's nodes, a *_tree_nodes.xml beside the file: docs/semantics.md §10)",
    )

    @field_validator("node_models", "nodes", "abstract", "trees", mode="before")
    @classmethod
    def _listify(cls, value: object) -> object:
        return _as_list(value)

    def reader_options(self) -> dict[str, object] | None:
        """The options the readers take (``fsmbt.formats`` ``ReadContext.options``), or
        ``None`` when none is set."""
        picked: dict[str, object] = {}
        for name in READER_FIELDS:
            value = getattr(self, name)
            if value:
                picked[name] = list(value) if isinstance(value, list) else value
        return picked or None


class VerifyRequest(_Request):
    """How two models are compared."""

    engine: VerifyEngine = Field(default="native", description="native, nusmv or both")
    loop: bool = Field(default=False, description="the BT side's root is ticked again")
    max_states: int | None = Field(
        default=None, ge=1, description="the native checker's state limit (default: the limits)"
    )
    read: ReadOptions = Field(default_factory=ReadOptions)

    def checker_limit(self) -> int:
        """The native checker's state limit: the one asked for, else the limits in force."""
        return checker_limit(self.max_states)


def checker_limit(max_states: int | None) -> int:
    """``max_states``, or ``fsmbt.limits.current().checker_max_states`` when it is ``None``."""
    return max_states if max_states is not None else limits.current().checker_max_states


class ConvertRequest(_Request):
    """One conversion: engine, style, output, verification, reading."""

    engine: str = Field(default="rules", description="rules, bsd, chds (llm, nllm, hybrid)")
    style: str = Field(
        default="auto",
        description="FSM -> BT: auto (structured for outcome-driven machines, else lebt), "
        "structured, lebt (paper)",
    )
    outcomes: str | None = Field(
        default=None,
        description="structured style: outcome statuses, e.g. arrived=success,lost=failure",
    )
    loop: bool = Field(default=False, description="BT -> FSM: the root is ticked again")
    hierarchy: Hierarchy = Field(
        default="subtrees", description="FSM -> BT of an HFSM: subtrees or flatten"
    )
    to: str | None = Field(
        default=None, description="the result's format (default: by extension, btcpp / scxml)"
    )
    verify: bool = Field(default=True, description="prove the result equivalent")
    verify_engine: VerifyEngine = Field(default="native", description="native, nusmv or both")
    load_check: bool = Field(
        default=True,
        description="load a written BehaviorTree.CPP tree in BehaviorTree.CPP 4.8.2 (the C++ "
        "build, else behaviortreepy) and refuse one that does not load",
    )
    max_states: int | None = Field(
        default=None, ge=1, description="state limit of exploration and checker"
    )
    overwrite: bool = Field(default=False, description="an existing output may be replaced")
    keep_not_equivalent: bool = Field(
        default=False, description="write the result even when it is not equivalent"
    )
    read: ReadOptions = Field(default_factory=ReadOptions)
    engine_options: dict[str, Any] = Field(
        default_factory=dict,
        description="further engine options (LLM endpoint, model, regenerations...)",
    )
    llm_client: Any = Field(
        default=None, exclude=True, description="an LLM client passed explicitly (not JSON)"
    )

    @model_validator(mode="before")
    @classmethod
    def _split_options(cls, data: object) -> object:
        """Accept the older flat spelling: ``source_format`` and an ``options`` dict that mixes
        reader options with engine options; each goes to its own field."""
        if not isinstance(data, Mapping):
            return data
        fields = dict(data)
        source_format = fields.pop("source_format", None)
        mixed = fields.pop("options", None)
        if source_format is None and not mixed:
            return fields
        read = fields.get("read")
        read_fields: dict[str, Any] = (
            read.model_dump() if isinstance(read, ReadOptions) else dict(read or {})
        )
        if source_format is not None:
            read_fields["format"] = source_format
        engine_options = dict(fields.get("engine_options") or {})
        for key, value in dict(mixed or {}).items():
            if key in READER_FIELDS:
                read_fields[key] = value
            elif key == "client":
                fields["llm_client"] = value
            elif key == "outcomes":
                fields["outcomes"] = value
            else:
                engine_options[key] = value
        fields["read"] = read_fields
        fields["engine_options"] = engine_options
        return fields

    @property
    def verification(self) -> VerifyRequest:
        """The verification part of this request."""
        return VerifyRequest(
            engine=self.verify_engine, loop=self.loop, max_states=self.max_states, read=self.read
        )

    def checker_limit(self) -> int:
        """The native checker's state limit: the one asked for, else the limits in force."""
        return checker_limit(self.max_states)


#: What a fixed-choice field is called in messages, per request model.
_NOUNS = {
    "VerifyRequest": {"engine": "verification engine"},
    "ConvertRequest": {"verify_engine": "verification engine", "hierarchy": "hierarchy"},
}


def option_error(error: ValidationError) -> InputError:
    """One ``InputError`` naming every invalid option of a request and why (exit 2 in the
    CLI, a 422 on the web page), instead of pydantic's multi-line report."""
    parts = []
    for problem in error.errors():
        where = ".".join(str(step) for step in problem.get("loc", ())) or "request"
        if problem.get("type") == "literal_error":
            noun = _NOUNS.get(error.title, {}).get(where, where.replace("_", " "))
            expected = problem.get("ctx", {}).get("expected", "")
            parts.append(f"unknown {noun} '{problem.get('input')}' (one of: {expected})")
            continue
        parts.append(f"{where}: {problem.get('msg', 'invalid')}")
    return InputError(f"invalid option(s): {'; '.join(parts)}")


def read_options(options: ReadOptions | None = None, **fields: Any) -> ReadOptions:
    """``options`` with ``fields`` changed, or new options from ``fields`` (validated).

    Raises:
        InputError: an unknown reader option or a value of the wrong type (every one named).
    """
    try:
        base = options.model_dump() if options is not None else {}
        return ReadOptions(**{**base, **fields})
    except ValidationError as error:
        raise option_error(error) from None


def convert_request(request: ConvertRequest | None = None, **fields: Any) -> ConvertRequest:
    """``request`` with ``fields`` changed, or a new request from ``fields`` (validated).

    Raises:
        InputError: an unknown option or a value of the wrong type (every problem named).
    """
    if request is not None and not fields:
        return request
    try:
        if request is None:
            return ConvertRequest(**fields)
        client = fields.pop("llm_client", request.llm_client)
        base = request.model_dump(exclude={"llm_client"})
        return ConvertRequest(**{**base, **fields}, llm_client=client)
    except ValidationError as error:
        raise option_error(error) from None


def verify_request(request: VerifyRequest | None = None, **fields: Any) -> VerifyRequest:
    """``request`` with ``fields`` changed, or a new request from ``fields`` (validated).

    ``source_format`` and ``options`` (reader options) are accepted as ``read`` fields."""
    source_format = fields.pop("source_format", None)
    options = fields.pop("options", None)
    if source_format is not None or options:
        base = request.read if request is not None else ReadOptions()
        read_fields = {**base.model_dump(), **dict(options or {})}
        if source_format is not None:
            read_fields["format"] = source_format
        fields["read"] = read_fields
    if request is not None and not fields:
        return request
    try:
        if request is None:
            return VerifyRequest(**fields)
        return VerifyRequest(**{**request.model_dump(), **fields})
    except ValidationError as error:
        raise option_error(error) from None


__all__ = [
    "READER_FIELDS",
    "ConvertRequest",
    "Hierarchy",
    "ReadOptions",
    "VerifyEngine",
    "VerifyRequest",
    "checker_limit",
    "convert_request",
    "option_error",
    "read_options",
    "verify_request",
]
