"""python-statemachine classes, read statically, and written (docs/formats/pystatemachine.md).

Reading parses the file with ``ast`` (``pysm.source.parse_source``): nothing is imported or
run. The machine is the first class deriving from ``StateMachine`` or ``StateChart`` (option
``machine`` names another). In its body:
- ``x = State(...)`` is state ``x`` (``initial=True``: the initial state, else the first one
  declared; ``final=True``: final; ``name=`` / the first argument, ``value=``, ``enter=``,
  ``exit=`` kept as ``pystatemachine.*`` attributes); its action is the one entry callback
  ``enter="name"`` names, else its id (final ones too);
- ``ev = <transitions>`` makes the transitions events ``ev``, where ``<transitions>`` joins with
  ``|``: ``a.to(b, ...)``, ``a.to.itself()``, ``b.from_(a, ...)``, ``b.from_.any()`` (every
  non-final state), optionally wrapped in ``Event(..., name=...)``; ``event="e1 e2"`` adds
  events; a ``<transitions>`` statement not assigned to a name is eventless (taken as soon as
  its source is entered, python-statemachine 3's rule, fsmbt's completion transition);
- of several transitions of one event from one state the first declared is taken (the library
  takes the first whose conditions hold; here there are none), later ones are dropped with a
  warning; an event a state has no transition for is ignored (the library raises
  ``TransitionNotAllowed`` unless ``allow_event_without_transition``: a warning says so).
Refused at their line: ``cond``/``unless``/``validators`` (guards), ``internal=True``,
``State.Compound`` / ``State.Parallel`` (nested classes), a transition from a final state, and
code that runs when the file is imported or the class is defined (a call that is not a
declaration, at module level or in the class body): nothing is executed, ever.

Writing produces the class (a state whose action is not its id gets ``enter="action"``: the
callback is the user's to write; identifiers only; hierarchical machines are flattened first by
``translate --flatten``). Costs: O(n) syntax nodes / O(S + T).
"""

from __future__ import annotations

import ast
import json
import keyword
import re

from fsmbt.formats.pysm.source import NotStatic, last_name, literal, parse_source
from fsmbt.formats.registry import ReadContext
from fsmbt.model import Model
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.model.fsm import FSM, State

_BASES = frozenset({"StateMachine", "StateChart"})
_GUARDS = ("cond", "unless", "validators")
A_PREFIX = "pystatemachine."
#: Module-level calls that declare rather than run (allowed outside functions).
_DECLARATIONS = frozenset({"State", "Event"})


class _Reader:
    def __init__(self, text: str, ctx: ReadContext) -> None:
        self.ctx = ctx
        self.name = ctx.display_name
        self.tree = parse_source(text, self.name)

    def where(self, node: ast.AST) -> SourceLocation:
        return SourceLocation(self.name, getattr(node, "lineno", None))

    def refuse(self, node: ast.AST, what: str) -> UnsupportedError:
        return UnsupportedError(what, location=self.where(node))

    def read(self) -> FSM:
        self.check_import_time()
        classes = [
            c
            for c in self.tree.body
            if isinstance(c, ast.ClassDef) and any(last_name(b) in _BASES for b in c.bases)
        ]
        if not classes:
            raise InputError(
                "no class deriving from StateMachine or StateChart in this file",
                location=SourceLocation(self.name),
            )
        wanted = self.ctx.options.get("machine")
        chosen = classes[0]
        if wanted is not None:
            named = [c for c in classes if c.name == wanted]
            if not named:
                raise InputError(
                    f"no StateMachine class '{wanted}' (found: "
                    f"{', '.join(c.name for c in classes)})",
                    location=SourceLocation(self.name),
                )
            chosen = named[0]
        elif len(classes) > 1:
            self.ctx.warn(
                f"{len(classes)} StateMachine classes; read '{chosen.name}' (choose one with "
                "the 'machine' option)"
            )
        return self.machine(chosen)

    def check_import_time(self) -> None:
        """Refuse code that would run on import or class definition (never run here)."""
        bodies: list[tuple[list[ast.stmt], str]] = [(self.tree.body, "module level")]
        for node in self.tree.body:
            if isinstance(node, ast.ClassDef):
                bodies.append((node.body, f"the body of class {node.name}"))
        for body, where in bodies:
            for stmt in body:
                if isinstance(stmt, ast.If) and _is_main_guard(stmt.test):
                    continue
                if isinstance(
                    stmt,
                    (
                        ast.Import,
                        ast.ImportFrom,
                        ast.FunctionDef,
                        ast.AsyncFunctionDef,
                        ast.ClassDef,
                        ast.Pass,
                    ),
                ):
                    continue
                if isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant):
                    continue
                if isinstance(stmt, (ast.Assign, ast.AnnAssign, ast.Expr)):
                    value = stmt.value
                    calls = [n for n in ast.walk(value) if isinstance(n, ast.Call)] if value else []
                    if all(_declaring(c) for c in calls):
                        continue
                    bad = next(c for c in calls if not _declaring(c))
                    raise InputError(
                        f"code that runs when the file is imported: {ast.unparse(bad.func)}(...) "
                        f"in {where}; fsmbt reads declarations only and runs nothing",
                        location=self.where(bad),
                    )
                raise InputError(
                    f"code that runs when the file is imported: a {type(stmt).__name__.lower()} "
                    f"statement in {where}; fsmbt reads declarations only and runs nothing",
                    location=self.where(stmt),
                )

    def machine(self, cls: ast.ClassDef) -> FSM:
        fsm = FSM(name=cls.name)
        declared: dict[str, ast.AST] = {}
        initial: str | None = None
        allow_ignored = False
        events: list[tuple[list[str], ast.expr, int]] = []  # (events, expression, line)
        for stmt in cls.body:
            if isinstance(stmt, ast.ClassDef):
                raise self.refuse(
                    stmt,
                    f"nested class '{stmt.name}' (State.Compound / State.Parallel): "
                    "compound and parallel states are not read from python-statemachine yet",
                )
            if (
                isinstance(stmt, ast.Assign)
                and len(stmt.targets) == 1
                and isinstance(stmt.targets[0], ast.Name)
            ):
                target = stmt.targets[0].id
                value = stmt.value
                if isinstance(value, ast.Call) and last_name(value.func) == "State":
                    state = self.state(target, value)
                    fsm.states[target] = state
                    declared[target] = stmt
                    if _flag(value, "initial"):
                        if initial is not None:
                            raise InputError(
                                f"two initial states ('{initial}' and '{target}')",
                                location=self.where(stmt),
                            )
                        initial = target
                elif target == "allow_event_without_transition":
                    allow_ignored = isinstance(value, ast.Constant) and value.value is True
                elif _is_transitions(value):
                    events.append(([target], value, stmt.lineno))
            elif isinstance(stmt, ast.Expr) and _is_transitions(stmt.value):
                events.append(([], stmt.value, stmt.lineno))
        if not fsm.states:
            raise InputError(f"class {cls.name} declares no State", location=self.where(cls))
        fsm.initial = initial or next(iter(fsm.states))
        taken: set[tuple[str, str | None]] = set()
        for names, expression, line in events:
            for source, target, extra in self.transitions(expression, fsm):
                chosen: list[str | None] = [*names, *extra]
                for event in chosen or [None]:
                    if fsm.states[source].final:
                        raise InputError(
                            f"a transition out of final state '{source}'",
                            location=SourceLocation(self.name, line),
                        )
                    if (source, event) in taken:
                        self.ctx.warn(
                            f"'{event or 'eventless'}' from '{source}' has an earlier "
                            "transition, which python-statemachine takes; this one is dropped",
                            line,
                        )
                        continue
                    taken.add((source, event))
                    fsm.add_transition(
                        source, event, target, location=SourceLocation(self.name, line)
                    )
        if not allow_ignored:
            self.ctx.warn(
                "an event the current state has no transition for raises TransitionNotAllowed "
                "in python-statemachine (allow_event_without_transition is not set); fsmbt "
                "reads it as ignored"
            )
        return fsm

    def state(self, target: str, call: ast.Call) -> State:
        attrs: dict[str, str] = {}
        for index, arg in enumerate(call.args[:2]):
            key = ("name", "value")[index]
            attrs[A_PREFIX + key] = self.text(arg)
        for kw in call.keywords:
            if kw.arg in ("name", "value", "enter", "exit"):
                attrs[A_PREFIX + kw.arg] = self.text(kw.value)
            elif kw.arg in ("initial", "final"):
                if not isinstance(kw.value, ast.Constant) or not isinstance(kw.value.value, bool):
                    raise self.refuse(kw.value, f"{kw.arg}= is not True or False")
            elif kw.arg in ("parallel", "states", "history"):
                raise self.refuse(
                    call,
                    f"State({kw.arg}=...): compound and parallel states "
                    "are not read from python-statemachine yet",
                )
            else:
                raise InputError(f"State() has no argument '{kw.arg}'", location=self.where(kw))
        final = _flag(call, "final")
        enter = next((kw.value for kw in call.keywords if kw.arg == "enter"), None)
        action = target
        if isinstance(enter, ast.Constant) and isinstance(enter.value, str):
            action = enter.value  # one named entry callback: the action it runs
        return State(
            target,
            action=action,
            final=final,
            attrs=attrs,
            location=self.where(call),
        )

    def text(self, node: ast.expr) -> str:
        try:
            value = literal(node)
        except NotStatic:
            return ast.unparse(node)
        return value if isinstance(value, str) else json.dumps(value)

    def transitions(self, expression: ast.expr, fsm: FSM) -> list[tuple[str, str, list[str]]]:
        """``(source, target, extra events)`` of a ``|``-joined expression (explicit stack)."""
        out: list[tuple[str, str, list[str]]] = []
        stack: list[ast.expr] = [expression]
        while stack:
            node = stack.pop()
            if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitOr):
                stack.extend([node.right, node.left])
                continue
            if isinstance(node, ast.Call) and last_name(node.func) == "Event":
                inner = node.args[0] if node.args else None
                if inner is None:
                    raise self.refuse(node, "Event() without transitions")
                stack.append(inner)
                continue
            out.extend(self.one_call(node, fsm))
        return out

    def one_call(self, node: ast.expr, fsm: FSM) -> list[tuple[str, str, list[str]]]:
        if not isinstance(node, ast.Call):
            raise self.refuse(node, f"'{ast.unparse(node)}' is not a transition declaration")
        extra: list[str] = []
        for kw in node.keywords:
            if kw.arg in _GUARDS:
                raise self.refuse(node, f"{kw.arg}=: guards are not in fsmbt's model")
            if kw.arg == "internal":
                if isinstance(kw.value, ast.Constant) and kw.value.value is True:
                    raise self.refuse(
                        node,
                        "internal=True: an internal transition enters no state, which "
                        "fsmbt's transitions always do",
                    )
            elif kw.arg == "event":
                value = self.text(kw.value)
                extra.extend(value.split())
            elif kw.arg not in ("on", "before", "after", "internal"):
                raise InputError(f"unknown transition argument '{kw.arg}'", location=self.where(kw))
        func = node.func
        # a.to(b, c) / a.to.itself() / b.from_(a) / b.from_.any()
        if isinstance(func, ast.Attribute) and func.attr in ("to", "from_"):
            owner = self.state_name(func.value, fsm)
            others = [self.state_name(a, fsm) for a in node.args]
            if func.attr == "to":
                return [(owner, other, extra) for other in others]
            return [(other, owner, extra) for other in others]
        if (
            isinstance(func, ast.Attribute)
            and isinstance(func.value, ast.Attribute)
            and func.value.attr in ("to", "from_")
        ):
            owner = self.state_name(func.value.value, fsm)
            if func.value.attr == "to" and func.attr == "itself":
                return [(owner, owner, extra)]
            if func.value.attr == "from_" and func.attr == "any":
                return [(s.name, owner, extra) for s in fsm.states.values() if not s.final]
        raise self.refuse(node, f"'{ast.unparse(node)}' is not a transition declaration")

    def state_name(self, node: ast.expr, fsm: FSM) -> str:
        if isinstance(node, ast.Name) and node.id in fsm.states:
            return node.id
        raise self.refuse(node, f"'{ast.unparse(node)}' is not a State declared before it")


def _declaring(call: ast.Call) -> bool:
    name = last_name(call.func)
    if name in _DECLARATIONS:
        return True
    func = call.func
    return isinstance(func, ast.Attribute) and (
        func.attr in ("to", "from_", "itself", "any")
        or (isinstance(func.value, ast.Attribute) and func.value.attr in ("to", "from_"))
    )


def _is_transitions(node: ast.expr) -> bool:
    stack = [node]
    while stack:
        current = stack.pop()
        if isinstance(current, ast.BinOp) and isinstance(current.op, ast.BitOr):
            stack.extend([current.left, current.right])
        elif isinstance(current, ast.Call) and (
            last_name(current.func) == "Event" or _declaring(current)
        ):
            if last_name(current.func) == "State":
                return False
            continue
        else:
            return False
    return True


def _flag(call: ast.Call, name: str) -> bool:
    return any(
        kw.arg == name and isinstance(kw.value, ast.Constant) and kw.value.value is True
        for kw in call.keywords
    )


def _is_main_guard(test: ast.expr) -> bool:
    return (
        isinstance(test, ast.Compare)
        and isinstance(test.left, ast.Name)
        and test.left.id == "__name__"
        and len(test.comparators) == 1
        and isinstance(test.comparators[0], ast.Constant)
        and test.comparators[0].value == "__main__"
    )


def read_pystatemachine(text: str, ctx: ReadContext) -> FSM:
    """Read a python-statemachine class statically (see the module docstring)."""
    return _Reader(text, ctx).read()


# -- writing ------------------------------------------------------------------------------------
def write_pystatemachine(model: Model) -> str:
    """A python-statemachine class for a flat FSM (see the module docstring)."""
    if not isinstance(model, FSM):
        raise UnsupportedError("python-statemachine holds state machines, not behavior trees")
    if model.is_hierarchical:
        raise UnsupportedError("composite or parallel states (flatten first)")
    if model.start_name is not None:
        raise UnsupportedError("a start pseudo-state left on an initial event")
    if model.initial is None:
        raise UnsupportedError("the machine has no initial state")
    for name in [*model.states, *model.events()]:
        if not name.isidentifier() or keyword.iskeyword(name) or name.startswith("_"):
            raise UnsupportedError(
                f"'{name}' is not a Python identifier that python-statemachine can use "
                "as a state or an event"
            )
    clash = set(model.states) & set(model.events())
    if clash:
        raise UnsupportedError(f"names used for a state and an event: {', '.join(sorted(clash))}")
    cls = model.name  # the class name is the machine's name, where Python allows it
    if not cls.isidentifier() or keyword.iskeyword(cls) or cls in ("State", "StateMachine"):
        cls = "".join(p[:1].upper() + p[1:] for p in re.split(r"[^A-Za-z0-9_]+", cls) if p)
        if not cls.isidentifier() or keyword.iskeyword(cls) or cls in ("State", "StateMachine"):
            cls = "Machine"
    lines = [
        '"""Written by fsmbt: the states and events of the model; the actions are yours."""',
        "",
        "from statemachine import State, StateMachine",
        "",
        "",
        f"class {cls}(StateMachine):",
        "    allow_event_without_transition = True",
        "    # fsmbt's models may have states that end nowhere or that nothing reaches",
        "    validate_trap_states = False",
        "    validate_final_reachability = False",
        "    validate_disconnected_states = False",
        "",
    ]
    for state in model.states.values():
        flags = []
        if state.name == model.initial:
            flags.append("initial=True")
        if state.final:
            flags.append("final=True")
        if state.action is not None and state.action != state.name:
            if not state.action.isidentifier() or keyword.iskeyword(state.action):
                raise UnsupportedError(
                    f"state '{state.name}' runs '{state.action}', which is not a Python "
                    "identifier a python-statemachine entry callback can be named"
                )
            flags.append(f"enter={state.action!r}")
        lines.append(f"    {state.name} = State({', '.join(flags)})")
    lines.append("")
    by_event: dict[str | None, list[str]] = {}
    for t in model.transitions:
        part = f"{t.source}.to.itself()" if t.source == t.target else f"{t.source}.to({t.target})"
        by_event.setdefault(t.event, []).append(part)
    for event, parts in by_event.items():
        if event is None:
            lines.extend(f"    {part}" for part in parts)
        else:
            lines.append(f"    {event} = {' | '.join(parts)}")
    return "\n".join(lines) + "\n"
