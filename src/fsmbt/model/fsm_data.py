"""Data kept by an FSM: the SCXML data model as the IR holds it (docs/semantics.md, "Data in
state machines").

A compact BT -> FSM conversion keeps a behavior tree's memory (retry counts, running indices,
remembered statuses) as variables instead of states. The IR keeps them in the format-specific
``attrs`` the model already has, under keys no format uses for anything else:

- ``FSM.attrs[DATAMODEL]`` on the top machine: the declarations, one ``name=expr`` per line
  (SCXML ``<datamodel><data id="name" expr="expr"/>``); its presence marks the machine as
  keeping data;
- ``Transition.attrs[COND]``: the guard (SCXML ``cond``), an expression of
  ``fsmbt.formats.scxml.expr`` over the variables;
- ``Transition.attrs[ASSIGN]``: the updates, one ``name=expr`` per line (``<assign>``), run when
  the transition is taken;
- ``State.attrs[ONEXIT]``: updates run when the state is left (``<onexit><assign>``).

Meaning (the only one): the W3C SCXML algorithm, with the ``python`` data model (the one
python-statemachine evaluates, so its engine runs the file as written; fsmbt's expression
subset reads it exactly: ``==``, ``<=``, ``>=``, ``and``, ``or``, literals, ``x + 1``) - the
transitions of a state on one event are tried in document order and the first whose guard holds
is taken. A machine with data is never flattened by ``fsmbt.model.flatten``'s own rules (they
know nothing of data): its flat meaning is the SCXML reader's exact expansion (configurations x
variable values), which the formats layer registers here (``register_expander``), so the model
layer needs no import from above. Cost of ``has_data``: O(1).
"""

from __future__ import annotations

import ast
import importlib
import re
from collections.abc import Callable

from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM, State

#: Keys in ``attrs`` (they contain no character an XML attribute name may hold alone).
DATAMODEL = "fsmbt:datamodel"
COND = "cond"
ASSIGN = "fsmbt:assign"
ONEXIT = "fsmbt:onexit"
#: The data model dialect the expressions are written in.
DIALECT = "python"

#: The Python syntax-tree node kinds of the expressions fsmbt writes (literals, names,
#: comparisons, ``and``/``or``/``not``, unary minus, ``+`` and ``-``): what the readers that
#: compile such an expression to Python (the SMACH writer's userdata code, the checkers'
#: evaluators in ``verify/subset_expr.py``) accept, node by node, and nothing else.
SUBSET_NODES: tuple[type[ast.AST], ...] = (
    ast.Expression,
    ast.Name,
    ast.Load,
    ast.Constant,
    ast.Compare,
    ast.Eq,
    ast.NotEq,
    ast.Lt,
    ast.LtE,
    ast.Gt,
    ast.GtE,
    ast.BoolOp,
    ast.And,
    ast.Or,
    ast.UnaryOp,
    ast.Not,
    ast.USub,
    ast.BinOp,
    ast.Add,
    ast.Sub,
)

_expander: Callable[[FSM], FSM] | None = None
#: A word of an expression: what ``mentioned_names`` looks for.
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def has_data(fsm: FSM) -> bool:
    """Whether ``fsm`` (a top machine) declares data."""
    return DATAMODEL in fsm.attrs


def parse_lines(text: str) -> list[tuple[str, str]]:
    """``name=expr`` lines as pairs (the name is everything before the first ``=``)."""
    pairs: list[tuple[str, str]] = []
    for line in text.splitlines():
        if line.strip():
            name, _, expr = line.partition("=")
            pairs.append((name.strip(), expr.strip()))
    return pairs


def join_lines(pairs: list[tuple[str, str]]) -> str:
    """The inverse of ``parse_lines``."""
    return "\n".join(f"{name}={expr}" for name, expr in pairs)


def mentioned_names(fsm: FSM, names: set[str], skip: State | None = None) -> set[str]:
    """The ``names`` (declared variables) that ``fsm`` and the machines nested in it mention in
    any attribute of a transition or a state (its ``name`` aside): guards, assignments,
    ``onexit``, anything a format kept. ``skip``: a state whose attributes and sub-machines are
    left out. Why one function: the compositional check asks which region uses a variable, the
    lazy runner whether a block's variables are read outside it; both must read the same
    places. O(the attributes' text)."""
    found: set[str] = set()
    stack = [fsm]
    while stack:
        machine = stack.pop()
        texts = [_attribute_text(t.attrs) for t in machine.transitions]
        for state in machine.states.values():
            if state is skip:
                continue
            texts.append(_attribute_text(state.attrs))
            stack.extend(state.regions)
        for text in texts:
            found.update(word for word in _IDENT.findall(text) if word in names)
    return found


def _attribute_text(attrs: dict[str, str]) -> str:
    return " ".join(value for key, value in attrs.items() if key != "name")


def data_places(fsm: FSM, limit: int = 4) -> str:
    """Where a machine's data lives, for a loss a person can find in the machine: per variable
    (the first ``limit``) its initial value, how many guards read it and how many transitions
    or ``<onexit>`` blocks assign it, each with the first place (``path`` of the state as
    ``FSM.walk`` names it, and the event). O(states + transitions) per variable shown."""
    pairs = parse_lines(fsm.attrs.get(DATAMODEL, ""))
    reads: dict[str, list[str]] = {name: [] for name, _e in pairs}
    writes: dict[str, list[str]] = {name: [] for name, _e in pairs}
    words = {name: re.compile(rf"\b{re.escape(name)}\b") for name, _e in pairs}
    paths: dict[tuple[int, str], str] = {}
    for path, machine, state in fsm.walk():
        paths[(id(machine), state.name)] = path
        for name, _expr in parse_lines(state.attrs.get(ONEXIT, "")):
            if name in writes:
                writes[name].append(f"{path} (on exit)")
    for machine in fsm.machines():
        for t in machine.transitions:
            source = machine.states.get(t.source)
            plain = "eventless" if source is not None and source.is_atomic else "completion"
            at = f"{paths.get((id(machine), t.source), t.source)} on {t.event or plain}"
            cond = t.attrs.get(COND, "")
            for name, word in words.items():
                if word.search(cond):
                    reads[name].append(at)
            for name, _expr in parse_lines(t.attrs.get(ASSIGN, "")):
                if name in writes:
                    writes[name].append(at)
    parts = []
    for name, initial in pairs[:limit]:
        read, written = reads[name], writes[name]
        parts.append(
            f"{name} (initial {initial}; read by {len(read)} guard(s)"
            + (f", first at {read[0]}" if read else "")
            + f"; assigned {len(written)} time(s)"
            + (f", first at {written[0]}" if written else "")
            + ")"
        )
    if len(pairs) > limit:
        parts.append(f"and {len(pairs) - limit} more")
    return "; ".join(parts)


def parallel_states(fsm: FSM) -> list[str]:
    """The paths of the parallel states of ``fsm`` (any level), in ``walk`` order."""
    return [path for path, _machine, state in fsm.walk() if state.is_parallel]


def register_expander(expander: Callable[[FSM], FSM]) -> None:
    """Install the exact expansion of a machine with data into a flat FSM (the SCXML reader's
    W3C reading of the machine written as SCXML; registered by ``fsmbt.formats.scxml.structural``)."""
    global _expander
    _expander = expander


def expand(fsm: FSM) -> FSM:
    """The flat FSM a machine with data means: every reachable (configuration, valuation).

    The expander lives in the formats layer, above this one: when no caller has loaded it
    yet, it is looked up by name (``importlib``, as the web page finds the runtimes), which
    registers it.

    Raises:
        UnsupportedError: no expander could be installed.
    """
    if _expander is None:
        importlib.import_module("fsmbt.formats.scxml.structural")
    if _expander is None:
        raise UnsupportedError(
            "this state machine keeps data (an SCXML data model); reading it needs "
            "fsmbt.formats, which was not loaded",
            element=fsm.name,
        )
    return _expander(fsm)
