"""fsmbt's expression subset (docs/semantics.md §6a: literals, names, ``==``, ``!=``, ``<``,
``<=``, ``>``, ``>=``, ``and``, ``or``, ``not``, ``x + 1``) compiled once to a Python evaluator,
for the checkers that step a data machine many times (``verify/pernode.py``,
``verify/lazy_fsm.py``). ``formats/scxml/expr.py`` reads every data model W3C allows; these
checkers read only what fsmbt's converters write, and refuse the rest.

Why ``eval`` is safe here: the parsed tree is checked node by node against a closed list of
node kinds (no call, attribute, subscript, comprehension or lambda), and the code runs with no
builtins, over an environment of the machine's own variables.

Cost: one parse and one walk per distinct text (callers cache); evaluation is Python's.
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Mapping
from typing import Any

from fsmbt.model.fsm_data import SUBSET_NODES

#: The subset without ``-`` (``subtract=False``): fsmbt's converters write only ``x + 1``.
_NO_SUBTRACT = tuple(kind for kind in SUBSET_NODES if kind is not ast.Sub)

Evaluator = Callable[[dict[str, Any]], Any]


class OutsideSubset(ValueError):
    """The text does not parse, or holds a construct outside the subset."""


class ForeignName(ValueError):
    """The text reads a name the renaming does not cover (``name``)."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


def compile_subset(
    text: str, *, rename: Mapping[str, str] | None = None, subtract: bool = False
) -> tuple[str, Evaluator]:
    """``text`` as its canonical text (``ast.unparse``, after renaming) and a function that
    evaluates it over an environment of variable values.

    Args:
        text: The expression.
        rename: When given, every name read must be a key (else ``ForeignName``) and is
            replaced by its value (a canonical variable name).
        subtract: Also allow ``-`` between two operands.

    Raises:
        OutsideSubset: a syntax error or a node kind outside the subset.
        ForeignName: a name ``rename`` does not cover.
    """
    allowed = SUBSET_NODES if subtract else _NO_SUBTRACT
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        raise OutsideSubset(text) from None
    for node in ast.walk(tree):
        if not isinstance(node, allowed):
            raise OutsideSubset(text)
        if rename is not None and isinstance(node, ast.Name):
            if node.id not in rename:
                raise ForeignName(node.id)
            node.id = rename[node.id]
    code = compile(tree, "<fsmbt subset>", "eval")

    def evaluate(env: dict[str, Any], code: Any = code) -> Any:
        return eval(code, {"__builtins__": {}}, env)  # noqa: S307

    return ast.unparse(tree), evaluate
