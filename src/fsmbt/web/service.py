"""What each API call computes, as plain functions of plain data (run in a worker process).

Every function here takes JSON-ready arguments, calls the library (``fsmbt.api``,
``fsmbt.render``, ``fsmbt.metrics``, ``fsmbt.model.validate``) and returns a JSON-ready dict; none
redoes pipeline work. They run in the server's worker processes (``fsmbt.web.workers``), so a
slow conversion never blocks the server, and they raise only ``FsmbtError`` for bad input
(the routes turn it into ``{"error", "where"}``).

Rules: no argument is ever a file-system path (``filename`` is a name for format detection and
messages; ``fsmbt.api.load_text`` never opens it); runtime files are written into a fresh
temporary folder and returned as a zip's bytes, the folder removed afterwards.

Costs: those of reading, converting and verifying (``fsmbt.api``), plus one Graphviz layout per
picture (``fsmbt.render.svg_text``).
"""

from __future__ import annotations

import importlib.util
import io
import tempfile
import zipfile
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from fsmbt import api
from fsmbt.formats import dumps, formats, get_format
from fsmbt.formats.btcpp.v3_write import prepare_v3
from fsmbt.metrics.elements import elements
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError, Hint, InputError
from fsmbt.model.validate import validate
from fsmbt.render import svg_text, trace_anchors
from fsmbt.render.dot import TooLargeError
from fsmbt.verify.report import Report

#: The engines offered without an LLM endpoint.
PLAIN_ENGINES = ("rules", "bsd", "chds")
#: The options a request may set (nothing else reaches an engine: no endpoint, no key).
HIERARCHIES = ("subtrees", "flatten")
#: FSM -> BT styles (docs/conversion.md, "Styles"; ``paper`` is ``lebt``).
STYLES = ("auto", "structured", "dispatch", "lebt")
#: Download formats besides the registry's writers: pictures through Graphviz.
PICTURE_FORMATS = ("svg", "png")
#: The file name ending of each download format.
SUFFIXES = {
    "btcpp": ".xml",
    "btcpp3": ".v3.xml",
    "scxml": ".scxml",
    "json": ".json",
    "yaml": ".yaml",
    "mermaid": ".mmd",
    "dot": ".dot",
    "svg": ".svg",
    "png": ".png",
    "paper-xml": ".fsm.xml",
    "smach": ".py",
    "csv": ".csv",
    "md": ".md",
    "paper-text": ".txt",
}

#: The hints in the page's words (the form's controls), as the CLI words them as flags.
WEB_WORDING = {
    Hint.INPUT_FORMAT: "choose its format in the Format menu",
    Hint.OUTPUT_FORMAT: "choose another download format",
    Hint.OVERWRITE: "nothing is overwritten by the page",
    Hint.NATIVE_VERIFIER: "use the native verifier",
    Hint.RULES_ENGINE: "choose the rules engine",
    Hint.LLM_ENGINE: "choose an LLM engine (when the server has an endpoint)",
    Hint.MAX_NODES: "draw it with `fsmbt render --max-nodes` on the command line",
    Hint.STATISTICS: "use `fsmbt info` on the command line for its structure",
    Hint.NO_EXPANSION: "draw it with `fsmbt render` on the command line",
    Hint.LLM_BASE_URL: "the server's administrator sets FSMBT_LLM_BASE_URL",
    Hint.LLM_MODEL: "the server's administrator sets FSMBT_LLM_MODEL",
}


def error_body(error: FsmbtError) -> dict[str, Any]:
    """The JSON of a refused request: the CLI's one-line cause, hints in the page's words.

    Args:
        error: the library's error.

    Returns:
        ``{"error": one line, "where": {"file", "line", "column", "element"} or None}``.
    """
    loc = error.location
    where = None
    if loc is not None or error.element:
        where = {
            "file": loc.file if loc else None,
            "line": loc.line if loc else None,
            "column": loc.column if loc else None,
            "element": error.element,
        }
    return {"error": error.text(WEB_WORDING), "where": where}


def format_list() -> list[dict[str, Any]]:
    """Every format fsmbt reads or writes, plus the picture formats.

    Returns:
        ``[{"name", "description", "extensions", "kinds", "read", "write"}]``.
    """
    listed = [
        {
            "name": f.name,
            "description": f.description,
            "extensions": list(f.extensions),
            "kinds": sorted(f.kinds),
            "read": f.read is not None,
            "write": f.write is not None,
        }
        for f in formats()
    ]
    listed += [
        {
            "name": name,
            "description": f"{name.upper()} picture (Graphviz)",
            "extensions": [f".{name}"],
            "kinds": ["bt", "fsm"],
            "read": False,
            "write": True,
        }
        for name in PICTURE_FORMATS
    ]
    return listed


def download_formats(kind: str, model: api.Model | None = None) -> list[str]:
    """The formats a model of ``kind`` can be downloaded in (writers, then pictures); with
    ``model``, without BehaviorTree.CPP v3 when v3 cannot hold it (a ``Script`` or another
    v4-only node, a post-condition a ``Switch`` reads: the dispatch form, a structured tree with
    a dispatch; ``prepare_v3``)."""
    names = [f.name for f in formats() if f.write is not None and kind in f.kinds]
    if isinstance(model, BTDocument) and "btcpp3" in names:
        try:
            prepare_v3(model)
        except FsmbtError:
            names.remove("btcpp3")
    return names + list(PICTURE_FORMATS)


#: The runtimes offered for download and the modules that write their files.
RUNTIME_MODULES = (("cpp", "fsmbt.runtime.cpp"), ("python", "fsmbt.runtime.python_runtime"))


def runtime_kinds() -> list[str]:
    """The runtimes whose files can be downloaded, checked now (``fsmbt.runtime`` is optional:
    another part of the project provides it)."""
    found = []
    for kind, module in RUNTIME_MODULES:
        try:
            if importlib.util.find_spec(module) is not None:
                found.append(kind)
        except ImportError:
            continue
    return found


def _load(model: dict[str, Any]) -> api.Loaded:
    text = model.get("text")
    if not isinstance(text, str) or not text.strip():
        raise InputError("the model is empty: paste a model, upload a file or pick an example")
    fmt = model.get("format") or None
    filename = model.get("filename") or None
    try:
        if fmt is not None:
            fmt = get_format(str(fmt)).name
        return api.load_text(text, fmt, filename=filename)
    except FsmbtError as exc:
        # a text has no file; name the upload in the location, as the CLI names its file
        loc = exc.location
        if filename and loc is not None and loc.file in (None, "<input>"):
            exc.location = replace(loc, file=filename)
        raise


def _issues(loaded: api.Loaded) -> list[dict[str, object]]:
    return [issue.to_dict() for issue in validate(loaded.model)]


def _picture(model: api.Model) -> dict[str, Any]:
    """SVG with anchors (SubTrees expanded, so ids follow the interpreter's paths)."""
    try:
        return {"svg": svg_text(model, expand_subtrees=True), "error": None}
    except TooLargeError as exc:
        return {"svg": None, "error": exc.text(WEB_WORDING)}


def _metrics(model: api.Model) -> dict[str, Any]:
    return elements(model).to_dict()


def _steps(report: Report, source: api.Model, result: api.Model) -> dict[str, Any] | None:
    """The shortest counterexample among the failed properties, each step with the SVG ids
    of where each side is."""
    failed = [p for p in report.properties.values() if not p.holds and p.counterexample]
    if not failed:
        return None
    shortest = min(failed, key=lambda p: len(p.counterexample or []))
    steps = []
    for step in shortest.counterexample or []:
        data = asdict(step)
        data["source_anchors"] = trace_anchors(source, step.source_state)
        data["result_anchors"] = trace_anchors(result, step.result_state)
        steps.append(data)
    return {"property": shortest.name, "detail": shortest.detail, "steps": steps}


def _properties(report: Report) -> list[dict[str, Any]]:
    return [
        {"name": p.name, "holds": p.holds, "detail": p.detail} for p in report.properties.values()
    ]


def inspect(model: dict[str, Any]) -> dict[str, Any]:
    """Read and validate one model (the page calls it as the input changes).

    Args:
        model: ``{"text", "filename"?, "format"?}``.

    Returns:
        ``{"format", "kind", "issues": [...], "warnings": [...], "metrics"}``.

    Raises:
        FsmbtError: the text cannot be read (located).
    """
    loaded = _load(model)
    return {
        "format": loaded.format,
        "kind": loaded.kind,
        "issues": _issues(loaded),
        "warnings": loaded.warnings,
        "metrics": _metrics(loaded.model),
    }


def convert(request: dict[str, Any]) -> dict[str, Any]:
    """Convert one model, verify the result, draw both.

    Args:
        request: ``{"text", "filename"?, "format"?, "engine", "options": {"loop", "hierarchy", "style"},
            "to"?}``.

    Returns:
        ``{"verdict", "equivalent", "direction", "engine", "source": {"format", "kind"},
        "result": {"format", "kind", "text"}, "properties", "counterexample", "warnings",
        "issues", "metrics": {"source", "result"}, "svg": {"source", "result"},
        "svg_errors", "downloads", "runtimes", "timings"}``.

    Raises:
        FsmbtError: bad input or a conversion the engine refuses.
    """
    loaded = _load(request)
    options = request.get("options") or {}
    hierarchy = str(options.get("hierarchy") or "subtrees")
    if hierarchy not in HIERARCHIES:
        raise InputError(
            f"unknown hierarchy option '{hierarchy}' (one of: {', '.join(HIERARCHIES)})"
        )
    fields: dict[str, Any] = {
        "engine": str(request.get("engine") or "rules"),
        "to": request.get("to") or None,
        "loop": bool(options.get("loop", False)),
        "hierarchy": hierarchy,
        "style": str(options.get("style") or "auto"),
    }
    outcome = api.convert_loaded(loaded, None, api.convert_request(**fields))
    report = outcome.report
    pictures = {"source": _picture(loaded.model), "result": _picture(outcome.result)}
    kind = api.model_kind(outcome.result)
    style = outcome.conversion.stats.get("style")
    return {
        "verdict": outcome.verdict,
        "equivalent": outcome.equivalent,
        "direction": outcome.conversion.direction,
        "engine": outcome.conversion.engine,
        "source": {"format": loaded.format, "kind": loaded.kind},
        "result": {"format": outcome.output_format, "kind": kind, "text": outcome.text},
        "properties": _properties(report) if report is not None else [],
        "mode": report.mode if report is not None else None,
        "counterexample": _steps(report, loaded.model, outcome.result) if report else None,
        "warnings": outcome.warnings,
        "style": style,
        "summary": outcome.conversion.stats.get("summary"),
        "issues": _issues(loaded),
        "metrics": {"source": _metrics(loaded.model), "result": _metrics(outcome.result)},
        "svg": {"source": pictures["source"]["svg"], "result": pictures["result"]["svg"]},
        "svg_errors": {
            "source": pictures["source"]["error"],
            "result": pictures["result"]["error"],
        },
        "downloads": download_formats(kind, outcome.result),
        # the runtimes run LEBTs (docs/runtime.md); a dispatch tree needs only DispatchEntry
        "runtimes": runtime_kinds() if kind == "bt" and style != "dispatch" else [],
        "timings": {k: round(v, 6) for k, v in outcome.timings.items()},
        # the load check (docs/semantics.md §5): "loads in BehaviorTree.CPP 4.8.2: yes"
        "loads": outcome.load.summary() if outcome.load is not None else None,
    }


def verify(request: dict[str, Any]) -> dict[str, Any]:
    """Check two models against each other (in either order).

    Args:
        request: ``{"first": {"text", "filename"?, "format"?}, "second": {...},
            "options": {"loop"}}``.

    Returns:
        ``{"verdict", "equivalent", "mode", "pairing", "swapped", "properties",
        "counterexample", "source_side", "metrics", "svg", "svg_errors", "warnings"}``;
        ``source_side`` says which of the two the report calls the source (``first`` or
        ``second``), so the stepper puts each trace state on the right picture.

    Raises:
        FsmbtError: unreadable models or a pair no pairing rule compares.
    """
    first_spec, second_spec = request.get("first"), request.get("second")
    if not isinstance(first_spec, dict) or not isinstance(second_spec, dict):
        raise InputError("verify needs two models: 'first' and 'second'")
    first, second = _load(first_spec), _load(second_spec)
    loop = bool((request.get("options") or {}).get("loop", False))
    report = api.verify_either_order(first.model, second.model, loop=loop)
    swapped = bool(report.stats.get("swapped"))
    source, result = (second, first) if swapped else (first, second)
    pictures = {"first": _picture(first.model), "second": _picture(second.model)}
    return {
        "verdict": api.verdict_word(report),
        "equivalent": report.equivalent,
        "mode": report.mode,
        "pairing": report.stats.get("pairing"),
        "swapped": swapped,
        "source_side": "second" if swapped else "first",
        "properties": _properties(report),
        "counterexample": _steps(report, source.model, result.model),
        "formats": {"first": first.format, "second": second.format},
        "metrics": {"first": _metrics(first.model), "second": _metrics(second.model)},
        "svg": {"first": pictures["first"]["svg"], "second": pictures["second"]["svg"]},
        "svg_errors": {"first": pictures["first"]["error"], "second": pictures["second"]["error"]},
        "warnings": [*first.warnings, *second.warnings],
    }


def picture(request: dict[str, Any]) -> dict[str, Any]:
    """One model's picture with a fold opened: the page's click on a ``[k nodes]`` box of a
    behavior tree (``focus``: that node's path from the main root, SubTrees expanded, as the
    box's ``fold@`` id names it) or on a closed composite state's box (``composite``: its
    path ``A/B``); without either, the picture the convert and verify answers show. The
    subtree is drawn by ``fsmbt render``'s rules (docs/cli.md 'Pictures at any size'): a big
    one is folded again, each fold openable in turn, and anchors keep their full paths, so a
    counterexample step still finds its element.

    Args:
        request: ``{"text", "filename"?, "format"?, "focus"?, "composite"?}``.

    Returns:
        ``{"kind", "focus", "composite", "svg", "error"}`` (``error``: the picture is over
        the drawing limit; then ``svg`` is ``None``).

    Raises:
        FsmbtError: unreadable model, ``focus`` on an FSM or ``composite`` on a BT, or a path
        naming no node / composite state.
    """
    loaded = _load(request)
    focus = request.get("focus") or None
    composite = request.get("composite") or None
    if focus is not None and composite is not None:
        raise InputError("open one fold at a time: focus (a BT node) or composite (an FSM state)")
    is_bt = isinstance(loaded.model, BTDocument)
    if focus is not None and not is_bt:
        raise InputError("focus opens a fold of a behavior tree; this is an FSM (use composite)")
    if composite is not None and is_bt:
        raise InputError(
            "composite opens a composite state of an FSM; this is a behavior tree (use focus)"
        )
    try:
        svg = svg_text(
            loaded.model,
            expand_subtrees=True,
            focus=None if focus is None else str(focus),
            composite=None if composite is None else str(composite),
        )
        error = None
    except TooLargeError as exc:
        svg, error = None, exc.text(WEB_WORDING)
    return {
        "kind": loaded.kind,
        "focus": focus,
        "composite": composite,
        "svg": svg,
        "error": error,
    }


def export(request: dict[str, Any]) -> tuple[bytes, str, str]:
    """A model (typically a conversion's result) in another format, for download.

    Args:
        request: ``{"text", "format"?, "filename"?, "to", "name"?}``.

    Returns:
        ``(bytes, file name, media type)``.

    Raises:
        FsmbtError: unreadable model, unknown format, or one that cannot hold the model.
    """
    loaded = _load(request)
    to = str(request.get("to") or "")
    stem = _safe_stem(str(request.get("name") or "result"))
    if to in PICTURE_FORMATS:
        svg = svg_text(loaded.model, expand_subtrees=False, anchors=False)
        if to == "svg":
            return svg.encode("utf-8"), f"{stem}.svg", "image/svg+xml"
        from fsmbt.render import picture_bytes

        data = picture_bytes(loaded.model, "png")
        return data, f"{stem}.png", "image/png"
    fmt = get_format(to)
    text = dumps(loaded.model, fmt.name)
    return text.encode("utf-8"), f"{stem}{SUFFIXES.get(fmt.name, '.txt')}", "text/plain"


def runtime_zip(kind: str) -> tuple[bytes, str]:
    """The runtime files of ``kind`` (``cpp`` or ``python``) as a zip.

    Returns:
        ``(zip bytes, file name)``.

    Raises:
        InputError: the runtime is not available in this installation.
    """
    if kind not in runtime_kinds():
        raise InputError(f"the {kind} runtime is not available in this installation")
    # Imported by name: fsmbt.runtime is an optional sibling layer, looked up at request time.
    module = importlib.import_module(dict(RUNTIME_MODULES)[kind])
    write_files = module.write_files
    buffer = io.BytesIO()
    with tempfile.TemporaryDirectory(prefix="fsmbt-web-") as folder:
        written = write_files(Path(folder), overwrite=False)
        with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
            for path in written:
                archive.write(path, Path(path).relative_to(folder).as_posix())
    return buffer.getvalue(), f"fsmbt-runtime-{kind}.zip"


def _safe_stem(name: str) -> str:
    """A download name with no folder part and only plain characters."""
    base = name.replace("\\", "/").rsplit("/", 1)[-1].split(".")[0]
    cleaned = "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in base)[:64]
    return cleaned or "result"
