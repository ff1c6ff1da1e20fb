"""Python 2 era sources (ROS 1 FlexBE and SMACH files) made parseable by Python 3's ``ast``.

Files written for ROS 1 run under Python 2: ``print x`` statements, ``except Error, e``,
``raise Error, "text"``, ``exec code``, backtick repr, ``ur''`` strings, ``0777`` octals,
``10L`` longs, ``<>``, and indentation mixing tabs and spaces (Python 2 reads a tab as the
next multiple of 8 columns; Python 3 refuses an inconsistent mix). The state machine they
build is the same; only the syntax around it differs. ``normalise`` rewrites those forms at
token level into their Python 3 spelling, so ``ast.parse`` reads the file. Nothing is
imported, compiled or executed: the text is tokenised (``tokenize``, a pure lexer) and edited.

Rules (docs/formats/flexbe.md, "Python 2 files"):
- Called only after Python 3's parser refused the text; a file Python 3 reads is never
  rewritten.
- Line numbers are kept (no line is added or removed), so every later error names the line
  of the original file; columns after an edit on the same line may shift by a few characters.
- Leading tabs are expanded to the next multiple of 8 columns (Python 2's rule) on every line
  that is not inside a string.
- Statement-level rewrites: ``print ...`` -> ``print(...)`` (``print >>f, x`` -> ``print(x,
  file=f)``), ``exec ...`` -> ``exec(...)``, ``except X, e`` -> ``except X as e``,
  ``raise E, v[, tb]`` -> ``raise E(v)``. Token rewrites: backticks -> ``repr(...)``, ``ur``/``UR``
  prefixes -> ``r``, ``0777`` -> ``0o777``, ``10L`` -> ``10``, ``<>`` -> ``!=``.
- What the rewrites did is returned as short notes (one per kind) for the reader's warning.

Costs: O(n) in the length of the text (one tokenisation, one pass over the tokens).
"""

from __future__ import annotations

import io
import token
import tokenize
from dataclasses import dataclass, field

_STATEMENT_KEYWORDS = frozenset({"print", "exec"})
_OPENERS = {"(": ")", "[": "]", "{": "}"}
_CLOSERS = frozenset(_OPENERS.values())


class NotNormalisable(Exception):
    """The text cannot be tokenised (an unterminated string, a stray character)."""

    def __init__(self, message: str, line: int | None) -> None:
        super().__init__(message)
        self.line = line


@dataclass
class _Edit:
    """Replace the text between two (line, column) positions (0-based line)."""

    start: tuple[int, int]
    end: tuple[int, int]
    text: str


@dataclass
class Normalised:
    """The rewritten text and what was rewritten (one note per kind of change)."""

    text: str
    notes: list[str] = field(default_factory=list)


def expand_leading_tabs(text: str) -> tuple[str, bool]:
    """Every line's leading whitespace with tabs expanded to 8-column stops (Python 2's
    indentation rule); lines inside triple-quoted strings are left alone."""
    lines = text.splitlines(keepends=True)
    inside = _string_lines(text)
    changed = False
    for index, line in enumerate(lines):
        if index + 1 in inside:
            continue
        stripped = line.lstrip(" \t\f")
        lead = line[: len(line) - len(stripped)]
        if "\t" not in lead:
            continue
        column = 0
        for char in lead:
            column = (column // 8 + 1) * 8 if char == "\t" else column + 1
        lines[index] = " " * column + stripped
        changed = True
    return "".join(lines), changed


def _string_lines(text: str) -> set[int]:
    """The 1-based lines that start inside a multi-line string token."""
    inside: set[int] = set()
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == token.STRING and tok.end[0] > tok.start[0]:
                inside.update(range(tok.start[0] + 1, tok.end[0] + 1))
    except (tokenize.TokenError, IndentationError, SyntaxError):
        pass
    return inside


def normalise(text: str) -> Normalised:
    """The text with Python 2 syntax rewritten to Python 3 (see the module docstring).

    Raises:
        NotNormalisable: the text cannot be tokenised even so.
    """
    notes: list[str] = []
    text, tabs = expand_leading_tabs(text)
    if tabs:
        notes.append("tabs in indentation expanded to 8-column stops")
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except tokenize.TokenError as exc:
        line = exc.args[1][0] if len(exc.args) > 1 and exc.args[1] else None
        raise NotNormalisable(str(exc.args[0]), line) from None
    except (IndentationError, SyntaxError) as exc:
        raise NotNormalisable(exc.msg, exc.lineno) from None
    edits: list[_Edit] = []
    kinds: dict[str, None] = {}
    _statement_edits(tokens, edits, kinds)
    _token_edits(tokens, edits, kinds)
    notes.extend(kinds)
    return Normalised(_apply(text, edits), notes)


def _logical_lines(tokens: list[tokenize.TokenInfo]) -> list[list[tokenize.TokenInfo]]:
    """The tokens of each logical line (comments and non-logical newlines left out)."""
    lines: list[list[tokenize.TokenInfo]] = []
    current: list[tokenize.TokenInfo] = []
    for tok in tokens:
        if tok.type in (tokenize.COMMENT, tokenize.NL, token.INDENT, token.DEDENT):
            continue
        if tok.type in (token.NEWLINE, token.ENDMARKER):
            if current:
                lines.append(current)
            current = []
            continue
        current.append(tok)
    if current:
        lines.append(current)
    return lines


def _top_level_commas(toks: list[tokenize.TokenInfo], stop: str | None = None) -> list[int]:
    """Indexes of the commas at bracket depth 0 (before a depth-0 ``stop`` operator)."""
    depth = 0
    out = []
    for index, tok in enumerate(toks):
        if tok.type != token.OP:
            continue
        if tok.string in _OPENERS:
            depth += 1
        elif tok.string in _CLOSERS:
            depth -= 1
        elif depth == 0 and stop is not None and tok.string == stop:
            break
        elif depth == 0 and tok.string == ",":
            out.append(index)
    return out


def _statement_edits(
    tokens: list[tokenize.TokenInfo], edits: list[_Edit], kinds: dict[str, None]
) -> None:
    for line in _logical_lines(tokens):
        for start in _statement_starts(line):
            _statement_edit(line[start:], edits, kinds)


def _statement_starts(line: list[tokenize.TokenInfo]) -> list[int]:
    """Where statements start in a logical line (after ``;`` and after a compound
    statement's ``:`` at depth 0, e.g. ``if x: print y``)."""
    starts = [0]
    depth = 0
    head = line[0].string if line else ""
    compound = head in ("if", "elif", "else", "for", "while", "try", "except", "finally", "with")
    for index, tok in enumerate(line):
        if tok.type != token.OP:
            continue
        if tok.string in _OPENERS:
            depth += 1
        elif tok.string in _CLOSERS:
            depth -= 1
        elif depth == 0 and tok.string == ";":
            starts.append(index + 1)
        elif depth == 0 and tok.string == ":" and compound and len(starts) == 1:
            starts.append(index + 1)
    return [s for s in starts if s < len(line)]


def _statement_edit(
    stmt: list[tokenize.TokenInfo], edits: list[_Edit], kinds: dict[str, None]
) -> None:
    first = stmt[0]
    end = _statement_end(stmt)
    if first.type == token.NAME and first.string in _STATEMENT_KEYWORDS and end > 1:
        following = stmt[1]
        if following.type == token.OP and following.string in ("(", "=", ".", "["):
            if following.string != "(" or _closes_statement(stmt[1:end]):
                return  # already a call (``print(x)``), or an assignment or attribute
        last = stmt[end - 1]
        if first.string == "print" and following.type == token.OP and following.string == ">>":
            commas = _top_level_commas(stmt[2:end])
            if commas:
                comma = stmt[2 + commas[0]]
                target_text = _span(stmt[2], stmt[1 + commas[0]])
                edits.append(_Edit(following.start, comma.end, "("))
                trailing = last.type == token.OP and last.string == "," and last is not comma
                start = last.start if trailing else last.end
                edits.append(_Edit(start, last.end, f", file={target_text})"))
            else:
                edits.append(_Edit(following.start, following.end, "("))
                edits.append(_Edit(last.end, last.end, ")"))
        else:
            edits.append(_Edit(first.end, following.start, "("))
            edits.append(_Edit(last.end, last.end, ")"))
        kinds[f"Python 2 '{first.string}' statements read as calls"] = None
        return
    if first.type == token.NAME and first.string == "except":
        commas = _top_level_commas(stmt[1:end], stop=":")
        if len(commas) == 1:
            comma = stmt[1 + commas[0]]
            edits.append(_Edit(comma.start, comma.end, " as"))
            kinds["Python 2 'except X, e' read as 'except X as e'"] = None
        return
    if first.type == token.NAME and first.string == "raise":
        commas = _top_level_commas(stmt[1:end])
        if commas:
            comma = stmt[1 + commas[0]]
            cut = stmt[1 + commas[1]] if len(commas) > 1 else None
            last = stmt[end - 1]
            if cut is not None:
                edits.append(_Edit(comma.start, comma.end, "("))
                edits.append(_Edit(cut.start, last.end, ")"))
            else:
                edits.append(_Edit(comma.start, comma.end, "("))
                edits.append(_Edit(last.end, last.end, ")"))
            kinds["Python 2 'raise E, value' read as 'raise E(value)'"] = None


def _statement_end(stmt: list[tokenize.TokenInfo]) -> int:
    """The number of tokens up to the statement's own ``;`` (depth 0), or all of them."""
    depth = 0
    for index, tok in enumerate(stmt):
        if tok.type != token.OP:
            continue
        if tok.string in _OPENERS:
            depth += 1
        elif tok.string in _CLOSERS:
            depth -= 1
        elif depth == 0 and tok.string == ";":
            return index
    return len(stmt)


def _closes_statement(toks: list[tokenize.TokenInfo]) -> bool:
    """Whether the bracket opened by ``toks[0]`` closes at the statement's last token."""
    depth = 0
    for index, tok in enumerate(toks):
        if tok.type == token.OP and tok.string in _OPENERS:
            depth += 1
        elif tok.type == token.OP and tok.string in _CLOSERS:
            depth -= 1
            if depth == 0:
                return index == len(toks) - 1
    return False


def _span(first: tokenize.TokenInfo, last: tokenize.TokenInfo) -> str:
    """The source text from ``first`` to ``last`` when both are on one line."""
    if first.start[0] != last.end[0]:
        return first.string
    return first.line[first.start[1] : last.end[1]]


def _token_edits(
    tokens: list[tokenize.TokenInfo], edits: list[_Edit], kinds: dict[str, None]
) -> None:
    backtick_open = False
    for index, tok in enumerate(tokens):
        following = tokens[index + 1] if index + 1 < len(tokens) else None
        adjacent = following is not None and following.start == tok.end
        if tok.type == token.ERRORTOKEN and tok.string == "`":
            edits.append(_Edit(tok.start, tok.end, ")" if backtick_open else "repr("))
            backtick_open = not backtick_open
            kinds["Python 2 backticks read as repr()"] = None
        elif (
            tok.type == token.NAME
            and tok.string.lower() == "ur"
            and adjacent
            and following is not None
            and following.type == token.STRING
        ):
            edits.append(_Edit(tok.start, tok.end, "r"))
            kinds["Python 2 ur'' strings read as r''"] = None
        elif (
            tok.type == token.NUMBER
            and tok.string == "0"
            and adjacent
            and following is not None
            and following.type == token.NUMBER
            and following.string.isdigit()
        ):
            edits.append(_Edit(tok.start, tok.end, "0o"))
            kinds["Python 2 octal literals read as 0o..."] = None
        elif (
            tok.type == token.NUMBER
            and adjacent
            and following is not None
            and following.type == token.NAME
            and following.string in ("L", "l")
        ):
            edits.append(_Edit(following.start, following.end, ""))
            kinds["Python 2 long literals (10L) read as ints"] = None
        elif (
            tok.type == token.OP
            and tok.string == "<"
            and adjacent
            and following is not None
            and following.type == token.OP
            and following.string == ">"
        ):
            edits.append(_Edit(tok.start, following.end, "!="))
            kinds["Python 2 '<>' read as '!='"] = None
        elif tok.type == token.OP and tok.string == "<>":
            edits.append(_Edit(tok.start, tok.end, "!="))
            kinds["Python 2 '<>' read as '!='"] = None


def _apply(text: str, edits: list[_Edit]) -> str:
    """The text with the edits made (they never overlap; applied from the end)."""
    lines = text.splitlines(keepends=True)
    offsets = [0]
    for line in lines:
        offsets.append(offsets[-1] + len(line))

    def absolute(position: tuple[int, int]) -> int:
        row, column = position
        if row - 1 >= len(lines):
            return len(text)
        return offsets[row - 1] + column

    out = text
    for edit in sorted(edits, key=lambda e: (absolute(e.start), absolute(e.end)), reverse=True):
        out = out[: absolute(edit.start)] + edit.text + out[absolute(edit.end) :]
    return out
