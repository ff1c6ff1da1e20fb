"""Python source of SMACH / FlexBE state machines, parsed and never run (docs/formats/smach.md).

Rules:
- The text is parsed with ``ast.parse`` only: nothing is imported, compiled to bytecode, executed
  or evaluated (no ``eval``/``exec``/``literal_eval`` of user text). Side effects written in the
  file (module-level code, ``__main__`` blocks) never happen.
- Bounds before and after parsing: at most ``MAX_SOURCE_BYTES`` of text; the parser's own
  ``RecursionError``/``MemoryError``/``SyntaxError`` become a located ``InputError``; a syntax
  tree deeper than ``MAX_AST_DEPTH`` is refused (measured iteratively) so nothing downstream
  can run out of stack.
- ``literal`` evaluates the few literal forms a state machine needs (strings, numbers, lists,
  tuples, dicts, names bound to such literals) with an explicit stack; anything else is
  ``NotStatic`` and the caller names it as unsupported.

Costs: O(n) in the size of the source for parsing and the depth check.
"""

from __future__ import annotations

import ast
from collections.abc import Callable

from fsmbt.formats.pysm.py2 import NotNormalisable, normalise
from fsmbt.model.errors import InputError, SourceLocation

#: A behaviour file larger than this is not a state machine someone wrote by hand or by editor.
MAX_SOURCE_BYTES = 4 * 1024 * 1024
#: Deepest syntax tree accepted (real behaviours stay under 30).
MAX_AST_DEPTH = 200


class NotStatic(Exception):
    """An expression whose value is only known when the program runs."""

    def __init__(self, node: ast.AST, what: str = "a value computed at run time") -> None:
        super().__init__(what)
        self.node = node
        self.what = what


def parse_source(text: str, name: str) -> ast.Module:
    """The module's syntax tree, or a located ``InputError`` (never a parser traceback).

    Args:
        text: the Python source.
        name: the file name for error locations.

    Returns:
        The parsed module (not executed); see ``parse_python`` for Python 2 sources.
    """
    return parse_python(text, name)[1]


def parse_python(text: str, name: str) -> tuple[str, ast.Module, list[str]]:
    """The module's syntax tree, read as Python 3 and else as Python 2 (never executed).

    A text Python 3's parser refuses is normalised by ``fsmbt.formats.pysm.py2`` (ROS 1 era
    files: ``print x``, ``except X, e``, mixed tabs ...) and parsed again; the text the tree
    was parsed from is returned, since the tree's columns refer to it.

    Args:
        text: the Python source.
        name: the file name for error locations.

    Returns:
        ``(text parsed, tree, notes)``: notes name each Python 2 form rewritten (empty for a
        Python 3 text).

    Raises:
        InputError: neither reading parses (the first error, located), or the source is too
            large or too deep.
    """
    if len(text.encode("utf-8", "surrogatepass")) > MAX_SOURCE_BYTES:
        raise InputError(
            f"Python source larger than {MAX_SOURCE_BYTES} bytes; not read",
            location=SourceLocation(name),
        )
    try:
        return text, _parse(text, name), []
    except SyntaxError as exc:
        first = exc
    try:
        normalised = normalise(text)
    except NotNormalisable:
        raise _syntax_error(first, name) from None
    try:
        tree = _parse(normalised.text, name)
    except SyntaxError as again:
        worse = (again.lineno or 0) > (first.lineno or 0)
        raise _syntax_error(again if worse else first, name) from None
    return normalised.text, tree, normalised.notes


def _syntax_error(exc: SyntaxError, name: str) -> InputError:
    return InputError(
        f"Python syntax error: {exc.msg}", location=SourceLocation(name, exc.lineno, exc.offset)
    )


def _parse(text: str, name: str) -> ast.Module:
    """``ast.parse`` with the parser's own failures (other than syntax) as ``InputError``."""
    try:
        tree = ast.parse(text, filename=name, mode="exec")
    except SyntaxError:
        raise
    except (RecursionError, MemoryError):
        raise InputError(
            "Python source nested too deeply for the parser (an expression or "
            "statement thousands of levels deep); not read",
            location=SourceLocation(name),
        ) from None
    except ValueError as exc:  # e.g. NUL bytes
        raise InputError(f"not Python source: {exc}", location=SourceLocation(name)) from None
    _check_depth(tree, name)
    return tree


def _check_depth(tree: ast.AST, name: str) -> None:
    stack: list[tuple[ast.AST, int]] = [(tree, 0)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_AST_DEPTH:
            line = getattr(node, "lineno", None)
            raise InputError(
                f"Python syntax nested more than {MAX_AST_DEPTH} levels deep; not read",
                location=SourceLocation(name, line),
            )
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))


def literal(node: ast.AST, lookup: Callable[[str], object] | None = None) -> object:
    """The value of a literal expression, evaluated with an explicit stack.

    Args:
        node: the expression.
        lookup: resolves a bare name to a literal value bound earlier (raises ``KeyError``
            when unknown).

    Returns:
        str, int, float, bool, None, list, tuple or dict built from those; ``Attribute`` chains
        of names (``Autonomy.Off``) come back as their dotted text.

    Raises:
        NotStatic: the expression is not such a literal.
    """
    results: dict[int, object] = {}
    stack: list[tuple[ast.AST, bool]] = [(node, False)]
    while stack:
        current, expanded = stack.pop()
        children = _literal_children(current, lookup)
        if not expanded and children:
            stack.append((current, True))
            stack.extend((child, False) for child in children)
            continue
        results[id(current)] = _literal_value(current, results, lookup)
    return results[id(node)]


def _literal_children(node: ast.AST, lookup: Callable[[str], object] | None) -> list[ast.AST]:
    if isinstance(node, (ast.List, ast.Tuple, ast.Set)):
        return list(node.elts)
    if isinstance(node, ast.Dict):
        if any(k is None for k in node.keys):
            raise NotStatic(node, "a dict built with ** unpacking")
        keys: list[ast.AST] = [k for k in node.keys if k is not None]
        return keys + list(node.values)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        return [node.operand]
    return []


def _literal_value(
    node: ast.AST, results: dict[int, object], lookup: Callable[[str], object] | None
) -> object:
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.List):
        return [results[id(e)] for e in node.elts]
    if isinstance(node, (ast.Tuple, ast.Set)):
        return tuple(results[id(e)] for e in node.elts)
    if isinstance(node, ast.Dict):
        out: dict[object, object] = {}
        for key, value in zip(node.keys, node.values):
            assert key is not None
            k = results[id(key)]
            if not isinstance(k, (str, int, float, bool, type(None), tuple)):
                raise NotStatic(key, "a dict key that is not a literal")
            out[k] = results[id(value)]
        return out
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        number = results[id(node.operand)]
        if isinstance(number, (int, float)) and not isinstance(number, bool):
            return -number if isinstance(node.op, ast.USub) else number
        raise NotStatic(node)
    if isinstance(node, ast.Name):
        if lookup is not None:
            try:
                return lookup(node.id)
            except KeyError:
                pass
        raise NotStatic(node, f"the variable '{node.id}' (its value is known only at run time)")
    dotted = dotted_name(node)
    if dotted is not None and isinstance(node, ast.Attribute):
        return dotted
    raise NotStatic(node)


def dotted_name(node: ast.AST) -> str | None:
    """``a.b.c`` for a chain of names and attributes, else ``None`` (iterative)."""
    parts: list[str] = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    parts.append(node.id)
    return ".".join(reversed(parts))


def last_name(node: ast.AST) -> str | None:
    """The last identifier of a name or attribute chain (``smach.StateMachine`` ->
    ``StateMachine``)."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return node.attr
    return None


_LINES_CACHE: dict[int, tuple[str, list[bytes]]] = {}


def source_text(text: str, node: ast.AST, limit: int = 200) -> str:
    """The source of ``node`` on one line, shortened to ``limit`` characters.

    The text's lines are split once per text (``ast.get_source_segment`` splits the whole
    text on every call, which made reading quadratic)."""
    cached = _LINES_CACHE.get(id(text))
    if cached is None or cached[0] is not text:
        _LINES_CACHE.clear()
        cached = (text, [line.encode("utf-8") for line in text.splitlines(keepends=True)])
        _LINES_CACHE[id(text)] = cached
    lines = cached[1]
    start, end = getattr(node, "lineno", None), getattr(node, "end_lineno", None)
    first, last = getattr(node, "col_offset", None), getattr(node, "end_col_offset", None)
    if None in (start, end, first, last) or not 1 <= start <= end <= len(lines):  # type: ignore[operator]
        return ""
    assert start is not None and end is not None and first is not None and last is not None
    if start == end:
        chunk = lines[start - 1][first:last]
    else:
        chunk = b"".join([lines[start - 1][first:], *lines[start : end - 1], lines[end - 1][:last]])
    segment = " ".join(chunk.decode("utf-8", "replace").split())
    return segment if len(segment) <= limit else segment[: limit - 3] + "..."
