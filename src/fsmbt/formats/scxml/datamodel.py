"""The finite data model of an SCXML document read by the W3C algorithm (docs/formats/scxml.md,
"Data read exactly").

Rules (decided once per document, before exploring; ``plan``):

- A *candidate* variable is declared by ``<data id>`` (its ``expr`` in the subset of
  ``fsmbt.formats.scxml.expr``, reading earlier candidates only; no ``expr``: ``undefined``)
  or by Apache Commons SCXML's ``<cs:var name expr>`` (a declaration and an assignment).
- A candidate is *tracked* when every ``<assign>`` to it (and every ``<cs:var>`` of it) has an
  expression in the subset reading tracked variables only (greatest fixpoint).
- A ``cond`` (transition or ``<if>``) in the subset that reads tracked variables only (or
  none: ``In()``, literals) is *computed* from the data; any other cond stays an input of the
  environment (docs/formats/scxml.md, "Guarded inputs"). An input cond that reads a variable
  some ``<assign>`` changes is refused naming that assignment's line (its value would depend
  on the machine's history).
- The *relevant* variables are those computed conds and exact ``eventexpr`` read, closed under
  "an assignment to a relevant variable reads it". Their values are part of each explored
  state; assignments to other variables do not matter and are ignored with a warning.
- ``<send eventexpr>``: *exact* when in the subset (string literals, ``+``, relevant variables,
  ``_event.name`` as the last operand); *unobservable* when it is a string literal ``P``
  followed by ``+`` operands of any text and no event descriptor can match a name starting
  with ``P`` (nor ``error.execution``, which a failing operand raises): it is then dropped
  with a warning. Otherwise refused with its line.
- ``<script>`` (never run) is ignored with a warning when it cannot affect control flow: no
  cond reads the data model at all (only ``In()`` and literals), no exact ``eventexpr`` reads
  a variable, and no descriptor matches ``error.execution``; the caller also checks that a
  failing script skips nothing that matters (``may_fail``). Otherwise refused with its line.

Costs: O(V · A) for the fixpoints (V variables, A assignments), O(D) per descriptor check.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from fsmbt.formats.scxml import expr as scxml_expr
from fsmbt.model.errors import LimitError

#: Apache Commons SCXML's namespace of custom actions (``<cs:var>``), both spellings in use.
COMMONS_NS = frozenset({"http://commons.apache.org/scxml", "https://commons.apache.org/scxml"})
ERROR_EXECUTION = "error.execution"
_IDENT = re.compile(r"[A-Za-z_$][\w$]*")
_PREFIX_OPERAND = re.compile(r"""\s*(?:'[^']*'|"[^"]*"|[A-Za-z_$][\w$]*|\d+(?:\.\d+)?)""")
_STRING = re.compile(r"""\s*('[^']*'|"[^"]*")""")
_MEMBER = re.compile(r"\.\s*[A-Za-z_$][\w$]*")


class StateLimitError(LimitError):
    """The configurations times data valuations pass the state limit (an unbounded variable)."""


@dataclass(frozen=True)
class Declared:
    """One ``<data>`` (or ``<cs:var>``): id, expression text, has content, line."""

    name: str
    expr: str | None
    has_content: bool
    line: int | None


@dataclass(frozen=True)
class Assignment:
    """One ``<assign>`` (or ``<cs:var>``): location, expression text, line."""

    location: str
    expr: str | None
    line: int | None
    declares: bool = False  # a <cs:var>


@dataclass(frozen=True)
class SendExpr:
    """One ``<send eventexpr>``: the expression text and its line."""

    text: str
    line: int | None


@dataclass
class DataPlan:
    """What the document's data means to the exploration (see module docstring)."""

    dialect: scxml_expr.Dialect | None
    tracked: set[str] = field(default_factory=set)
    relevant: list[str] = field(default_factory=list)  # declaration order
    varying: list[str] = field(default_factory=list)  # relevant ones some assignment changes
    computed: dict[int, scxml_expr.Expr] = field(default_factory=dict)  # guard index -> expr
    assigns: dict[int, scxml_expr.Expr] = field(default_factory=dict)  # to relevant variables
    sends: dict[int, scxml_expr.Expr] = field(default_factory=dict)  # exact eventexprs
    dropped_sends: set[int] = field(default_factory=set)  # unobservable eventexprs
    initial: dict[str, scxml_expr.Value] = field(default_factory=dict)
    declared: set[str] = field(default_factory=set)
    reads_data: str | None = None  # why a script would matter (a cond reading the data)

    @property
    def has_data(self) -> bool:
        """Whether explored states carry data values (the varying relevant variables: a
        constant one is the same in every state and is left out of the names)."""
        return bool(self.varying)


class Refusal(Exception):
    """A rule refuses the document: the message and the line."""

    def __init__(self, message: str, line: int | None) -> None:
        super().__init__(message)
        self.message, self.line = message, line


def matches(descriptor: str, event: str) -> bool:
    """W3C 5.9.3: ``*`` matches every event; ``a`` matches ``a`` and ``a.b`` (token prefix)."""
    return descriptor == "*" or event == descriptor or event.startswith(descriptor + ".")


def may_match_prefix(descriptors: Iterable[str], prefix: str) -> bool:
    """Whether some descriptor matches some event name that starts with ``prefix``."""
    for d in descriptors:
        if d == "*" or d.startswith(prefix) or prefix.startswith(d + "."):
            return True
    return False


def matches_error_execution(descriptors: Iterable[str]) -> bool:
    """Whether some descriptor matches ``error.execution`` (W3C's executable-content error)."""
    return any(matches(d, ERROR_EXECUTION) for d in descriptors)


def literal_prefix(text: str) -> str | None:
    """``P`` when ``text`` is a string literal ``P`` followed by ``+`` operands only, each a
    literal or an identifier chain of member accesses and calls (``a.b(c, 'd')[0]``): in
    ECMAScript such a value is a string starting with ``P``, or the evaluation fails
    (``error.execution``). ``None`` for any other text."""
    head = _STRING.match(text)
    if head is None:
        return None
    prefix, position, end = head.group(1)[1:-1], head.end(), len(text.rstrip())
    if position >= end:
        return None  # a plain literal: the exact reading takes it
    while position < end:
        rest = text[position:end].lstrip()
        if not rest.startswith("+"):
            return None
        position = end - len(rest) + 1
        operand = _PREFIX_OPERAND.match(text, position)
        if operand is None:
            return None
        after = _skip_postfix(text, operand.end(), end)
        if after is None:
            return None
        position = after
    return prefix


def _skip_postfix(text: str, position: int, end: int) -> int | None:
    """Past ``.name``, ``(...)`` and ``[...]`` suffixes (brackets balanced, strings skipped)."""
    while True:
        rest = text[position:end].lstrip()
        position = end - len(rest)
        if rest.startswith("."):
            found = _MEMBER.match(text, position)
            if found is None:
                return None
            position = found.end()
        elif rest[:1] in ("(", "["):
            depth, index = 0, position
            while index < end:
                char = text[index]
                if char in "'\"":
                    close = text.find(char, index + 1)
                    if close < 0:
                        return None
                    index = close
                elif char in "([":
                    depth += 1
                elif char in ")]":
                    depth -= 1
                    if depth == 0:
                        break
                index += 1
            if depth != 0:
                return None
            position = index + 1
        else:
            return position


def plan(
    dialect: scxml_expr.Dialect | None,
    data: Sequence[Declared],
    assignments: Sequence[Assignment],
    guards: Sequence[str],
    sends: Sequence[SendExpr],
    descriptors: Sequence[str],
    used: set[int],
) -> DataPlan:
    """Decide which variables are tracked, which conds computed, which sends exact.

    Args:
        dialect: The data model's dialect (``None``: a data model fsmbt does not read).
        data: The declarations, in document order (``<cs:var>`` ones included).
        assignments: Every ``<assign>`` and ``<cs:var>``, in document order.
        guards: The distinct cond texts (index = guard index).
        sends: Every ``<send eventexpr>``.
        descriptors: Every transition's event descriptors (normalised tokens).
        used: The guards whose value can matter (of transitions, and of ``<if>`` elements
            with effects): only these make variables relevant or refuse the document.

    Returns:
        The plan.

    Raises:
        Refusal: An input cond reads a variable an assignment changes, or an ``eventexpr``
            is neither exact nor unobservable.
    """
    result = DataPlan(dialect)
    result.declared = {d.name for d in data}
    parsed: dict[str, scxml_expr.Expr | None] = {}  # assignment / data text -> parse
    if dialect is not None:
        candidates = _candidates(dialect, data, parsed)
        result.tracked = _tracked(dialect, candidates, assignments, parsed)
    guard_exprs: dict[int, scxml_expr.Expr] = {}
    for index, text in enumerate(guards):
        expr = _parse(text, dialect, parsed)
        if expr is not None and scxml_expr.EVENT_NAME not in expr.names:
            if expr.names <= result.tracked:
                guard_exprs[index] = expr
    result.computed = guard_exprs
    for index, text in enumerate(guards):
        if index in guard_exprs or index not in used:
            continue
        for name in _IDENT.findall(text):
            changes = [a for a in assignments if _root(a.location) == name]
            if not changes:
                continue
            if name not in result.tracked:
                a, why = _why_untracked(name, changes, result, dialect, parsed)
                raise Refusal(
                    f"unsupported: <assign> to '{name}', which a guard reads ('{text}'), {why}, "
                    f"line {a.line}",
                    a.line,
                )
            a = changes[0]
            raise Refusal(
                f"unsupported: the guard '{text}' is outside fsmbt's expression subset and "
                f"reads '{name}', which the <assign> at line {a.line} changes",
                a.line,
            )
    for index, send in enumerate(sends):
        expr = _parse(send.text, dialect or scxml_expr.ECMASCRIPT, parsed)
        if (
            expr is not None
            and _event_name_last(expr)
            and expr.names - {scxml_expr.EVENT_NAME} <= result.tracked
        ):
            result.sends[index] = expr
            continue
        prefix = literal_prefix(send.text)
        if (
            prefix is not None
            and not may_match_prefix(descriptors, prefix)
            and not matches_error_execution(descriptors)
        ):
            result.dropped_sends.add(index)
            continue
        raise Refusal(
            f'unsupported: <send eventexpr="{send.text}"> (its event name is not computable '
            "exactly, and an event descriptor may match it)",
            send.line,
        )
    result.relevant = _relevant(data, assignments, result, parsed, used)
    relevant = set(result.relevant)
    changed = {a.location for a in assignments}
    result.varying = [name for name in result.relevant if name in changed]
    for index, a in enumerate(assignments):
        if a.location in relevant:
            expr = parsed.get(a.expr or "")
            assert expr is not None  # tracked: every assignment parses
            result.assigns[index] = expr
    for declared in data:
        if declared.name not in relevant:
            continue
        expr = parsed.get(declared.expr or "") if declared.expr is not None else None
        if declared.expr is None:
            result.initial[declared.name] = (
                None if dialect is not scxml_expr.ECMASCRIPT else scxml_expr.UNDEFINED
            )
        elif expr is not None:
            try:
                result.initial[declared.name] = scxml_expr.evaluate(
                    expr, result.initial, lambda _state: False
                )
            except scxml_expr.ExpressionError as exc:
                raise Refusal(
                    f"unsupported: <data id='{declared.name}'>: {exc}", declared.line
                ) from None
    for index, text in enumerate(guards):
        if index in used and _reads_data(text):
            result.reads_data = result.reads_data or f"the cond '{text}' reads the data model"
    for index, expr in result.sends.items():
        if expr.names - {scxml_expr.EVENT_NAME}:
            result.reads_data = (
                result.reads_data or f"the eventexpr '{sends[index].text}' reads the data model"
            )
    return result


def _why_untracked(
    name: str,
    changes: list[Assignment],
    result: DataPlan,
    dialect: scxml_expr.Dialect | None,
    parsed: dict[str, scxml_expr.Expr | None],
) -> tuple[Assignment, str]:
    """The assignment that keeps ``name`` from being tracked, and why."""
    if dialect is None:
        return changes[0], "in a data model fsmbt does not read"
    if name not in result.declared:
        return changes[0], "of a variable no <data> declares"
    for a in changes:
        if a.location.strip() != name:
            return a, f"to the member location '{a.location}'"
        expr = _parse(a.expr, dialect, parsed)
        if expr is None:
            return a, f"of an expression outside fsmbt's subset ('{a.expr}')"
        if not expr.names <= result.tracked:
            return a, f"of an expression reading a variable fsmbt does not track ('{a.expr}')"
    return changes[0], "of a variable whose <data> value is outside fsmbt's subset"


def _reads_data(text: str) -> bool:
    """Whether a cond reads the data model (anything but ``In()``, literals, ``_event``)."""
    try:
        expr = scxml_expr.parse(text)
    except scxml_expr.ExpressionError:
        return True
    return bool(expr.names - {scxml_expr.EVENT_NAME})


def _parse(
    text: str | None,
    dialect: scxml_expr.Dialect | None,
    cache: dict[str, scxml_expr.Expr | None],
) -> scxml_expr.Expr | None:
    if text is None or dialect is None:
        return None
    if text not in cache:
        try:
            cache[text] = scxml_expr.parse(text, dialect)
        except scxml_expr.ExpressionError:
            cache[text] = None
    return cache[text]


def _candidates(
    dialect: scxml_expr.Dialect,
    data: Sequence[Declared],
    parsed: dict[str, scxml_expr.Expr | None],
) -> set[str]:
    out: set[str] = set()
    for declared in data:
        if declared.has_content:
            continue
        if declared.expr is None:
            out.add(declared.name)
            continue
        expr = _parse(declared.expr, dialect, parsed)
        if expr is not None and expr.names <= out:
            out.add(declared.name)
    return out


def _tracked(
    dialect: scxml_expr.Dialect,
    candidates: set[str],
    assignments: Sequence[Assignment],
    parsed: dict[str, scxml_expr.Expr | None],
) -> set[str]:
    tracked = set(candidates)
    changed = True
    while changed:
        changed = False
        for a in assignments:
            root = _root(a.location)
            if root not in tracked:
                continue
            expr = _parse(a.expr, dialect, parsed)
            if a.location != root or expr is None or not expr.names <= tracked:
                tracked.discard(root)  # a member location (``x.y``) changes ``x`` too
                changed = True
    return tracked


def _root(location: str) -> str:
    """The variable a location names (``x`` of ``x.y[0]``)."""
    found = _IDENT.match(location.strip())
    return found.group(0) if found else location


def _event_name_last(expr: scxml_expr.Expr) -> bool:
    """``_event.name`` absent, or the last operand of a top-level ``+`` (or the whole)."""
    if scxml_expr.EVENT_NAME not in expr.names:
        return True
    postfix = expr.postfix
    uses = [i for i, item in enumerate(postfix) if item == ("name", scxml_expr.EVENT_NAME)]
    last = len(postfix) - 1
    if len(uses) != 1:
        return False
    return uses[0] == last or (uses[0] == last - 1 and postfix[last] == ("binary", "+"))


def _relevant(
    data: Sequence[Declared],
    assignments: Sequence[Assignment],
    result: DataPlan,
    parsed: dict[str, scxml_expr.Expr | None],
    used: set[int],
) -> list[str]:
    wanted: set[str] = set()
    computed = [e for i, e in result.computed.items() if i in used]
    for expr in [*computed, *result.sends.values()]:
        wanted |= expr.names & result.tracked
    size = -1
    while size != len(wanted):  # grows monotonically within the tracked variables
        size = len(wanted)
        for a in assignments:
            found = parsed.get(a.expr or "")
            if a.location in wanted and found is not None:
                wanted |= found.names & result.tracked
        for declared in data:
            found = parsed.get(declared.expr or "")
            if declared.name in wanted and found is not None:
                wanted |= found.names & result.tracked
    order: list[str] = []
    for declared in data:
        if declared.name in wanted and declared.name not in order:
            order.append(declared.name)
    return order


def limit_error(
    limit: int, limit_name: str, env_name: str, valuations: Iterable[dict[str, scxml_expr.Value]]
) -> StateLimitError:
    """The state-limit error of a data-valued exploration, naming the variable that took the
    most distinct values (the unbounded one, in practice)."""
    seen: dict[str, set[scxml_expr.Value]] = {}
    for valuation in valuations:
        for name, value in valuation.items():
            seen.setdefault(name, set()).add(value)
    hint = ""
    if seen:
        name = max(seen, key=lambda n: len(seen[n]))
        hint = f"; the variable '{name}' took {len(seen[name])} distinct values (is it unbounded?)"
    return StateLimitError(
        f"more than {limit} reachable configurations and data values{hint} "
        f"(limit {limit_name}; raise it with {env_name})"
    )
