"""fsmbt's library API: the whole pipeline, read -> model -> convert -> verify -> write.

Why one module: the command line, the batch runner, the evaluation, the web page and the
simulations all do the same few things with a model, and each must do them the same way (the
same reader, the same engine table, the same checker, the same refusal to overwrite). They call
these functions and only parse options and print around them; none of them does this work again.

The steps, each a thin public function over the package that owns it:

- ``load`` / ``load_text``: a file or a text into a model (``fsmbt.formats``), with the reader's
  warnings and the format it was read as. ``load_for_llm`` reads through the LLM extraction
  step (``fsmbt.llm.extract``) when an LLM engine is asked for and no parser reads the input.
- ``convert_model``: one engine's conversion (``fsmbt.convert``); the direction follows the
  model's kind.
- ``verify_models``: the five properties (``fsmbt.verify``), native, NuSMV or both.
- ``check_destination`` / ``write``: where the result goes, checked *before* any work is done,
  and written atomically (a temporary file in the same folder, then a rename), so an output is
  never left half-written.
- ``check_loads`` (``fsmbt.semantics.engines.btcpp_load``): a behavior tree written for
  BehaviorTree.CPP is loaded in BehaviorTree.CPP 4.8.2 before it is reported or written, an
  SCXML result in python-statemachine where it is installed (``scxml_load``); a result the
  engine refuses is a located ``TreeLoadError``, never a verdict (docs/semantics.md §5,
  "Every written tree loads"). ``ConvertRequest.load_check=False`` skips it. The check runs
  beside the proof (``semantics.engines.load_beside``: the two are independent), so a large
  result costs the longer of the two, not their sum.
- ``convert_file``: all of it for one input, returning one ``Outcome`` (both models, the
  conversion, the report, timings, warnings, where the result was written).

What happens to the output when the result is not equivalent (docs/cli.md, "convert"): the
result is verified *before* it is written. An equivalent result (or one not verified, when
verification was switched off) is written; a result that is not equivalent is not written, so a
wrong model never lands where the user expects a proven one, unless ``keep_not_equivalent`` asks
for it (then it is written, and the ``Outcome`` says it is not equivalent). Either way the
result's text is in the ``Outcome``.

Costs: reading is linear in the input; conversion and verification costs are stated in
``fsmbt.convert`` and ``fsmbt.verify``; writing is linear in the output.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fsmbt.api_types import (
    ConvertRequest,
    ReadOptions,
    VerifyRequest,
    checker_limit,
    convert_request,
    verify_request,
)
from fsmbt.convert import ConversionResult, convert
from fsmbt.convert.engines import NUSMV_CHECKED
from fsmbt.formats import detect_format, dumps, get_format, loads
from fsmbt.formats.registry import format_for_path, read_text
from fsmbt.formats.translate import Translation, expand_data_for
from fsmbt.formats.translate import translate as translate_model
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import Hint, InputError, SourceLocation, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.model.validate import Issue
from fsmbt.semantics.blockers import Blocker
from fsmbt.semantics.blockers import conversion_blockers as blockers_of
from fsmbt.semantics.engines.btcpp_load import LoadCheck
from fsmbt.semantics.engines.load_beside import PendingLoad, start_load_check
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.verify import Report, verify
from fsmbt.verify.native import StateLimitError
from fsmbt.verify.orient import OUTCOME_RULE, orient, rules_text
from fsmbt.verify.wording import readable

Model = FSM | BTDocument

#: The format a result is written in when neither a format nor a file extension names one.
DEFAULT_FSM_FORMAT = "scxml"  # BT -> FSM: nested states survive
DEFAULT_BT_FORMAT = "btcpp"  # FSM -> BT: BehaviorTree.CPP v4 XML with TreeNodesModel
#: Engines that ask a language model (they read prose and pictures through LLM extraction).
LLM_ENGINES = ("llm", "nllm", "hybrid")
#: Formats whose events are the states' outcomes (docs/semantics.md §11): ``--style auto``
#: gives their machines the structured tree.
OUTCOME_FORMATS = ("smach", "flexbe", "yasmin")

#: The verdict words every layer prints and stores.
EQUIVALENT = "EQUIVALENT"
NOT_EQUIVALENT = "NOT EQUIVALENT"
NOT_VERIFIED = "NOT VERIFIED"

#: ``on_stage`` is told each step's name as it starts: "read", "convert", "verify", "write".
StageHook = Callable[[str], None]


@dataclass
class Loaded:
    """A model read from a file or a text, with what the reader had to say about it.

    Attributes:
        model: the model (an ``FSM`` or a ``BTDocument``).
        path: the file it came from, or ``None`` for a text.
        format: the name of the format it was read as (``"btcpp"``, ``"scxml"``, ... or
            ``"llm"`` when a language model extracted it).
        warnings: the reader's documented, non-fatal deviations, each with its location.
        extracted_by_llm: ``True`` when no parser read the input and the LLM wrote the model.
    """

    model: Model
    path: Path | None
    format: str
    warnings: list[str] = field(default_factory=list)
    extracted_by_llm: bool = False

    @property
    def kind(self) -> str:
        """``"fsm"`` or ``"bt"``."""
        return model_kind(self.model)


@dataclass
class Outcome:
    """Everything one conversion produced, for any layer to print, store or show.

    Attributes:
        source: the loaded source model.
        conversion: the engine's result (converted model, engine, direction, stats, warnings).
        report: the verification report, or ``None`` when verification was skipped.
        output_format: the format the result was serialised in.
        text: the result serialised in ``output_format``.
        output: where the result was written, or ``None`` (no path given, or not written).
        written: whether ``output`` holds the result.
        timings: seconds per step ("read", "convert", "verify", "load", "write").
        load: the load check of the written result (BehaviorTree.CPP for a BehaviorTree.CPP
            tree, python-statemachine for SCXML; ``None``: another format, no engine, or the
            check was skipped); a refused result never gets an ``Outcome``.
    """

    source: Loaded
    conversion: ConversionResult
    report: Report | None
    output_format: str
    text: str
    output: Path | None = None
    written: bool = False
    timings: dict[str, float] = field(default_factory=dict)
    load: LoadCheck | None = None

    @property
    def result(self) -> Model:
        """The converted model."""
        return self.conversion.model

    @property
    def equivalent(self) -> bool | None:
        """``True``/``False`` from the report; ``None`` when verification was skipped."""
        return None if self.report is None else self.report.equivalent

    @property
    def verdict(self) -> str:
        """``"EQUIVALENT"``, ``"NOT EQUIVALENT"`` or ``"NOT VERIFIED"``."""
        return verdict_word(self.report)

    @property
    def warnings(self) -> list[str]:
        """The reader's warnings, then the engine's."""
        return [*self.source.warnings, *self.conversion.warnings]

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (the models themselves are left out; ``text`` has the result).

        Returns:
            A dict with source, output, format, engine, direction, stats, warnings, verdict,
            equivalent, properties (name -> holds), timings and written.
        """
        return {
            "source": str(self.source.path) if self.source.path is not None else None,
            "source_format": self.source.format,
            "output": str(self.output) if self.output is not None else None,
            "written": self.written,
            "format": self.output_format,
            "engine": self.conversion.engine,
            "direction": self.conversion.direction,
            "stats": self.conversion.stats,
            "warnings": self.warnings,
            "verdict": self.verdict,
            "equivalent": self.equivalent,
            "properties": self.report.verdicts() if self.report is not None else None,
            "timings": {name: round(seconds, 6) for name, seconds in self.timings.items()},
            "loads": None
            if self.load is None
            else {"engine": self.load.engine, "loaded": self.load.loaded},
        }


def model_kind(model: Model) -> str:
    """``"fsm"`` for an FSM, ``"bt"`` for a behavior tree document."""
    return "fsm" if isinstance(model, FSM) else "bt"


def verdict_word(report: Report | None) -> str:
    """The verdict of ``report`` in the words every layer uses.

    Args:
        report: a verification report, or ``None`` when verification was skipped.

    Returns:
        ``EQUIVALENT``, ``NOT EQUIVALENT`` or ``NOT VERIFIED``.
    """
    if report is None:
        return NOT_VERIFIED
    return EQUIVALENT if report.equivalent else NOT_EQUIVALENT


class DestinationExists(InputError):
    """The output file exists and replacing it was not asked for (the CLI names ``--force``)."""

    def __init__(self, location: SourceLocation) -> None:
        super().__init__("exists", location=location, hints=(Hint.OVERWRITE,))


# -- read -------------------------------------------------------------------------------------


def load(
    path: str | Path,
    fmt: str | None = None,
    *,
    options: dict[str, object] | ReadOptions | None = None,
) -> Loaded:
    """Read one model file.

    Args:
        path: the file.
        fmt: its format's name; detected from the content, then the extension, when ``None``.
        options: reader options: for BehaviorTree.CPP files ``node_models`` (TreeNodesModel
            files), ``nodes`` (node profiles ``nav2``/``moveit_pro`` and YAML/JSON node files)
            and ``abstract`` (``time``, ``blackboard``); docs/semantics.md §10; ``trees``
            (files or folders whose trees SubTrees may name) and ``include_root`` (the folder
            ``<include>`` s may resolve in); docs/formats/btcpp.md.

    Returns:
        The ``Loaded`` model with the reader's warnings.

    Raises:
        InputError: the file cannot be read or is not a valid model (located).
        UnsupportedError: the model uses something fsmbt cannot model exactly (located).
    """
    if isinstance(options, ReadOptions):
        fmt = fmt or options.format
        options = options.reader_options()
    path = Path(path)
    text = read_text(path)
    chosen = get_format(fmt).name if fmt else detect_format(text, path).name
    warnings: list[str] = []
    model = loads(text, chosen, path=path, options=options, warnings=warnings)
    return Loaded(model, path, chosen, warnings)


def load_text(
    text: str,
    fmt: str | None = None,
    *,
    filename: str | None = None,
    options: dict[str, object] | ReadOptions | None = None,
) -> Loaded:
    """Read one model from a text (a paste, an upload, an LLM answer).

    Args:
        text: the model's text.
        fmt: its format's name; detected from the content (then ``filename``'s extension).
        filename: a name used for format detection and in error locations only; it is never
            opened, so relative includes are refused rather than read from the server's disk.
        options: reader options.

    Returns:
        The ``Loaded`` model (``path`` is ``None``).

    Raises:
        InputError, UnsupportedError: as for ``load``.
    """
    if isinstance(options, ReadOptions):
        fmt = fmt or options.format
        options = options.reader_options()
    name = Path(Path(filename).name) if filename else None
    warnings: list[str] = []
    chosen = fmt or detect_format(text, name).name
    model = loads(text, chosen, options=options, warnings=warnings)
    return Loaded(model, None, chosen, warnings)


def load_for_llm(source: str | Path, request: ConvertRequest) -> tuple[Loaded, object | None]:
    """Read the source of an LLM engine's conversion, through LLM extraction where needed.

    The LLM engines (``llm``, ``nllm``, ``hybrid``) read prose, unknown notations and pictures
    by asking the model to extract them (``hybrid`` asks only when no parser reads the file).

    Args:
        source: the source file.
        request: the conversion (its engine, ``read.format``, ``engine_options`` with the
            endpoint, and an ``llm_client`` when the caller made one).

    Returns:
        The ``Loaded`` source and the client used (``None`` when none was needed); the caller
        passes the client on explicitly (``request.llm_client``).

    Raises:
        InputError, UnsupportedError: unreadable input; ``LLMConfigError`` when an LLM engine
        has no endpoint configured.
    """
    from fsmbt.llm.engine import client_from_options
    from fsmbt.llm.extract import needs_llm, read_input

    path = Path(source)
    fmt = request.read.format
    client = request.llm_client
    if client is None and (request.engine != "hybrid" or needs_llm(path, fmt)):
        client = client_from_options(dict(request.engine_options))
    regenerations = request.engine_options.get("max_regenerations")
    loaded = read_input(
        path,
        fmt,
        client=client,
        max_regenerations=regenerations if isinstance(regenerations, int) else None,
    )
    return Loaded(loaded.model, path, loaded.format, loaded.warnings, loaded.extracted), client


# -- convert and verify ----------------------------------------------------------------------


def convert_model(
    model: Model,
    engine: str = "rules",
    *,
    style: str = "auto",
    loop: bool = False,
    hierarchy: str | None = None,
    **options: object,
) -> ConversionResult:
    """Convert an FSM into a BT, or a BT into a hierarchical FSM.

    Args:
        model: the source model; its kind decides the direction.
        engine: the engine's name (``rules``, ``bsd``, ``chds``, ``llm``, ...).
        style: the output structure style: ``auto`` (default: ``structured`` for an
            outcome-driven machine, else ``dispatch``), ``structured``, ``dispatch``, ``lebt``
            (``paper``).
        loop: BT -> FSM: the root is ticked again after it returns.
        hierarchy: FSM -> BT with ``rules``: ``subtrees`` (one SubTree per composite state) or
            ``flatten``; ``None`` leaves the engine's default.
        **options: further engine options.

    Returns:
        The engine's ``ConversionResult``.

    Raises:
        InputError: an unknown engine or an invalid model; UnsupportedError: the engine cannot
        convert this model (the reason is named).
    """
    if loop:
        options["loop"] = True
    if hierarchy is not None and engine == "rules" and isinstance(model, FSM):
        options["hierarchy"] = hierarchy
    return convert(model, engine=engine, style=style, **options)


def lebt_port_issues(model: Model) -> list[Issue]:
    """The LEBT leaves whose redundant ports (a guard's ``target``, a state's ``exits``)
    contradict the tree's structure (``fsmbt.semantics.lebt.ports``); none for an FSM.

    Args:
        model: any model.

    Returns:
        Error issues, each naming the leaf and its line.
    """
    if not isinstance(model, BTDocument):
        return []
    from fsmbt.semantics.lebt.ports import lebt_port_issues as issues

    return issues(model)


def _warn_lebt_ports(loaded: Loaded) -> None:
    """Add each LEBT port contradiction to ``loaded.warnings`` once (the checkers read the
    structure, so the verdict stands; the file still says something false)."""
    for issue in lebt_port_issues(loaded.model):
        text = str(issue).replace(": error: ", ": ", 1)
        if text not in loaded.warnings:
            loaded.warnings.append(text)


def verify_models(
    source: Model,
    result: Model,
    engine: str = "native",
    *,
    loop: bool = False,
    max_states: int | None = None,
    outcomes: str | None = None,
    outcome_driven: bool = False,
) -> Report:
    """Check that ``result`` behaves exactly like ``source`` (the five properties).

    Args:
        source: the source model.
        result: the converted model.
        engine: ``native``, ``nusmv`` or ``both`` (both must agree).
        loop: the BT side's root is ticked again after it returns.
        max_states: the native checker's state limit (``None``: ``fsmbt.limits.current()``'s
            ``checker_max_states``).
        outcomes: an FSM and its structured tree: the outcome rules (``"arrived=success"``,
            docs/semantics.md §11); ``None``: the default names.
        outcome_driven: the FSM's events are outcomes (a SMACH/FlexBE/YASMIN source).

    Returns:
        The ``Report``: verdict, five properties, shortest counterexamples.

    Raises:
        EngineDisagreement: ``both`` and the engines disagree (a bug in one of them).
        InputError, UnsupportedError: the pair cannot be compared.
    """
    report = verify(
        source,
        result,
        engine=engine,
        loop=loop,
        max_states=checker_limit(max_states),
        outcomes=OutcomeRules.from_option(outcomes),
        outcome_driven=outcome_driven,
    )
    _name_abstractions(report, source, result)
    _name_data_model(report, source, result)
    return readable(report, source, result)


def _name_data_model(report: Report, *models: Model) -> None:
    """Record in ``report.stats["data_model"]`` what was checked for a machine that keeps data
    (``fsmbt.model.fsm_data``): its exact flat meaning, the W3C expansion of its SCXML
    (docs/semantics.md, "Data in state machines")."""
    from fsmbt.model.fsm_data import DATAMODEL, has_data, parse_lines

    for model in models:
        if isinstance(model, FSM) and has_data(model):
            names = [name for name, _expr in parse_lines(model.attrs[DATAMODEL])]
            states = sum(1 for _ in model.walk())
            report.stats["data_model"] = (
                f"the state machine '{model.name}' keeps {len(names)} variable(s) in guards and "
                f"assignments; its {states} states were checked through their exact flat "
                "meaning: the machine written as SCXML and expanded by the W3C algorithm "
                "(every reachable configuration and valuation of the variables)"
            )


def _name_abstractions(report: Report, *models: Model) -> None:
    """Record in ``report.stats["abstractions"]`` every abstraction the BT side was modelled
    under (docs/semantics.md §10): the verdict holds under them, and says so."""
    from fsmbt.semantics.nodes import abstractions_used

    found: dict[str, None] = dict.fromkeys(report.stats.get("abstractions", []))
    for model in models:
        for sentence in abstractions_used(model):
            found.setdefault(sentence, None)
    if found:
        report.stats["abstractions"] = list(found)


def verify_either_order(
    first: Model,
    second: Model,
    engine: str = "native",
    *,
    loop: bool = False,
    max_states: int | None = None,
    outcome_driven: bool = False,
) -> Report:
    """Like ``verify_models``, for two models given in either order.

    The pair is put in the order its pairing rule needs (``fsmbt.verify.orient``): an FSM and
    its loop-execution BT by macro steps with the FSM as the source, a BT and its FSM by leaf
    execution with the BT as the source. The verdict is the same for both orders; the report
    names the rule in ``stats["pairing"]`` and, when the order was reversed, says so in
    ``stats["swapped"]``.

    Raises:
        InputError: the pair cannot be compared by its rule; the message names the rule that
        was tried and every rule there is.
        EngineDisagreement: ``both`` and the engines disagree.
    """
    oriented = orient(first, second, outcome_driven=outcome_driven)
    try:
        report = verify_models(
            oriented.source,
            oriented.result,
            engine,
            loop=loop,
            max_states=max_states,
            outcome_driven=oriented.rule == OUTCOME_RULE,
        )
    except (UnsupportedError, StateLimitError):
        raise  # a construct, or a size or time limit: not a pairing problem
    except InputError as exc:
        if Hint.MAX_STATES in exc.hints:  # the explorers' own state limits
            raise
        raise InputError(
            f"{exc.message} (pairing rule tried: {oriented.rule}; the rules are: {rules_text()})",
            location=exc.location,
            element=exc.element,
            hints=exc.hints,
        ) from None
    report.stats["pairing"] = oriented.rule
    report.stats["swapped"] = oriented.swapped
    return report


# -- write -----------------------------------------------------------------------------------


def check_destination(path: str | Path, *, overwrite: bool = False) -> Path:
    """Refuse a destination that cannot take a result, before any work is done.

    Args:
        path: the file to be written.
        overwrite: an existing file may be replaced.

    Returns:
        The path.

    Raises:
        InputError: the path is a folder, exists (without ``overwrite``), or its folder is a
        file; the error names the path and says how to proceed.
    """
    path = Path(path)
    where = SourceLocation(str(path))
    if path.is_dir():
        raise InputError("is a folder; name a file to write the result to", location=where)
    if path.exists() and not overwrite:
        raise DestinationExists(where)
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise InputError(
                    f"cannot write here: '{parent}' is a file, not a folder", location=where
                )
            if not os.access(parent, os.W_OK):
                raise InputError(
                    f"cannot write here: no permission to write in '{parent}'", location=where
                )
            break
    return path


def output_format_for(kind: str, *, to: str | None = None, output: Path | None = None) -> str:
    """The format a result of ``kind`` is written in.

    Args:
        kind: ``"fsm"`` or ``"bt"``.
        to: an explicit format name.
        output: the output file, whose extension may name the format.

    Returns:
        ``to`` when given, else the format of ``output``'s extension, else ``scxml`` for an
        FSM and ``btcpp`` for a BT.
    """
    if to is not None:
        return get_format(to).name
    if output is not None:
        guessed = format_for_path(output, writing=True, kind=kind)
        if guessed is not None:
            return guessed.name
    return DEFAULT_FSM_FORMAT if kind == "fsm" else DEFAULT_BT_FORMAT


def write(
    model: Model, path: str | Path, fmt: str | None = None, *, overwrite: bool = False
) -> Path:
    """Write a model to a file, atomically.

    Args:
        model: the model.
        path: the file; its folder is created when missing.
        fmt: the format; from ``path``'s extension (then the kind's default) when ``None``.
        overwrite: an existing file may be replaced.

    Returns:
        The path written.

    Raises:
        InputError: the destination is refused (see ``check_destination``), the format cannot
        hold the model, or the file system refuses the write.
    """
    path = check_destination(path, overwrite=overwrite)
    if (
        fmt is None
        and path.suffix
        and format_for_path(path, writing=True, kind=model_kind(model)) is None
    ):
        # a name whose extension no writer has: say so rather than write another format into it
        raise InputError(
            f"cannot tell the output format from '{path.name}'",
            location=SourceLocation(str(path)),
            hints=(Hint.OUTPUT_FORMAT,),
        )
    chosen = output_format_for(model_kind(model), to=fmt, output=path)
    return write_text(dumps(model, chosen), path, overwrite=overwrite)


def _file_mode(path: Path) -> int:
    """The mode ``path`` keeps when replaced, else ``0o666`` less the umask."""
    try:
        return path.stat().st_mode & 0o7777
    except OSError:
        return 0o666 & ~_umask()


def _umask() -> int:
    """The process's umask, read without changing it where the system says it (Linux's
    ``/proc/self/status``: setting and restoring it races with other threads' file creation)."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(text: str, path: str | Path, *, overwrite: bool = False) -> Path:
    """Write a text atomically: a temporary file in the same folder, then a rename.

    A reader never sees half a file, and a crash mid-write leaves the old file (or none). The
    file gets the mode a plain ``open`` would give it: a replaced file keeps its own mode, a new
    one ``0o666`` less the process's umask (a temporary file is created ``0o600``; without this,
    results would be unreadable to the user's group although ``render`` and ``translate``
    outputs were not).

    Args:
        text: what to write (UTF-8).
        path: the destination.
        overwrite: an existing file may be replaced.

    Returns:
        The path written.

    Raises:
        InputError: the destination is refused or the file system refuses the write.
    """
    path = check_destination(path, overwrite=overwrite)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(
            prefix=f".{path.name}.", suffix=".tmp", dir=path.parent
        )
        try:
            with os.fdopen(handle, "w", encoding="utf-8", newline="") as stream:
                stream.write(text)
                stream.flush()
                os.fchmod(stream.fileno(), _file_mode(path))
                os.fsync(stream.fileno())
            if not overwrite and path.exists():  # appeared while we wrote: keep it
                raise DestinationExists(SourceLocation(str(path)))
            os.replace(temporary, path)
        finally:
            if os.path.exists(temporary):
                os.unlink(temporary)
    except OSError as exc:
        raise InputError(
            f"cannot write: {exc.strerror}", location=SourceLocation(str(path))
        ) from None
    return path


# -- the whole pipeline ----------------------------------------------------------------------


@contextmanager
def _timed(timings: dict[str, float], stage: str, on_stage: StageHook | None) -> Iterator[None]:
    if on_stage is not None:
        on_stage(stage)
    started = time.perf_counter()
    try:
        yield
    finally:
        timings[stage] = time.perf_counter() - started


def conversion_blockers(model: Model) -> list[Blocker]:
    """Everything conversion would refuse in ``model``, all at once (``validate``, ``info``,
    ``render`` and ``convert`` report the same list).

    Args:
        model: a model; only BT documents have blockers here (an FSM reader refuses at read
            time).

    Returns:
        The ``Blocker`` s (message, location, element), in tree order.
    """
    if not isinstance(model, BTDocument):
        return []
    return blockers_of(model)


def _refuse_blockers(model: Model) -> None:
    """Raise one ``UnsupportedError`` naming every blocker (located at the first)."""
    found = conversion_blockers(model)
    if not found:
        return
    first = found[0]
    message = first.message
    if len(found) > 1:
        rest = "; ".join(str(b) for b in found[1:])
        message = f"{message} (and {len(found) - 1} more blocker(s): {rest})"
    error = UnsupportedError if first.unsupported else InputError
    raise error(message, location=first.location, element=first.element)


def convert_file(
    source: str | Path,
    output: str | Path | None = None,
    request: ConvertRequest | None = None,
    *,
    on_stage: StageHook | None = None,
    **fields: Any,
) -> Outcome:
    """Read, convert, verify and write one model file.

    The destination is checked first, so a refused output costs no conversion. The result is
    written only after verification, and only when it is equivalent (or not verified), unless
    ``request.keep_not_equivalent``.

    Args:
        source: the source file.
        output: where to write the result; ``None`` keeps it in ``Outcome.text`` only.
        request: what to do (``fsmbt.api_types.ConvertRequest``: engine, style, output format,
            verification, reading); the defaults when ``None``.
        on_stage: told each step's name as it starts (for progress displays).
        **fields: ``ConvertRequest`` fields given one by one (``engine="bsd"``), applied over
            ``request``; validated the same way (an unknown name is an error).

    Returns:
        The ``Outcome``.

    Raises:
        InputError, UnsupportedError: bad input or a refused destination (located);
        EngineDisagreement: ``verify_engine="both"`` and the engines disagree;
        TreeLoadError: the result is a BehaviorTree.CPP tree the engine does not load (not
            written; located at the output and the engine's line).
    """
    request = convert_request(request, **fields)
    if output is not None:
        check_destination(output, overwrite=request.overwrite)
    timings: dict[str, float] = {}
    with _timed(timings, "read", on_stage):
        loaded, request = _load_source(source, request)
    outcome = convert_loaded(loaded, output, request, on_stage=on_stage)
    outcome.timings = {**timings, **outcome.timings}
    return outcome


def _load_source(source: str | Path, request: ConvertRequest) -> tuple[Loaded, ConvertRequest]:
    """Read the source of ``request``'s conversion; the LLM engines read through extraction
    and get the client they made passed on explicitly in the returned request."""
    if request.engine not in LLM_ENGINES:
        return load(source, request.read.format, options=request.read.reader_options()), request
    loaded, client = load_for_llm(source, request)
    return loaded, request.model_copy(update={"llm_client": client})


def convert_loaded(
    loaded: Loaded,
    output: str | Path | None = None,
    request: ConvertRequest | None = None,
    *,
    on_stage: StageHook | None = None,
    **fields: Any,
) -> Outcome:
    """Convert, verify and (optionally) write a model already read (a file, a text, an upload).

    The same steps and rules as ``convert_file`` after reading; a text from ``load_text`` goes
    through here, so the web page and the batch runner convert exactly as the CLI does.

    Args:
        loaded: the source, from ``load``, ``load_text`` or ``load_for_llm``.
        output, request, on_stage, fields: as for ``convert_file``.

    Returns:
        The ``Outcome`` (``timings`` without "read").

    Raises:
        As ``convert_file``.
    """
    request = convert_request(request, **fields)
    destination = Path(output) if output is not None else None
    if destination is not None:
        check_destination(destination, overwrite=request.overwrite)
    _warn_lebt_ports(loaded)
    timings: dict[str, float] = {}
    _refuse_blockers(loaded.model)
    with _timed(timings, "convert", on_stage):
        engine_options = dict(request.engine_options)
        if request.llm_client is not None:
            engine_options["client"] = request.llm_client
        if loaded.extracted_by_llm or request.engine in LLM_ENGINES:
            engine_options.setdefault("extracted_by_llm", loaded.extracted_by_llm)
            if loaded.path is not None:
                engine_options.setdefault("source_name", str(loaded.path))
        if request.max_states is not None:
            engine_options.setdefault("max_states", request.max_states)
        if request.engine == "rules" and loaded.format in OUTCOME_FORMATS:
            engine_options["outcome_driven"] = True  # the format's events are outcomes
        if request.outcomes:
            engine_options["outcomes"] = request.outcomes
        if request.engine == "rules" and request.verify and request.verify_engine != "native":
            engine_options[NUSMV_CHECKED] = True  # auto writes a form NuSMV encodes
        conversion = convert_model(
            loaded.model,
            request.engine,
            style=request.style,
            loop=request.loop,
            hierarchy=request.hierarchy,
            **engine_options,
        )
    fmt = output_format_for(model_kind(conversion.model), to=request.to, output=destination)
    # a format without a data model gets the proven machine's exact expansion, named
    written_model, data_loss = expand_data_for(conversion.model, fmt)
    if data_loss is not None:
        conversion.warnings.append(data_loss)
    text = dumps(written_model, fmt)
    report: Report | None = None
    # the load check runs beside the proof (semantics.engines.load_beside): they are independent
    pending: PendingLoad | None = None
    if request.load_check and _load_checked(fmt, conversion.model):
        pending = start_load_check(text, fmt)
    try:
        if request.verify:
            with _timed(timings, "verify", on_stage):
                structured = conversion.stats.get("style") == "structured"
                report = verify_models(
                    loaded.model,
                    conversion.model,
                    request.verify_engine,
                    loop=request.loop,
                    max_states=request.max_states,
                    outcomes=request.outcomes if structured else None,
                    outcome_driven=structured,
                )
    except BaseException:
        if pending is not None:
            pending.cancel()
        raise
    load: LoadCheck | None = None
    if pending is not None:
        with _timed(timings, "load", on_stage):  # the wait past the proof
            load = pending.result()  # None without the engine (python-statemachine)
    if load is not None:
        load.raise_if_refused(str(destination) if destination is not None else "<stdout>")
    outcome = Outcome(loaded, conversion, report, fmt, text, output=destination, load=load)
    if destination is not None and (
        report is None or report.equivalent or request.keep_not_equivalent
    ):
        with _timed(timings, "write", on_stage):
            write_text(text, destination, overwrite=request.overwrite)
        outcome.written = True
    outcome.timings = timings
    return outcome


def _load_checked(fmt: str, model: FSM | BTDocument) -> bool:
    """Whether a result written as ``fmt`` gets a load check (docs/semantics.md §5): a
    behavior tree written for BehaviorTree.CPP, a state machine written as SCXML."""
    if fmt == "btcpp":
        return isinstance(model, BTDocument)
    return fmt == "scxml" and isinstance(model, FSM)


def verify_files(
    source: str | Path,
    converted: str | Path,
    request: VerifyRequest | None = None,
    *,
    converted_format: str | None = None,
    on_stage: StageHook | None = None,
    **fields: Any,
) -> tuple[Loaded, Loaded, Report]:
    """Read two model files and check that the second behaves exactly like the first.

    Args:
        source: the source model's file.
        converted: the converted model's file.
        request: the checker, loop mode, state limit and reader options
            (``fsmbt.api_types.VerifyRequest``; ``read.format`` is the first file's format).
        converted_format: the second file's format (default: detected).
        on_stage: told each step's name as it starts ("read", "verify").
        **fields: ``VerifyRequest`` fields given one by one, applied over ``request``.

    Returns:
        Both loaded models (as given) and the ``Report``; the pair is compared in the order
        its pairing rule needs, so the verdict does not depend on the argument order.

    Raises:
        InputError, UnsupportedError: unreadable models or a pair that cannot be compared;
        EngineDisagreement: ``both`` and the engines disagree.
    """
    request = verify_request(request, **fields)
    options = request.read.reader_options()
    timings: dict[str, float] = {}
    with _timed(timings, "read", on_stage):
        first = load(source, request.read.format, options=options)
        second = load(converted, converted_format, options=options)
        _warn_lebt_ports(first)
        _warn_lebt_ports(second)
    with _timed(timings, "verify", on_stage):
        outcome_driven = first.format in OUTCOME_FORMATS or second.format in OUTCOME_FORMATS
        report = verify_either_order(
            first.model,
            second.model,
            request.engine,
            loop=request.loop,
            max_states=request.max_states,
            outcome_driven=outcome_driven,
        )
    return first, second, report


def translate(
    source: str | Path,
    output: str | Path | None = None,
    *,
    to: str | None = None,
    read: ReadOptions | None = None,
    flatten: bool = False,
    overwrite: bool = False,
    verify_request: VerifyRequest | None = None,
) -> tuple[Loaded, Translation, Report | None]:
    """The same model in another format, every loss named, proven to mean the same.

    Read (``load``) -> write in the target format and read it back (``fsmbt.formats.translate``)
    -> prove the read-back equivalent to the source (``verify_models``; a loss that changes
    behaviour is an ``UnsupportedError`` and nothing is written) -> write atomically, after
    the destination was checked before any work.

    Args:
        source: the input file.
        output: where to write (``None``: only return the text).
        to: the target format (default: from ``output``'s extension and the model's kind).
        read: how the input is read (format, reader options).
        flatten: write a hierarchical FSM as its flat machine (named as a loss).
        overwrite: an existing ``output`` may be replaced.
        verify_request: the checker and its limits (default: native).

    Returns:
        The source as read, the ``Translation`` (text, losses, ``verified``) and the
        equivalence report (``None`` when the target cannot be read back).

    Raises:
        InputError, UnsupportedError: unreadable input, an unknown target, a refused
        destination, or a translation that changes the model's behaviour (located).
    """
    read = read or ReadOptions()
    destination = check_destination(output, overwrite=overwrite) if output is not None else None
    loaded = load(source, read.format, options=read)
    target = to
    if target is None and destination is not None:
        guessed = format_for_path(destination, writing=True, kind=loaded.kind)
        target = guessed.name if guessed is not None else None
    if target is None:
        where = f" (from '{destination.name}')" if destination is not None else ""
        raise InputError(f"cannot tell the target format; name it with --to{where}")
    result = translate_model(loaded.model, target, flatten=flatten, source_format=loaded.format)
    result.warnings = list(loaded.warnings)
    if loaded.format == target == "btcpp" and loaded.path is not None:
        # the user's own file, edited only where v4 needs it (comments, attribute order and
        # every untouched byte kept; byte for byte when nothing changes): docs/formats/btcpp.md
        from fsmbt.formats.btcpp.preserve import edited_source

        original = read_text(loaded.path)
        kept = edited_source(original, loaded.model, result.text)  # type: ignore[arg-type]
        if kept is not None:
            result.text = kept
    report: Report | None = None
    if result.read_back is not None and result.checked is not None:
        request = verify_request or VerifyRequest()
        report = verify_models(
            result.checked, result.read_back, request.engine, max_states=request.max_states
        )
        if not report.equivalent:
            failed = [name for name, prop in report.properties.items() if not prop.holds]
            details = "; ".join(f"{name}: {report.properties[name].detail}" for name in failed)
            raise UnsupportedError(
                f"translating to {result.target_format} changes the model's behaviour "
                f"({details}); nothing written"
            )
        result.verified = True
    if destination is not None:
        write_text(result.text, destination, overwrite=overwrite)
    return loaded, result, report


__all__ = [
    "ConvertRequest",
    "ReadOptions",
    "VerifyRequest",
    "DEFAULT_BT_FORMAT",
    "DEFAULT_FSM_FORMAT",
    "EQUIVALENT",
    "LLM_ENGINES",
    "NOT_EQUIVALENT",
    "NOT_VERIFIED",
    "DestinationExists",
    "Loaded",
    "Model",
    "Outcome",
    "check_destination",
    "convert_file",
    "convert_loaded",
    "convert_model",
    "convert_request",
    "verify_request",
    "load",
    "load_for_llm",
    "load_text",
    "model_kind",
    "output_format_for",
    "verdict_word",
    "verify_either_order",
    "verify_files",
    "translate",
    "verify_models",
    "write",
    "write_text",
]
