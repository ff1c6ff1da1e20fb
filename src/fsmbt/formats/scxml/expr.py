"""A small, safe expression language for SCXML data models (docs/formats/scxml.md, "Data").

Read, never executed as code: literals (numbers, quoted strings, the dialect's ``true`` /
``false`` / ``null`` spellings), identifiers (variables), ``_event.name``, ``In('id')``,
``empty(x)`` (jexl), unary ``!``/``-``/``+``/``not``, and the binary operators ``* / %``,
``+ -``, ``< <= > >=`` (jexl's ``lt le gt ge``), ``== != === !==`` (``eq ne``),
``&&``/``and``, ``||``/``or``, with parentheses. Anything else (member access, calls,
``_event.data``) does not parse (``ExpressionError``).

Values follow the dialect (``Dialect``: ecmascript, jexl, python) where the subset is exact,
and an operation whose result the dialect would compute by a coercion fsmbt does not model
(``'5' * 2``, ``1 / 0``, ``undefined + 1``, comparing a string with a number) raises
``OutsideSubset``: the caller refuses the document with the expression's line instead of
guessing. What the dialect itself reports as an error (reading an undeclared variable in
ECMAScript or Python, ``_event`` before any event) raises ``ExecutionError``: W3C 5.9/5.10 make
it ``error.execution`` (a guard is then false, the rest of the block is skipped).

Parsing is the shunting-yard algorithm (no recursion), evaluation a stack machine over the
postfix form: O(length) each.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any


class _Undefined:
    """ECMAScript's ``undefined`` (a ``<data>`` without a value)."""

    _instance: _Undefined | None = None

    def __new__(cls) -> _Undefined:
        if cls._instance is None:
            cls._instance = super().__new__(cls)
        return cls._instance

    def __repr__(self) -> str:
        return "undefined"

    def __hash__(self) -> int:
        return 0x5C5C

    def __eq__(self, other: object) -> bool:
        return other is self


UNDEFINED = _Undefined()
Value = int | float | str | bool | None | _Undefined
#: Integers past this lose exactness as ECMAScript numbers (2**53).
MAX_SAFE_INTEGER = 2**53

_TOKEN = re.compile(
    r"""\s*(?:(?P<num>\d+(?:\.\d+)?)|(?P<str>'[^']*'|"[^"]*")|"""
    r"""(?P<event>_event\.name\b)|"""
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
#: The name ``_event.name`` takes in ``Expr.names``.
EVENT_NAME = "_event.name"


class ExpressionError(ValueError):
    """The text is not in the language, or its value cannot be computed."""


class OutsideSubset(ExpressionError):
    """The dialect would compute a value by a rule fsmbt does not model (a coercion)."""


class ExecutionError(ExpressionError):
    """The dialect itself fails here: W3C's ``error.execution``."""


@dataclass(frozen=True)
class Dialect:
    """How one data model spells and computes the subset.

    Attributes:
        name: ``ecmascript``, ``jexl`` or ``python``.
        constants: literal words and their values.
        words: whether ``and``/``or``/``not``/``lt``/... are operators.
        undeclared_is_null: reading an undeclared variable gives ``null`` (jexl) instead of an
            error (ECMAScript ``ReferenceError``, Python ``NameError``).
        functions: the functions of one argument the dialect has (``In``, jexl's ``empty``).
        string_plus_number: ``'a' + 1`` joins (ECMAScript, jexl) instead of failing (Python).
    """

    name: str
    constants: Mapping[str, Value]
    words: bool
    undeclared_is_null: bool
    functions: frozenset[str]
    string_plus_number: bool


ECMASCRIPT = Dialect(
    "ecmascript",
    {"true": True, "false": False, "null": None, "undefined": UNDEFINED},
    False,
    False,
    frozenset({"In"}),
    True,
)
JEXL = Dialect(
    "jexl",
    {"true": True, "false": False, "null": None},
    True,
    True,
    frozenset({"In", "empty"}),
    True,
)
PYTHON = Dialect(
    "python", {"True": True, "False": False, "None": None}, True, False, frozenset({"In"}), False
)
#: Every spelling at once: what ``parse`` reads without a dialect (tests, tools).
ANY = Dialect(
    "any",
    {**ECMASCRIPT.constants, **PYTHON.constants},
    True,
    False,
    frozenset({"In", "empty"}),
    True,
)
_DIALECTS = {"ecmascript": ECMASCRIPT, "jexl": JEXL, "python": PYTHON}


def dialect_of(datamodel: str | None) -> Dialect | None:
    """The dialect of a ``datamodel`` attribute (absent: ECMAScript, the data model of the
    W3C examples and of SCION); ``None`` for a data model fsmbt does not read (``null``,
    ``xpath``, ``cplusplus:...``)."""
    if datamodel is None or not datamodel.strip():
        return ECMASCRIPT
    return _DIALECTS.get(datamodel.strip().lower())


@dataclass(frozen=True)
class Expr:
    """A parsed expression: its postfix form, the identifiers it reads, its dialect."""

    text: str
    postfix: tuple[tuple[str, object], ...]
    names: frozenset[str]
    dialect: Dialect = ANY


def parse(text: str, dialect: Dialect = ANY) -> Expr:
    """Parse ``text`` (see module docstring).

    Args:
        text: An expression.
        dialect: The data model's spelling (default: every spelling).

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
        if not expect_operand and (
            found.group("num") or found.group("str") or found.group("event")
        ):
            raise ExpressionError("two operands in a row")
        if found.group("num") is not None:
            number = found.group("num")
            out.append(("value", float(number) if "." in number else int(number)))
            expect_operand = False
            continue
        if found.group("str") is not None:
            out.append(("value", found.group("str")[1:-1]))
            expect_operand = False
            continue
        if found.group("event") is not None:
            out.append(("name", EVENT_NAME))
            names.add(EVENT_NAME)
            expect_operand = False
            continue
        token = found.group("op") or found.group("name") or ""
        if found.group("name") is not None and dialect.words:
            token = _WORDS.get(token, token)
        is_word = found.group("name") is not None and token in _WORDS.values()
        if found.group("name") is not None and not is_word:
            if not expect_operand:
                raise ExpressionError("two operands in a row")
            if token in dialect.constants:
                out.append(("value", dialect.constants[token]))
            elif token in dialect.functions:
                if not text[position:].lstrip().startswith("("):
                    raise ExpressionError(f"'{token}' without its argument")
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
    return Expr(text, tuple(out), frozenset(names), dialect)


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


def evaluate(
    expr: Expr,
    data: Mapping[str, Value],
    in_state: Callable[[str], bool],
    event_name: str | None = None,
) -> Value:
    """The value of ``expr``.

    Args:
        expr: A parsed expression.
        data: The variables' values (the declared variables).
        in_state: ``In(id)``.
        event_name: ``_event.name`` (``None``: no event processed yet).

    Returns:
        The value, computed as the expression's dialect computes it.

    Raises:
        ExecutionError: The dialect fails (an undeclared variable, no ``_event`` yet).
        OutsideSubset: The dialect would coerce in a way fsmbt does not model.
    """
    dialect = expr.dialect
    stack: list[Value] = []
    for kind, item in expr.postfix:
        if kind == "value":
            stack.append(item)  # type: ignore[arg-type]
        elif kind == "name":
            name = str(item)
            if name == EVENT_NAME:
                if event_name is None:
                    raise ExecutionError("_event is not bound before the first event")
                stack.append(event_name)
            elif name in data:
                stack.append(data[name])
            elif dialect.undeclared_is_null:
                stack.append(None)
            else:
                raise ExecutionError(f"'{name}' is not declared")
        elif kind == "call":
            argument = stack.pop()
            if item == "In":
                if not isinstance(argument, str):
                    raise OutsideSubset("In() of a value that is not a string")
                stack.append(in_state(argument))
            else:  # jexl's empty(): null or the empty string
                stack.append(argument is None or argument is UNDEFINED or argument == "")
        elif kind == "unary":
            operand = stack.pop()
            if item == "!":
                stack.append(not truthy(operand))
            else:
                number = _number(operand, dialect, str(item))
                stack.append(-number if item == "-" else number)
        else:
            right, left = stack.pop(), stack.pop()
            stack.append(_binary(str(item), left, right, dialect))
    return stack[-1]


def _kind(value: Value) -> str:
    if value is None:
        return "null"
    if value is UNDEFINED:
        return "undefined"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    return "string"


def _number(value: Value, dialect: Dialect, op: str) -> int | float:
    """A numeric operand: numbers, and booleans (``true + 1`` is 2 in every dialect)."""
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, (int, float)):
        return value
    raise OutsideSubset(f"'{op}' on {_kind(value)} (a coercion fsmbt does not model)")


def _exact(number: int | float, op: str) -> int | float:
    if isinstance(number, float):
        if math.isnan(number) or math.isinf(number):
            raise OutsideSubset(f"'{op}' gives {number} (outside fsmbt's subset)")
        if number.is_integer():
            number = int(number)
    if isinstance(number, int) and abs(number) > MAX_SAFE_INTEGER:
        raise OutsideSubset(f"'{op}' gives {number}, past exact numbers (2**53)")
    return number


def _binary(op: str, left: Value, right: Value, dialect: Dialect) -> Value:
    if op == "&&":
        return right if truthy(left) else left
    if op == "||":
        return left if truthy(left) else right
    kinds = (_kind(left), _kind(right))
    if op in ("===", "!=="):
        same = kinds[0] == kinds[1] and left == right
        return same if op == "===" else not same
    if op in ("==", "!="):
        return _loose_equal(left, right, kinds) == (op == "==")
    if op == "+" and "string" in kinds:
        if kinds != ("string", "string") and not dialect.string_plus_number:
            raise OutsideSubset("'+' of a string and a value that is not one")
        return _check_length(f"{text_of(left)}{text_of(right)}")
    if op in ("<", "<=", ">", ">="):
        if kinds == ("string", "string"):
            a: Any = left
            b: Any = right
        else:
            a, b = _number(left, dialect, op), _number(right, dialect, op)
        return {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b}[op]
    x, y = _number(left, dialect, op), _number(right, dialect, op)
    if op in ("/", "%") and y == 0:
        raise OutsideSubset(f"'{op}' by zero (outside fsmbt's subset)")
    if op == "+":
        return _exact(x + y, op)
    if op == "-":
        return _exact(x - y, op)
    if op == "*":
        return _exact(x * y, op)
    if op == "/":
        if dialect is JEXL and isinstance(x, int) and isinstance(y, int) and x % y:
            raise OutsideSubset("jexl's integer division with a remainder")
        return _exact(x / y, op)
    # '%': ECMAScript and jexl (Java) take the dividend's sign, Python the divisor's
    return _exact(x % y if dialect is PYTHON else math.fmod(x, y), op)


def _loose_equal(left: Value, right: Value, kinds: tuple[str, str]) -> bool:
    absent = {"null", "undefined"}
    if kinds[0] in absent or kinds[1] in absent:
        return kinds[0] in absent and kinds[1] in absent
    if kinds[0] == kinds[1] or set(kinds) == {"number", "boolean"}:
        return left == right
    raise OutsideSubset("'==' of a string and a value that is not one (a coercion)")


#: The longest string value fsmbt keeps (a string that keeps growing is refused).
MAX_STRING = 10_000


def _check_length(text: str) -> str:
    if len(text) > MAX_STRING:
        raise OutsideSubset(f"a string longer than {MAX_STRING} characters")
    return text


def text_of(value: Value) -> str:
    """A value as ECMAScript writes it (``true``, ``null``, ``3``, ``0.5``)."""
    if value is True or value is False:
        return "true" if value else "false"
    if value is None:
        return "null"
    if value is UNDEFINED:
        return "undefined"
    if isinstance(value, float):
        if value.is_integer():
            return str(int(value))
        if not 1e-6 <= abs(value) < 1e21:
            raise OutsideSubset(f"the text of {value!r} (exponent notation)")
        return repr(value)
    return str(value)


def shown(value: Value) -> str:
    """A value as a state name shows it: ``text_of``, or Python's ``repr`` where ECMAScript
    would write an exponent (never an error)."""
    try:
        return text_of(value)
    except OutsideSubset:
        return repr(value)


def truthy(value: Value) -> bool:
    """The truth of a value (the same in the three dialects for the subset's values)."""
    if value is UNDEFINED or value is None:
        return False
    return bool(value)
