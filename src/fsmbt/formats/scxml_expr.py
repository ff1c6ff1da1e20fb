"""A small, safe expression language for SCXML data models (docs/formats/scxml.md, "Data").

Read, never executed as code: literals (numbers, quoted strings, ``true``/``false``/``null``),
identifiers (``<data>`` ids), ``In('id')``, ``empty(x)``, unary ``!``/``-``/``not``, and the
binary operators ``* / %``, ``+ -``, ``< <= > >=`` (and jexl's ``lt le gt ge``),
``== != === !==`` (``eq ne``), ``&&``/``and``, ``||``/``or``, with parentheses. It covers the
ECMAScript, jexl and python expressions simple state machines use; anything else (member
access, calls, ``_event``) does not parse, and the document is then read with guards as inputs
of the environment. Parsing is the shunting-yard algorithm (no recursion), evaluation a stack
machine over the postfix form: O(length) each.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

Value = int | float | str | bool | None

_TOKEN = re.compile(
    r"""\s*(?:(?P<num>\d+(?:\.\d+)?)|(?P<str>'[^']*'|"[^"]*")|"""
    r"""(?P<op>===|!==|==|!=|>=|<=|&&|\|\||[-+*/%<>!(),])|"""
    r"""(?P<name>[A-Za-z_$][\w$]*))"""
)
_WORDS = {
    "and": "&&",
    "or": "||",
    "not": "!",
    "lt": "<",
    "le": "<=",
    "gt": ">",
    "ge": ">=",
    "eq": "==",
    "ne": "!=",
}
_BINARY = {
    "||": 1,
    "&&": 2,
    "==": 3,
    "!=": 3,
    "===": 3,
    "!==": 3,
    "<": 4,
    "<=": 4,
    ">": 4,
    ">=": 4,
    "+": 5,
    "-": 5,
    "*": 6,
    "/": 6,
    "%": 6,
}
_UNARY_PRECEDENCE = 7
_FUNCTIONS = frozenset({"In", "empty"})
_CONSTANTS: dict[str, Value] = {
    "true": True,
    "false": False,
    "null": None,
    "True": True,
    "False": False,
    "None": None,
}


class ExpressionError(ValueError):
    """The text is not in the language, or its value cannot be computed."""


@dataclass(frozen=True)
class Expr:
    """A parsed expression: its postfix form and the identifiers it reads."""

    text: str
    postfix: tuple[tuple[str, object], ...]
    names: frozenset[str]


def parse(text: str) -> Expr:
    """Parse ``text`` (see module docstring).

    Args:
        text: An expression.

    Returns:
        The parsed expression.

    Raises:
        ExpressionError: The text is not in the language.
    """
    out: list[tuple[str, object]] = []
    ops: list[tuple[str, object]] = []
    names: set[str] = set()
    position, expect_operand = 0, True
    text_length = len(text.rstrip())
    while position < text_length:
        found = _TOKEN.match(text, position)
        if found is None or found.end() == position:
            raise ExpressionError(f"cannot read {text[position : position + 20]!r}")
        position = found.end()
        if found.group("num") is not None:
            number = found.group("num")
            out.append(("value", float(number) if "." in number else int(number)))
            expect_operand = False
            continue
        if found.group("str") is not None:
            out.append(("value", found.group("str")[1:-1]))
            expect_operand = False
            continue
        token = found.group("op") or found.group("name") or ""
        token = _WORDS.get(token, token)
        if found.group("name") is not None and token not in _WORDS.values():
            if token in _CONSTANTS:
                out.append(("value", _CONSTANTS[token]))
            elif token in _FUNCTIONS:
                ops.append(("call", token))
            else:
                out.append(("name", token))
                names.add(token)
            expect_operand = False
            continue
        if token == "(":
            ops.append(("(", None))
            expect_operand = True
        elif token == ")":
            while ops and ops[-1][0] != "(":
                out.append(ops.pop())
            if not ops:
                raise ExpressionError("unbalanced ')'")
            ops.pop()
            if ops and ops[-1][0] == "call":
                out.append(ops.pop())
            expect_operand = False
        elif token == ",":
            raise ExpressionError("functions of several arguments are not read")
        elif expect_operand and token in ("!", "-", "+"):
            ops.append(("unary", token))
        elif token in _BINARY and not expect_operand:
            precedence = _BINARY[token]
            while (
                ops
                and ops[-1][0] in ("binary", "unary")
                and (_UNARY_PRECEDENCE if ops[-1][0] == "unary" else _BINARY[str(ops[-1][1])])
                >= precedence
            ):
                out.append(ops.pop())
            ops.append(("binary", token))
            expect_operand = True
        else:
            raise ExpressionError(f"unexpected {token!r}")
    while ops:
        if ops[-1][0] == "(":
            raise ExpressionError("unbalanced '('")
        out.append(ops.pop())
    if not out or expect_operand:
        raise ExpressionError("incomplete expression")
    _check_arity(out)
    return Expr(text, tuple(out), frozenset(names))


def _check_arity(postfix: list[tuple[str, object]]) -> None:
    depth = 0
    for kind, _value in postfix:
        if kind in ("value", "name"):
            depth += 1
        elif kind == "binary":
            depth -= 1
        if depth < 1:
            raise ExpressionError("malformed expression")
    if depth != 1:
        raise ExpressionError("malformed expression")


def evaluate(expr: Expr, data: Mapping[str, Value], in_state: Callable[[str], bool]) -> Value:
    """The value of ``expr``.

    Args:
        expr: A parsed expression.
        data: The variables' values.
        in_state: ``In(id)``.

    Returns:
        The value (ECMAScript-like: ``+`` joins strings, ``===`` compares type and value).

    Raises:
        ExpressionError: An unknown variable, a type error, a division by zero.
    """
    stack: list[Value] = []
    try:
        for kind, item in expr.postfix:
            if kind == "value":
                stack.append(item)  # type: ignore[arg-type]
            elif kind == "name":
                if item not in data:
                    raise ExpressionError(f"unknown variable '{item}'")
                stack.append(data[str(item)])
            elif kind == "call":
                argument = stack.pop()
                stack.append(
                    in_state(str(argument)) if item == "In" else argument in (None, "", 0, False)
                )
            elif kind == "unary":
                operand: Any = stack.pop()  # a number here, or the operator raises below
                if item == "!":
                    stack.append(not _truthy(operand))
                else:
                    stack.append(-operand if item == "-" else +operand)
            else:
                right, left = stack.pop(), stack.pop()
                stack.append(_binary(str(item), left, right))
    except (TypeError, ZeroDivisionError, IndexError) as exc:
        raise ExpressionError(f"cannot evaluate '{expr.text}': {exc}") from None
    return stack[-1]


def _truthy(value: Value) -> bool:
    return bool(value)


def _binary(op: str, left: Value, right: Value) -> Value:
    if op == "&&":
        return right if _truthy(left) else left
    if op == "||":
        return left if _truthy(left) else right
    if op == "===":
        return type(left) is type(right) and left == right
    if op == "!==":
        return not (type(left) is type(right) and left == right)
    if op == "==":
        return left == right
    if op == "!=":
        return left != right
    if op == "+" and (isinstance(left, str) or isinstance(right, str)):
        return f"{_text(left)}{_text(right)}"
    a: Any = left  # operands of mixed types fail here with TypeError, which the caller reports
    b: Any = right
    result = {
        "<": lambda: a < b,
        "<=": lambda: a <= b,
        ">": lambda: a > b,
        ">=": lambda: a >= b,
        "+": lambda: a + b,
        "-": lambda: a - b,
        "*": lambda: a * b,
        "/": lambda: a / b,
        "%": lambda: a % b,
    }[op]()
    if isinstance(result, float) and result.is_integer() and op != "/":
        return int(result)
    return result  # type: ignore[no-any-return]


def _text(value: Value) -> str:
    if value is True or value is False:
        return "true" if value else "false"
    return "null" if value is None else str(value)


def text_of(value: Value) -> str:
    """A value as ECMAScript writes it (``true``, ``null``, ``3``)."""
    return _text(value)


def truthy(value: Value) -> bool:
    """ECMAScript-like truth of a value."""
    return _truthy(value)
