"""One registry of file formats: each format module registers a reader and/or writer here.

Reading goes through ``loads`` (a text; ``read_text`` reads a file safely first): the size and
encoding are checked before any parser sees the bytes, the format is picked from ``--from``, the
extension or the content, and any problem is an ``InputError`` with the file name. ``dumps``
writes a text. Files are read and written only through ``fsmbt.api`` (``load``, ``write``,
``translate``: the one front door, with the destination check and atomic writes).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from fsmbt import limits
from fsmbt.model.errors import Hint, InputError, SourceLocation, UnsupportedError
from fsmbt.model.files import read_located
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import DATAMODEL, data_places, has_data, parallel_states, parse_lines

if TYPE_CHECKING:
    from fsmbt.model import Model

Reader = Callable[[str, "ReadContext"], "Model"]
Writer = Callable[["Model"], str]


@dataclass
class ReadContext:
    """What a reader may need besides the text.

    Attributes:
        path: The file read, for error locations and relative includes (``None``: a string).
        options: Reader options (e.g. ``node_models`` for BehaviorTree.CPP).
        warnings: Documented, non-fatal deviations the reader recorded, located.
    """

    path: Path | None = None
    options: dict[str, object] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)

    def warn(self, message: str, line: int | None = None, element: str | None = None) -> None:
        """Record a documented, non-fatal deviation (e.g. an ignored SCXML datamodel).

        Args:
            message: What was ignored or changed, and why.
            line: The line it is on, when known.
            element: The element or node it concerns, when known.
        """
        where = f"{self.location(line)}: " + (f"{element}: " if element else "")
        self.warnings.append(f"{where}{message}")

    @property
    def display_name(self) -> str:
        """The file name errors show (``<input>`` for text with no file)."""
        return str(self.path) if self.path is not None else "<input>"

    def location(self, line: int | None = None, column: int | None = None) -> SourceLocation:
        """A location in the input being read.

        Args:
            line: 1-based line, when known.
            column: 1-based column, when known.

        Returns:
            The location, naming :attr:`display_name`.
        """
        return SourceLocation(self.display_name, line, column)


@dataclass(frozen=True)
class Format:
    """A file format: its name, extensions, which models it holds, its reader and writer.

    Attributes:
        name: The name users give it (lower case, e.g. ``"btcpp"``).
        extensions: File name endings that select it (``".xml"``, ``".bt.json"``).
        kinds: Which models it holds, a subset of ``{"fsm", "bt"}``.
        description: One line for format listings.
        read: Text to model, or ``None`` for a write-only format.
        write: Model to text, or ``None`` for a read-only format.
        sniff: Whether a text looks like this format (content detection).
        priority: Order of sniffing; lower is tried first.
        cannot_hold: What its writer refuses, in a person's words.
        read_back_as: The format whose reader reads this write-only format's files.
    """

    name: str
    extensions: tuple[str, ...]
    kinds: frozenset[str]  # subset of {"fsm", "bt"}
    description: str
    read: Reader | None = None
    write: Writer | None = None
    sniff: Callable[[str], bool] | None = None
    priority: int = 50  # lower is tried first when sniffing content
    #: what its writer refuses, in a person's words ("" when it holds every model of its kinds)
    cannot_hold: str = ""
    #: a write-only format whose files another format's reader reads (``btcpp3``: ``btcpp``);
    #: ``fsmbt translate`` reads what it wrote back with that reader to check it
    read_back_as: str | None = None


_FORMATS: dict[str, Format] = {}


def register(fmt: Format) -> Format:
    """Add a format to the registry (a format module calls this on import).

    Args:
        fmt: The format; a later registration under the same name replaces it.

    Returns:
        ``fmt``, so a module can write ``FORMAT = register(Format(...))``.
    """
    _FORMATS[fmt.name] = fmt
    return fmt


def formats() -> list[Format]:
    """Every registered format, built-in ones loaded first.

    Returns:
        The formats in sniffing order (priority, then name).
    """
    _load_builtin_formats()
    return sorted(_FORMATS.values(), key=lambda f: (f.priority, f.name))


def get_format(name: str) -> Format:
    """The format of a given name.

    Args:
        name: A format name, any case.

    Returns:
        The registered format.

    Raises:
        InputError: No format has that name (the message lists the known ones).
    """
    _load_builtin_formats()
    try:
        return _FORMATS[name.lower()]
    except KeyError:
        known = ", ".join(sorted(_FORMATS))
        raise InputError(f"unknown format '{name}' (known: {known})") from None


#: The modules of the built-in formats, each registering its format on import.
BUILTIN_FORMAT_MODULES: tuple[str, ...] = (
    "fsmbt.formats.paper.xml_format",
    "fsmbt.formats.paper.text_format",
    "fsmbt.formats.scxml.structural",
    "fsmbt.formats.btcpp.xml_format",
    "fsmbt.formats.btcpp.v3_write",
    "fsmbt.formats.pysm.smach",
    "fsmbt.formats.pysm.flexbe",
    "fsmbt.formats.schema.json_format",
    "fsmbt.formats.schema.yaml_format",
    "fsmbt.formats.tables.csv_format",
    "fsmbt.formats.tables.markdown",
    "fsmbt.formats.diagrams.dot",
    "fsmbt.formats.diagrams.mermaid",
    "fsmbt.formats.yasmin.formats",
    "fsmbt.formats.smcat.smcat_format",
    "fsmbt.formats.transitions.config_format",
    "fsmbt.formats.pystatemachine.class_format",
)


def _load_builtin_formats() -> None:
    """Import every built-in format module once so each registers itself."""
    import importlib

    for name in BUILTIN_FORMAT_MODULES:
        importlib.import_module(name)


def format_for_path(path: Path, *, writing: bool = False, kind: str | None = None) -> Format | None:
    """The format a file name selects by its extension.

    Args:
        path: The file name; the longest matching extension wins (``.bt.json`` over ``.json``).
        writing: Only formats that can write (else: that can read).
        kind: Only formats that hold this kind of model (``"fsm"`` or ``"bt"``).

    Returns:
        The format, or ``None`` when no extension matches.
    """
    suffixes = "".join(path.suffixes).lower()
    candidates = [
        f
        for f in formats()
        if any(suffixes.endswith(ext) for ext in f.extensions)
        and (f.write if writing else f.read) is not None
        and (kind is None or kind in f.kinds)
    ]
    if not candidates:
        return None
    candidates.sort(key=lambda f: -max(len(e) for e in f.extensions if suffixes.endswith(e)))
    return candidates[0]


def detect_format(text: str, path: Path | None = None) -> Format:
    """Pick a reader: content sniffing first (extensions lie), then the extension.

    Args:
        text: The input text.
        path: The file it came from, for the extension and the error location.

    Returns:
        The format to read ``text`` with.

    Raises:
        InputError: Neither the content nor the extension tells the format.
    """
    for fmt in formats():
        if fmt.read is not None and fmt.sniff is not None and fmt.sniff(text):
            return fmt
    if path is not None:
        by_ext = format_for_path(path)
        if by_ext is not None:
            return by_ext
    raise InputError(
        "cannot tell the format of this input "
        f"(known: {', '.join(f.name for f in formats() if f.read)})",
        location=SourceLocation(str(path) if path else None),
        hints=(Hint.INPUT_FORMAT,),
    )


def decode(data: bytes, name: str) -> str:
    """Bytes to text: UTF-8 (with or without BOM) or UTF-16 with BOM; binary is refused.

    Args:
        data: The raw input.
        name: The input's name, for error locations.

    Returns:
        The decoded text.

    Raises:
        InputError: Empty input, binary data, UTF-16 without a byte-order mark, or invalid
            UTF-8/UTF-16 (the message gives the byte offset and line).
    """
    location = SourceLocation(name)
    if not data.strip():
        raise InputError("empty input: no model in it", location=location)
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise InputError(f"invalid UTF-16 at byte {exc.start}", location=location) from None
    if b"\x00" in data[:8192]:
        head = data[:8192]
        if len(head) >= 4 and (
            head[1::2].count(0) > 0.9 * len(head[1::2])
            or head[0::2].count(0) > 0.9 * len(head[0::2])
        ):
            raise InputError(
                "looks like UTF-16 without a byte-order mark; save the file as UTF-8",
                location=location,
            )
        raise InputError("binary data, not a text model", location=location)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(
            f"not valid UTF-8 at byte {exc.start} (line {line}); save the file as UTF-8",
            location=location,
        ) from None


def loads(
    text: str,
    fmt: str | None = None,
    *,
    path: Path | None = None,
    options: dict[str, object] | None = None,
    warnings: list[str] | None = None,
) -> Model:
    """Parse a model from text.

    Args:
        text: The model's text.
        fmt: A format name; ``None`` detects it (see :func:`detect_format`).
        path: The file the text came from (error locations, relative includes).
        options: Reader options.
        warnings: When given, the reader's documented warnings are appended to it.

    Returns:
        The model (``FSM`` or ``BTDocument``).

    Raises:
        InputError: Unknown or write-only format, text over the size limit, or text the
            reader refuses (located).
        UnsupportedError: A construct the format allows but fsmbt cannot model (located).
    """
    _check_text_size(text, path)
    chosen = get_format(fmt) if fmt else detect_format(text, path)
    if chosen.read is None and chosen.read_back_as is not None:
        chosen = get_format(chosen.read_back_as)  # btcpp3 files are read as btcpp reads them
    if chosen.read is None:
        raise InputError(f"format '{chosen.name}' can be written but not read")
    ctx = ReadContext(path=path, options=dict(options or {}))
    try:
        model = chosen.read(text, ctx)
    except InputError as exc:  # every error names the input, even where a reader did not
        if exc.location is None:
            exc.location = ctx.location()
        raise
    check_model_size(model, ctx.location())
    if warnings is not None:
        warnings.extend(ctx.warnings)
    return model


def _check_text_size(text: str, path: Path | None) -> None:
    limit = limits.current().max_input_bytes
    if len(text) > limit or (
        len(text) * 4 > limit and len(text.encode("utf-8", "replace")) > limit
    ):
        raise InputError(
            limits.exceeded(
                f"the input's {len(text.encode('utf-8', 'replace'))} bytes",
                "max_input_bytes",
                limit,
            ),
            location=SourceLocation(str(path) if path else None),
        )


def check_model_size(model: Model, location: SourceLocation) -> None:
    """Refuse a model with more states (FSM, all levels) or nodes (BT, all trees) than the
    limits allow (``FSMBT_MAX_STATES`` / ``FSMBT_MAX_NODES``). Explicit stacks; O(size)."""
    from fsmbt.model.fsm import FSM

    bounds = limits.current()
    count = 0
    if isinstance(model, FSM):
        for machine in model.machines():  # stops at the first machine past the limit
            count += len(machine.states)
            if count > bounds.max_states:
                raise InputError(
                    limits.exceeded(
                        f"the machine's {count}+ states", "max_states", bounds.max_states
                    ),
                    location=location,
                )
        return
    nodes = [tree.root for tree in model.trees.values() if tree.root is not None]
    while nodes:
        node = nodes.pop()
        count += 1
        if count > bounds.max_nodes:
            raise InputError(
                limits.exceeded(f"the document's {count}+ nodes", "max_nodes", bounds.max_nodes),
                location=location,
            )
        nodes.extend(node.children)


def read_text(path: str | Path) -> str:
    """The text of one model file: a regular file, within the size limit, decoded.

    Raises:
        InputError: a folder, a device or FIFO, a file over the limit, unreadable bytes.
    """
    path = Path(path)
    return decode(read_located(path), str(path))


def dumps(model: Model, fmt: str) -> str:
    """A model as text in a format.

    Args:
        model: An ``FSM`` or a ``BTDocument``.
        fmt: The format name.

    Returns:
        The text the format's writer produces.

    Raises:
        InputError: Unknown or read-only format, or one that cannot hold this kind of model.
        UnsupportedError: The model uses something the format cannot express.
    """
    chosen = get_format(fmt)
    kind = "bt" if not _is_fsm(model) else "fsm"
    if chosen.write is None:
        raise InputError(f"format '{chosen.name}' can be read but not written")
    if kind not in chosen.kinds:
        raise InputError(f"format '{chosen.name}' cannot hold a {kind.upper()}")
    refuse_data_loss(model, chosen.name)
    return chosen.write(model)


#: FSM formats that hold a data model (``fsmbt.model.fsm_data``): SCXML as ``<datamodel>``,
#: JSON and YAML as the attributes they keep, SMACH as userdata and generated decision states
#: (``fsmbt.formats.pysm.smach_data``). ``fsmbt translate`` writes any other format as the
#: machine's exact expansion, named as a loss.
DATA_FORMATS = frozenset({"scxml", "json", "yaml", "smach"})


def keeps_data(model: Model, fmt: str) -> bool:
    """Whether ``fmt`` writes ``model``'s data as data: a machine without data always; else a
    format of ``DATA_FORMATS``, except SMACH for a machine with a parallel state (its regions
    take turns on the data, docs/semantics.md §6a; a SMACH ``Concurrence`` runs its children at
    once, so no userdata can keep the turns)."""
    if not isinstance(model, FSM) or not has_data(model):
        return True
    if fmt == "smach":
        return not parallel_states(model)
    return fmt in DATA_FORMATS


def data_loss_reason(model: FSM, fmt: str) -> str:
    """Why ``fmt`` cannot keep ``model``'s data, in a person's words (``keeps_data`` false)."""
    if fmt == "smach":
        shown = ", ".join(parallel_states(model)[:3])
        return (
            f"smach keeps data as userdata, but not in the parallel state(s) {shown}, whose "
            "regions take turns on it (a SMACH Concurrence runs its children at once)"
        )
    return f"{fmt} has no data model"


def refuse_data_loss(model: Model, fmt: str) -> None:
    """A machine that keeps data written in a format that cannot keep it would lose its
    guards and updates, and with them its meaning: refused, naming what would be lost, where,
    and the ways out (docs/semantics.md, "Data in state machines")."""
    if keeps_data(model, fmt):
        return
    assert isinstance(model, FSM)
    names = [name for name, _expr in parse_lines(model.attrs[DATAMODEL])]
    raise UnsupportedError(
        f"{data_loss_reason(model, fmt)}, and this state machine keeps {len(names)} "
        f"variable(s) in guards and assignments ({data_places(model)}): write it as SCXML, "
        "JSON, YAML or SMACH, translate it (written as its exact flat expansion, named as a "
        "loss), or convert with --unroll",
        element=model.name,
    )


def _is_fsm(model: object) -> bool:
    from fsmbt.model.fsm import FSM

    return isinstance(model, FSM)
