"""XInclude in SCXML: ``<xi:include href="part.scxml"/>`` replaced by the fragment it names,
before either SCXML reader sees the document (docs/formats/scxml.md, "XInclude and <invoke>").

Rules (docs/security.md, rule 4 - the same confinement as BehaviorTree.CPP includes):

- ``href`` is resolved relative to the file that holds the ``<xi:include>`` (symlinks
  followed) and must stay inside the folder of the file the user gave (or the reader option
  ``include_root``); it must be a regular file, is read within ``limits.max_input_bytes``
  (each file on its own) and parsed by ``xml_safe.parse_xml`` (no entities, no DTD, no
  network). Text with no file (``api.load(text)``) cannot include: an ``InputError``.
- Chains of includes are at most ``limits.max_include_depth`` files deep; a file that
  includes itself, directly or not, is an ``InputError`` naming the chain.
- ``parse="xml"`` (the default) only: ``parse="text"`` would put the file in as character
  data, which holds no state (``UnsupportedError``); ``xpointer`` and ``href`` with a scheme
  or a fragment are unsupported as well. A missing or unreadable file is replaced by the
  content of ``<xi:fallback>`` when the include has one (XInclude 1.0, 4.4), else an
  ``InputError``; a refused path never falls back.
- The document and all its inclusions together (a file included twice counts twice) stay
  within ``limits.max_input_bytes``: repeated inclusion cannot blow the document up.
- The fragment's root element takes the place of the ``<xi:include>``. Elements of the
  fragment in no namespace are taken into the including element's namespace (SCXML
  fragments are usually written without ``xmlns``; XInclude would leave them in no namespace,
  where an SCXML reader ignores them) - warned once per included file.
- References inside an included fragment (``<invoke src>``) resolve against the fragment's
  file (XInclude's base-URI fix-up, kept in ``Included.bases`` rather than as ``xml:base``
  attributes, which the readers would keep as state attributes).
- Elements that came from an included file carry the line of the ``<xi:include>`` that
  brought them in (error messages name the including file; a warning names the included
  file, and ``describe`` says which file a line's content came from).

Costs: O(total elements of all files); everything is iterative (explicit stacks).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from fsmbt import limits
from fsmbt.formats.registry import ReadContext, decode
from fsmbt.formats.xml_safe import local_name, namespace, parse_xml
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.model.files import note_read, read_located

XINCLUDE_NS = "http://www.w3.org/2001/XInclude"
_INCLUDE = f"{{{XINCLUDE_NS}}}include"
_FALLBACK = f"{{{XINCLUDE_NS}}}fallback"


@dataclass
class Included:
    """What the expansion did: which line of the main file brought in which file."""

    files: dict[int, str] = field(default_factory=dict)  # include line -> included file
    size: int = 0  # characters of the document and of every inclusion (each one counted)
    #: the root element of each included fragment -> its file (XInclude's base URI fix-up:
    #: references inside, e.g. ``<invoke src>``, resolve against that file)
    bases: dict[etree._Element, Path] = field(default_factory=dict)

    def base_of(self, element: etree._Element) -> Path | None:
        """The file ``element`` came from, when it came from an included file."""
        node: etree._Element | None = element
        while node is not None:
            if node in self.bases:
                return self.bases[node]
            node = node.getparent()
        return None

    def describe(self, line: int | None) -> str:
        """`` (content included from 'x.scxml')`` for a line that holds an include, else ``""``."""
        if line is None or line not in self.files:
            return ""
        return f" (content included from '{self.files[line]}')"


def confinement_root(ctx: ReadContext) -> Path:
    """The folder includes and ``<invoke src>`` files must stay in: the reader option
    ``include_root``, else the folder of the file read (docs/security.md, rule 4).

    Raises:
        InputError: ``ctx`` has no file (text given directly).
    """
    option = ctx.options.get("include_root")
    if option:
        return Path(str(option)).resolve()
    if ctx.path is None:
        raise InputError("a document read from text cannot include or invoke files")
    return Path(ctx.path).resolve().parent


def resolve_confined(
    ctx: ReadContext,
    base: Path | None,
    href: str,
    what: str,
    where: SourceLocation,
    element: str,
) -> Path:
    """The file ``href`` names, relative to ``base`` (the file that holds the reference),
    confined to :func:`confinement_root`.

    Args:
        ctx: The read (options, the file the user gave).
        base: The file holding the reference (``None``: text, refused).
        href: The reference as written.
        what: ``"include"`` or ``"<invoke src>"`` for messages.
        where: The reference's location.
        element: The element named in errors.

    Returns:
        The resolved path (not yet checked to exist).

    Raises:
        InputError: no file to resolve against, or a path outside the allowed folder.
        UnsupportedError: a URL (a scheme other than ``file:``) or a fragment identifier.
    """
    target = href.strip()
    if target.startswith("file:"):
        target = target[len("file:") :]
    elif ":" in target.split("/", 1)[0] and len(target.split(":", 1)[0]) > 1:
        raise UnsupportedError(
            f"unsupported: {what} '{href}' (a URL; only files next to the document are read)",
            location=where,
            element=element,
        )
    if "#" in target:
        raise UnsupportedError(
            f"unsupported: {what} '{href}' with a fragment identifier",
            location=where,
            element=element,
        )
    if not target:
        raise InputError(f"{what} without a file name", location=where, element=element)
    if base is None:
        raise InputError(
            f"{what} '{href}' needs the including file's path to resolve (read the file, not text)",
            location=where,
            element=element,
        )
    top = confinement_root(ctx)
    resolved = (base.resolve().parent / target).resolve()
    if not resolved.is_relative_to(top):
        raise InputError(
            f"{what} '{href}' resolves to {resolved}, outside the folder of the file read "
            f"({top}); refused (allow a wider folder with the include_root option)",
            location=where,
            element=element,
        )
    return resolved


def read_confined(path: Path, href: str, what: str, where: SourceLocation, element: str) -> str:
    """The text of a resolved include / invoked file (regular file, size limit, decoded).

    Raises:
        InputError: not a regular file, too large, unreadable, undecodable.
    """
    note_read(path)  # a dependency even when it is missing
    if not path.is_file():  # a FIFO or a device could block or never end
        raise InputError(
            f"{what} '{href}' ({path}) is not a regular file"
            if path.exists()
            else f"{what} '{href}' ({path}) does not exist",
            location=where,
            element=element,
        )
    data = read_located(path, f"{what} '{href}' ({path})", location=where, element=element)
    return decode(data, str(path))


def check_chain(chain: tuple[Path, ...], resolved: Path, what: str, where: SourceLocation) -> None:
    """Refuse a cycle and a chain deeper than ``limits.max_include_depth``."""
    if resolved in chain:
        cycle = " -> ".join(str(p) for p in (*chain, resolved))
        raise InputError(f"{what} cycle: {cycle}", location=where)
    depth = limits.current().max_include_depth
    if len(chain) >= depth:
        raise InputError(
            limits.exceeded(
                f"a chain of {len(chain) + 1} {what} files", "max_include_depth", depth
            ),
            location=where,
        )


def parse_document(text: str, ctx: ReadContext) -> tuple[etree._Element, Included]:
    """Parse an SCXML document and replace every ``<xi:include>`` (module docstring).

    Args:
        text: The document.
        ctx: The read (``ctx.path`` is the including file; warnings go to ``ctx``).

    Returns:
        The root element with includes expanded, and what was included where.

    Raises:
        InputError: malformed XML in any file, a missing file without fallback, a path out
            of the allowed folder, a cycle, a limit exceeded.
        UnsupportedError: ``parse="text"``, ``xpointer``, a URL.
    """
    root = parse_xml(text, ctx.display_name)
    included = Included(size=len(text))
    if next(root.iter(f"{{{XINCLUDE_NS}}}*"), None) is None:
        return root, included
    if namespace(root) == XINCLUDE_NS:
        raise InputError(
            f"the document's root element is <xi:{local_name(root)}>",
            location=ctx.location(root.sourceline),
        )
    top_path = Path(ctx.path).resolve() if ctx.path is not None else None
    # (element to expand, file holding it, chain of files, line in the main file)
    stack: list[tuple[etree._Element, Path | None, tuple[Path, ...], int | None]] = [
        (e, top_path, (top_path,) if top_path else (), None) for e in _outer_includes(root)
    ]
    stack.reverse()
    while stack:
        element, base, chain, main_line = stack.pop()
        line = main_line if main_line is not None else element.sourceline
        # the user's own file is named as they gave it; an included one by its resolved path
        named = ctx.display_name if base is None or base == top_path else str(base)
        where = SourceLocation(named, element.sourceline)
        replacement, source = _expand_one(element, base, chain, where, ctx, included, line)
        parent = element.getparent()
        assert parent is not None  # the root is never an include (refused above)
        position = parent.index(element)
        parent.remove(element)
        for offset, new in enumerate(replacement):
            parent.insert(position + offset, new)
        inner_base = source or base
        if source is not None:
            included.bases.update((new, source) for new in replacement)
        inner_chain = (*chain, source) if source else chain
        pending = []
        for new in replacement:
            pending.extend(_outer_includes(new))
            if source is not None and line is not None:  # another file's content: at the include
                for node in new.iter():
                    if isinstance(node.tag, str) and node.tag != _INCLUDE:
                        node.sourceline = line  # type: ignore[misc]  # lxml allows it
        inner_line = line if source is not None or main_line is not None else None
        stack.extend((inner, inner_base, inner_chain, inner_line) for inner in reversed(pending))
    stray = next(root.iter(f"{{{XINCLUDE_NS}}}*"), None)
    if stray is not None:
        raise InputError(
            f"<xi:{local_name(stray)}> outside an <xi:include>",
            location=ctx.location(stray.sourceline),
            element=f"<xi:{local_name(stray)}>",
        )
    return root, included


def _outer_includes(top: etree._Element) -> list[etree._Element]:
    """The ``<xi:include>`` elements in ``top`` (itself included) that are not inside another
    one (those in an ``<xi:fallback>`` are expanded only if the fallback is used)."""
    out = []
    stack = [top]
    while stack:
        element = stack.pop()
        if element.tag == _INCLUDE:
            out.append(element)
            continue
        stack.extend(reversed([c for c in element if isinstance(c.tag, str)]))
    return out


def _expand_one(
    element: etree._Element,
    base: Path | None,
    chain: tuple[Path, ...],
    where: SourceLocation,
    ctx: ReadContext,
    included: Included,
    line: int | None,
) -> tuple[list[etree._Element], Path | None]:
    """The elements that replace one ``<xi:include>``, and the file they come from (``None``:
    the fallback's content, from the including file)."""
    name = "<xi:include>"
    for key in ("xpointer", "encoding", "accept", "accept-language"):
        if element.get(key) is not None:
            raise UnsupportedError(
                f"unsupported: XInclude with {key}=", location=where, element=name
            )
    parse = element.get("parse", "xml")
    if parse == "text":
        raise UnsupportedError(
            'unsupported: XInclude parse="text" (it includes the file as character data, '
            'which holds no state; use parse="xml")',
            location=where,
            element=name,
        )
    if parse != "xml":
        raise InputError(f'XInclude parse="{parse}" (xml or text)', location=where, element=name)
    href = element.get("href")
    if not href:
        raise InputError("<xi:include> without href", location=where, element=name)
    fallbacks = [c for c in element if isinstance(c.tag, str) and c.tag == _FALLBACK]
    resolved = resolve_confined(ctx, base, href, "include", where, name)
    check_chain(chain, resolved, "include", where)
    try:
        text = read_confined(resolved, href, "included file", where, name)
    except InputError:
        if not fallbacks:
            raise
        ctx.warn(
            f"included file '{href}' cannot be read: its <xi:fallback> is used instead",
            line=line,
            element=name,
        )
        return [c for c in fallbacks[0] if isinstance(c.tag, str)], None
    included.size += len(text)
    budget = limits.current().max_input_bytes
    if included.size > budget:  # a file included many times (a, twice b, twice c...) grows
        raise InputError(
            limits.exceeded(
                f"the document with its inclusions ({included.size}+ characters, each "
                "inclusion counted)",
                "max_input_bytes",
                budget,
            ),
            location=where,
            element=name,
        )
    fragment = parse_xml(text, str(resolved))
    holder = element.getparent()
    target_ns = namespace(holder) if holder is not None else None
    moved = False
    if target_ns is not None:
        for node in fragment.iter():
            if isinstance(node.tag, str) and namespace(node) is None:
                node.tag = f"{{{target_ns}}}{local_name(node)}"
                moved = True
    if moved:
        ctx.warn(
            f"elements of the included file '{href}' without a namespace are read in the "
            "SCXML namespace of the including document",
            line=line,
            element=name,
        )
    if line is not None:
        included.files.setdefault(line, str(resolved))
    return [fragment], resolved


def annotate(error: InputError, text: str, ctx: ReadContext) -> InputError:
    """``error`` with `` (content included from 'x')`` added when it is located at the line of
    an ``<xi:include>`` (content from another file carries that line). Re-expands the includes
    only for a document that has some and an error with a line: O(document) once, on failure.

    Args:
        error: The error a reader raised.
        text: The document read.
        ctx: The read.

    Returns:
        ``error`` (its message extended in place when it applies).
    """
    location = error.location
    if location is None or location.line is None or XINCLUDE_NS not in text:
        return error
    line = location.line
    if location.file != ctx.display_name:
        return error  # (an error in an invoked file is located in that file)
    try:
        _root, included = parse_document(text, ReadContext(ctx.path, dict(ctx.options)))
    except InputError:
        return error
    error.message += included.describe(line)
    return error
