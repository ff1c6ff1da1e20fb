"""Running Graphviz: DOT source in, an SVG/PNG/PDF file out, never hanging, never clobbering.

The ``graphviz`` package builds the DOT source; the picture comes from Debian's ``dot`` binary,
called here with a wall-clock timeout (the package's own ``pipe`` has none). Label text from a
model goes through ``label_text`` so a name never changes the DOT's meaning.
"""

from __future__ import annotations

import html
import re
import shutil
import subprocess
from pathlib import Path

import graphviz
from graphviz import quoting

from fsmbt.model.errors import FsmbtError, Hint, InputError, SourceLocation

#: Pictures of more nodes than this are refused: dot's layout time grows quickly and nobody
#: reads such a picture. Callers raise it with ``max_nodes``.
DEFAULT_MAX_NODES = 5_000
#: Seconds dot may run before it is stopped.
DOT_TIMEOUT_S = 120.0
#: Output formats by file suffix; ``.dot`` writes the source without running Graphviz.
OUTPUT_FORMATS = {".svg": "svg", ".png": "png", ".pdf": "pdf", ".dot": "dot", ".gv": "dot"}
FONT = "DejaVu Sans"
#: A picture's long side is at most this many times its short side (issue 29).
MAX_ASPECT = 4.0


class GraphvizError(FsmbtError):
    """Graphviz is missing, failed or ran out of time."""


class TooLargeError(InputError):
    """The model has more nodes than a readable picture holds."""


def label_text(*lines: str) -> str:
    """Lines of model text as one DOT label: backslashes kept literal, lines centred, never
    mistaken for an HTML label (a name like ``<x>`` would be one)."""
    cleaned = [line.replace("\\", "\\\\").replace("\r", "").replace("\n", "\\n") for line in lines]
    return graphviz.nohtml("\\n".join(cleaned))


def html_label(head: list[str], details: list[str], *, head_size: int | None = None) -> str:
    """An HTML-like label: ``head`` lines (the first at ``head_size`` points, bold when set),
    then ``details`` in small grey type. Model text is escaped."""
    parts: list[str] = []
    for index, line in enumerate(head):
        text = _html_escape(line)
        if index == 0 and head_size is not None:
            text = f'<FONT POINT-SIZE="{head_size}"><B>{text}</B></FONT>'
        parts.append(text)
    parts.extend(f'<FONT POINT-SIZE="9" COLOR="gray30">{_html_escape(d)}</FONT>' for d in details)
    return "<" + "<BR/>".join(parts or [" "]) + ">"


def _html_escape(text: str) -> str:
    return html.escape(" ".join(text.split()), quote=True) or " "


def check_size(count: int, max_nodes: int, what: str) -> None:
    if count > max_nodes:
        raise TooLargeError(
            f"too large to draw: {count} {what} (limit {max_nodes}); "
            "a picture this big is unreadable and slow to lay out",
            hints=(Hint.MAX_NODES, Hint.STATISTICS),
        )


def dot_id(text: str) -> str:
    """A model name as a DOT node id for the ``graphviz`` package: never read as an HTML id
    (``<b>``), and a trailing backslash (which would escape the closing quote) padded with a
    space."""
    trailing = len(text) - len(text.rstrip("\\"))
    return graphviz.nohtml(text + " " if trailing % 2 else text)


def edge_line(tail: str, head: str, attrs: dict[str, str]) -> str:
    """One edge statement. ``graphviz.Digraph.edge`` reads ``a:b`` as node ``a``, port ``b``;
    model names may hold colons, so ends are quoted as plain ids here."""
    rest = dict(attrs)
    listed = quoting.attr_list(rest.pop("label", None), kwargs=rest)  # as Digraph.edge lists them
    return f"\t{quoting.quote(tail)} -> {quoting.quote(head)}{listed}\n"


def assemble(
    root: graphviz.Digraph,
    clusters: list[tuple[graphviz.Digraph, graphviz.Digraph]],
    edges: list[str],
) -> str:
    """The DOT source of ``root`` with ``clusters`` nested inside it and ``edges`` after them.

    ``clusters`` lists ``(cluster, parent)`` in pre-order. The source is written out in one
    pre-order walk with an explicit stack (``graphviz.Digraph.subgraph`` copies a cluster's text
    into its parent, quadratic in the nesting depth), each cluster's own statements first, then
    its sub-clusters, then its closing brace. O(total lines).
    """
    children: dict[int, list[graphviz.Digraph]] = {}
    for cluster, parent in clusters:
        children.setdefault(id(parent), []).append(cluster)
    out: list[str] = []
    stack: list[tuple[graphviz.Digraph, str, bool]] = [(root, "", False)]
    while stack:
        graph, pad, closing = stack.pop()
        if closing:
            if graph is root:
                out.extend(edges)
            out.append(f"{pad}}}\n")
            continue
        lines = list(graph.__iter__(subgraph=graph is not root))
        out.extend(f"{pad}{line}" if pad else line for line in lines[:-1])  # all but its "}"
        stack.append((graph, pad, True))
        stack.extend((child, pad + "\t", False) for child in reversed(children.get(id(graph), [])))
    return "".join(out)


def output_format(path: Path) -> str:
    suffix = path.suffix.lower()
    try:
        return OUTPUT_FORMATS[suffix]
    except KeyError:
        known = ", ".join(OUTPUT_FORMATS)
        raise InputError(
            f"cannot draw into '{path.name}': use one of {known}",
            location=SourceLocation(str(path)),
        ) from None


def check_output(path: Path, *, overwrite: bool) -> str:
    """The picture format ``path`` asks for; refuses an existing file unless ``overwrite``."""
    fmt = output_format(path)
    if path.exists() and not overwrite:
        raise InputError("exists", location=SourceLocation(str(path)), hints=(Hint.OVERWRITE,))
    return fmt


def dot_binary() -> str:
    found = shutil.which("dot")
    if found is None:
        raise GraphvizError(
            "Graphviz's `dot` is not installed (Debian: apt-get install graphviz; "
            "or run ./scripts/setup.sh)"
        )
    return found


def run_dot(source: str, fmt: str, *, timeout: float = DOT_TIMEOUT_S) -> bytes:
    """The picture bytes of ``source`` in ``fmt`` (svg, png, pdf)."""
    try:
        done = subprocess.run(
            [dot_binary(), f"-T{fmt}"],
            input=source.encode("utf-8"),
            capture_output=True,
            timeout=timeout,
            check=False,
        )
    except subprocess.TimeoutExpired:
        raise GraphvizError(f"Graphviz did not finish within {timeout:g} s") from None
    if done.returncode != 0:
        message = done.stderr.decode("utf-8", "replace").strip().splitlines()
        raise GraphvizError(f"Graphviz failed: {message[-1] if message else done.returncode}")
    return done.stdout


def layout_extent(source: str, *, timeout: float = DOT_TIMEOUT_S) -> tuple[float, float, float]:
    """(scale, width, height) of Graphviz's layout of ``source``: the first line of
    ``dot -Tplain`` (width and height in inches before a ``size`` cap scales them by scale)."""
    first = run_dot(source, "plain", timeout=timeout).split(b"\n", 1)[0].split()
    if len(first) < 4 or first[0] != b"graph":
        raise GraphvizError("Graphviz gave no layout size")
    return float(first[1]), float(first[2]), float(first[3])


def picture_size(data: bytes, fmt: str) -> tuple[float, float] | None:
    """(width, height) of a PNG (pixels, from its IHDR header) or an SVG (points, from the
    root element's attributes); ``None`` for other formats or an unreadable header."""
    if fmt == "png" and data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) >= 24:
        return float(int.from_bytes(data[16:20], "big")), float(int.from_bytes(data[20:24], "big"))
    if fmt == "svg":
        head = data[: data.find(b">", data.find(b"<svg")) + 1].decode("utf-8", "replace")
        found = re.search(r'width="([\d.]+)(?:pt|px)?"\s+height="([\d.]+)(?:pt|px)?"', head)
        if found:
            return float(found.group(1)), float(found.group(2))
    return None


def fit_aspect(
    source: str,
    fmt: str,
    data: bytes,
    *,
    max_aspect: float = MAX_ASPECT,
    timeout: float = DOT_TIMEOUT_S,
) -> bytes:
    """``data`` (the picture of ``source`` in ``fmt``), or, when its long side is more than
    ``max_aspect`` times its short side, the picture laid out again with Graphviz's ``ratio``
    set to just within ``max_aspect``: dot then spreads the layout along the short side (more
    space between ranks or nodes; node and label sizes unchanged), and a ``size`` cap in the
    source still applies. Costs a second layout, only for such pictures."""
    patched = aspect_source(source, fmt, data, max_aspect=max_aspect)
    return data if patched == source else run_dot(patched, fmt, timeout=timeout)


def aspect_source(source: str, fmt: str, data: bytes, *, max_aspect: float = MAX_ASPECT) -> str:
    """The source ``fit_aspect`` draws for ``data`` (the picture of ``source`` in ``fmt``):
    ``source`` itself, or with Graphviz's ``ratio`` set when the picture is too elongated."""
    size = picture_size(data, fmt)
    if size is None or min(size) <= 0:
        return source
    width, height = size
    if max(width, height) <= max_aspect * min(width, height):
        return source
    ratio = 0.98 * max_aspect if height > width else 1.02 / max_aspect  # height / width
    brace = source.find("{")
    if brace < 0:
        return source
    return f"{source[: brace + 1]}\n\tratio={ratio:.3f}{source[brace + 1 :]}"


def write_picture(
    source: str,
    path: str | Path,
    *,
    overwrite: bool = False,
    timeout: float = DOT_TIMEOUT_S,
    max_aspect: float | None = None,
) -> Path:
    """Write ``source`` as the picture ``path`` names (by suffix); refuse to replace a file.
    With ``max_aspect``, a PNG or SVG more elongated than that is laid out again
    (``fit_aspect``)."""
    path = Path(path)
    fmt = check_output(path, overwrite=overwrite)
    data = source.encode("utf-8") if fmt == "dot" else run_dot(source, fmt, timeout=timeout)
    if max_aspect is not None and fmt in ("png", "svg"):
        data = fit_aspect(source, fmt, data, max_aspect=max_aspect, timeout=timeout)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    except OSError as exc:
        raise InputError(
            f"cannot write: {exc.strerror}", location=SourceLocation(str(path))
        ) from None
    return path
