"""One safe XML parse for every XML format (BehaviorTree.CPP, the paper's FSM XML, SCXML).

Why a module of its own: model files come from anywhere, and XML parsers are a classic attack
surface. Every XML reader in fsmbt goes through :func:`parse_xml`, which

- refuses a DOCTYPE whose internal subset declares entities (billion laughs, external entities)
  before any parser sees the text, and parses with ``resolve_entities=False``,
  ``no_network=True``, ``load_dtd=False`` (nothing is fetched, nothing is expanded);
- turns malformed XML into one ``InputError`` naming file, line, column and lxml's cause;
- allows element nesting up to ``limits.current().max_xml_depth`` levels (``fsmbt.limits``,
  ``FSMBT_MAX_XML_DEPTH``; generated behavior trees are deep) and refuses deeper documents at
  once with a clear message - never a ``RecursionError`` or a hang.

libxml2 (under lxml) stops at 2 048 levels even with ``huge_tree``; documents deeper than that
are parsed by the standard library's expat (C, not recursive) feeding lxml's ``TreeBuilder``, so
callers always get an lxml element tree whose elements carry ``sourceline``. Comments and
processing instructions are dropped. Complexity: O(n) in the size of the text.

Leniency (only for a caller that passes ``notes``: the BehaviorTree.CPP reader, docs/formats/
btcpp.md "What BehaviorTree.CPP reads"): tinyxml2, BehaviorTree.CPP's parser, ends a comment at
the first ``-->`` and accepts ``--`` inside it (``<!------->``, ``<!-- a -- b -->``), which XML
1.0 forbids and libxml2 refuses ("Double hyphen within comment"). When the strict parse fails so
and the text has such comments, their bodies are blanked (same length, newlines kept, so every
line and column stays right: comments are dropped anyway) and the text parsed again, one note
saying so. The security rules above are unchanged: the entity check runs first on the original
text, and the second parse uses the same hardened parser.
"""

from __future__ import annotations

import re
import xml.parsers.expat as expat
from typing import Any

from lxml import etree

from fsmbt import limits
from fsmbt.model.errors import InputError, SourceLocation

#: libxml2's own limit with ``huge_tree=True``; deeper documents go through expat.
_LIBXML_MAX_DEPTH = 2048

_DOCTYPE_SUBSET = re.compile(r"<!DOCTYPE[^>\[]*\[(?P<subset>.*?)\]\s*>", re.S)
_ENTITY_DECL = re.compile(r"<!ENTITY", re.I)
_PROLOG_NOISE = re.compile(r"\s+|<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>\[]*(\[.*?\])?\s*>", re.S)
_TAG_NAME = re.compile(r"<\s*([A-Za-z_][\w.:-]*)")


def root_tag(text: str) -> str | None:
    """The local name of the root element (prefix dropped), or ``None`` if there is none.

    Cheap and forgiving: used for content sniffing, reads at most the first 64 KiB.
    """
    head = text[:65536].lstrip("\ufeff")
    pos = 0
    while True:
        noise = _PROLOG_NOISE.match(head, pos)
        if noise is None or noise.end() == pos:
            break
        pos = noise.end()
    match = _TAG_NAME.match(head, pos)
    if match is None:
        return None
    return match.group(1).rsplit(":", 1)[-1]


def local_name(element: etree._Element) -> str:
    """An element's tag without its namespace (``{uri}state`` -> ``state``)."""
    return etree.QName(element).localname


def namespace(element: etree._Element) -> str | None:
    return etree.QName(element).namespace


#: A comment as tinyxml2 reads it: from ``<!--`` to the first ``-->``.
_TINYXML_COMMENT = re.compile(r"<!--(?P<body>.*?)-->", re.S)


def _blank_hyphen_comments(text: str) -> tuple[str, int]:
    """Comments whose body XML 1.0 forbids (``--`` inside, or ``-`` last) blanked: the text
    and how many were."""
    count = 0

    def blank(match: re.Match[str]) -> str:
        nonlocal count
        body = match.group("body")
        if "--" not in body and not body.endswith("-"):
            return match.group(0)
        count += 1
        return "<!--" + re.sub(r"[^\n]", " ", body) + "-->"

    return _TINYXML_COMMENT.sub(blank, text), count


def parse_xml(
    text: str, source: str | None = None, notes: list[str] | None = None
) -> etree._Element:
    """Parse ``text`` safely and return the root element (see the module docstring).

    ``source`` is the file name used in error messages. ``notes``: read comments as tinyxml2
    does (the module docstring's "Leniency"), each leniency used appended as one located line.
    """
    _refuse_entity_declarations(text, source)
    if notes is None:
        return _parse_strict(text, source)
    try:
        return _parse_strict(text, source)
    except InputError as exc:
        if "comment" not in str(exc).lower():
            raise
        lenient, count = _blank_hyphen_comments(text)
        if not count:
            raise
        root = _parse_strict(lenient, source)
        notes.append(
            f"{source}: {count} comment(s) hold '--' (XML 1.0 forbids it; read as "
            "BehaviorTree.CPP's tinyxml2 reads them, to the first '-->')"
        )
        return root


def _parse_strict(text: str, source: str | None) -> etree._Element:
    data = text.encode("utf-8")
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=True,
        remove_comments=True,
        remove_pis=True,
        encoding="utf-8",
    )
    max_depth = limits.current().max_xml_depth
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        if "Excessive depth" in str(exc):
            return _parse_deep(data, source, max_depth)
        line, column = exc.position if exc.position else (exc.lineno, None)
        cause = re.sub(r",\s*line \d+, column \d+\s*$", "", exc.msg or str(exc))
        raise InputError(
            f"malformed XML: {cause}", location=SourceLocation(source, line, column)
        ) from None
    except ValueError as exc:  # lxml refuses some text before parsing (e.g. an XML declaration)
        raise InputError(f"malformed XML: {exc}", location=SourceLocation(source)) from None
    if max_depth < _LIBXML_MAX_DEPTH:
        _check_depth(root, source, max_depth)
    return root


def _check_depth(root: etree._Element, source: str | None, max_depth: int) -> None:
    """Refuse a parsed tree deeper than ``max_depth`` (explicit stack; O(elements))."""
    stack = [(root, 1)]
    while stack:
        element, depth = stack.pop()
        if depth > max_depth:
            raise InputError(
                _too_deep(max_depth), location=SourceLocation(source, element.sourceline)
            )
        stack.extend((child, depth + 1) for child in element)


def _too_deep(max_depth: int) -> str:
    return limits.exceeded(f"XML nested deeper than {max_depth} levels", "max_xml_depth", max_depth)


def _refuse_entity_declarations(text: str, source: str | None) -> None:
    for match in _DOCTYPE_SUBSET.finditer(text):
        if _ENTITY_DECL.search(match.group("subset")):
            line = text.count("\n", 0, match.start()) + 1
            raise InputError(
                "DOCTYPE declares entities; refused (entity expansion and external entities "
                "are a security risk, and no model format needs them)",
                location=SourceLocation(source, line),
            )


class _TooDeep(Exception):
    pass


def _parse_deep(data: bytes, source: str | None, max_depth: int) -> etree._Element:
    """expat -> lxml ``TreeBuilder`` for documents deeper than libxml2 allows."""
    builder = etree.TreeBuilder()
    parser = expat.ParserCreate(encoding="UTF-8", namespace_separator=" ")
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    depth = 0

    def clark(name: str) -> str:
        uri, _, local = name.rpartition(" ")
        return f"{{{uri}}}{local}" if uri else local

    def start(name: str, attrs: dict[str, str]) -> None:
        nonlocal depth
        depth += 1
        if depth > max_depth:
            raise _TooDeep
        # lxml's TreeBuilder.start returns the new element (types-lxml declares None)
        element: Any = builder.start(  # type: ignore[func-returns-value]
            clark(name), {clark(k): v for k, v in attrs.items()}
        )
        element.sourceline = parser.CurrentLineNumber

    def end(name: str) -> None:
        nonlocal depth
        depth -= 1
        builder.end(clark(name))

    def entity_declared(*_args: object) -> None:
        raise InputError(
            "DOCTYPE declares entities; refused",
            location=SourceLocation(source, parser.CurrentLineNumber),
        )

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = builder.data
    parser.EntityDeclHandler = entity_declared
    try:
        parser.Parse(data, True)
    except _TooDeep:
        raise InputError(
            _too_deep(max_depth),
            location=SourceLocation(
                source, parser.CurrentLineNumber, parser.CurrentColumnNumber + 1
            ),
        ) from None
    except expat.ExpatError as exc:
        raise InputError(
            f"malformed XML: {expat.ErrorString(exc.code)}",
            location=SourceLocation(source, exc.lineno, exc.offset + 1),
        ) from None
    return builder.close()
