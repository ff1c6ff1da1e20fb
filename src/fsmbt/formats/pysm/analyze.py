"""Static reading of SMACH / FlexBE construction code into container records (no execution).

What is understood (docs/formats/smach.md, docs/formats/flexbe.md):
- container constructors: ``StateMachine``, ``Sequence``, ``Concurrence``, ``Iterator``
  (SMACH) and ``OperatableStateMachine``, ``ConcurrencyContainer``, ``PriorityContainer``
  (FlexBE), called through any import alias, bound to a name (or ``self`` in a container
  subclass's ``__init__``);
- ``with c:`` / ``with c.opened():`` opens ``c``; ``X.add(label, state, transitions, ...)`` and
  ``add_auto`` in positional and keyword forms add to the innermost open container;
  ``Iterator.set_contained_state``; ``c.set_initial_state([label])``;
- a state is a call of a class (its outcomes taken from the class's ``__init__`` when the class
  is in the file, from a table of library states, or from an ``outcomes=`` argument), a
  ``CBState`` (outcomes from ``@cb_interface``), a container, or a FlexBE
  ``self.use_behavior(Class, ...)`` (an embedded behaviour);
- literal values (labels, outcome lists, transition dicts) may come through names bound to
  literals earlier in the same function or module;
- what a state is configured with (``fsmbt.formats.pysm.params``: constructor arguments,
  the userdata keys its class declares - in the file, or through ``resolver`` in the file its
  import names -, the ROS interface of SMACH's generic states), the ``remapping=`` and the
  FlexBE editor's ``# x:.. y:..`` position of each ``add``, a container's keys and its
  ``c.userdata.k = v`` values: kept as annotations, never deciding which states exist.
Everything else that touches a container - a label or transitions computed at run time, an
``add`` in a loop or under a condition, a callback deciding outcomes - is ``UnsupportedError``
with its line. Statements are walked with an explicit stack; nothing is executed.

Costs: O(n) in the number of syntax nodes.
"""

from __future__ import annotations

import ast
import re
from collections import ChainMap
from collections.abc import Callable
from dataclasses import dataclass, field

from fsmbt.formats.pysm.params import (
    ClassDecl,
    Configured,
    class_declaration,
    configure,
    render,
    string_list,
)
from fsmbt.formats.pysm.source import NotStatic, last_name, literal, source_text
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError

SMACH_CONTAINERS = {
    "StateMachine": "sm",
    "Sequence": "sequence",
    "Concurrence": "concurrence",
    "Iterator": "iterator",
}
FLEXBE_CONTAINERS = {
    "OperatableStateMachine": "sm",
    "ConcurrencyContainer": "flexbe-concurrency",
    "PriorityContainer": "priority",
    "LockableStateMachine": "sm",
    "PreemptableStateMachine": "sm",
}
CONTAINER_CLASSES = {**SMACH_CONTAINERS, **FLEXBE_CONTAINERS}
#: Registered outcomes of library states whose source is not in the file (smach_ros).
LIBRARY_OUTCOMES: dict[str, tuple[str, ...]] = {
    "SimpleActionState": ("succeeded", "aborted", "preempted"),
    "ServiceState": ("succeeded", "aborted", "preempted"),
    "MonitorState": ("valid", "invalid", "preempted"),
    "ConditionState": ("true", "false", "preempted"),
}
_ADD_METHODS = frozenset({"add", "add_auto"})
_CONTAINER_METHODS = _ADD_METHODS | {
    "set_contained_state",
    "set_initial_state",
    "add_outcome_map",
    "set_iteritems",
    "register_outcomes",
}


@dataclass
class StateRef:
    """A leaf state: its class, outcomes when known, where it was made."""

    cls: str
    outcomes: list[str] | None
    line: int
    callback: str | None = None
    opaque_behaviour: bool = False  # an embedded behaviour whose file was not found
    config: Configured = field(default_factory=Configured)  # parameters, keys, ROS interface
    declared: list[str] | None = None  # outcomes its class declares (file or package)


@dataclass
class Embedded:
    """A FlexBE ``self.use_behavior(Class, name)``: another behaviour's state machine."""

    cls: str
    module: str | None
    line: int


@dataclass
class Child:
    """One ``add``: a label, what was added and its transitions in source order."""

    label: str
    state: StateRef | Container | Embedded
    transitions: dict[str, str | None]
    line: int
    autonomy: dict[str, str] = field(default_factory=dict)
    connectors: list[str] = field(default_factory=list)  # add_auto
    remapping: dict[str, str] = field(default_factory=dict)  # the state's key -> container's
    position: tuple[int, int] | None = None  # FlexBE editor's ``# x:.. y:..`` above the add


@dataclass
class Container:
    """One container as the code builds it."""

    cls: str
    kind: str  # sm, sequence, concurrence, iterator, flexbe-concurrency, priority
    outcomes: list[str]
    line: int
    var: str | None = None
    children: list[Child] = field(default_factory=list)
    initial: str | None = None
    initial_line: int | None = None
    parent: Container | None = None
    # Sequence
    connector: str | None = None
    # Concurrence / ConcurrencyContainer
    default_outcome: str | None = None
    outcome_map: list[tuple[str, dict[str, str]]] = field(default_factory=list)
    #: SMACH ``outcome_cb`` / ``child_termination_cb`` -> the callback's source text (user code
    #: fsmbt never runs; docs/semantics.md §11, "Concurrence callbacks")
    callbacks: dict[str, str] = field(default_factory=dict)
    # Iterator
    items: int | None = None  # static number of items, None = computed at run time
    items_text: str = ""
    loop_outcomes: list[str] = field(default_factory=list)
    break_outcomes: list[str] = field(default_factory=list)
    final_outcome_map: dict[str, str] = field(default_factory=dict)
    exhausted_outcome: str = "exhausted"
    contained_line: int | None = None
    blocker: UnsupportedError | None = None  # raised only if this container is read
    labels: set[str] = field(default_factory=set)
    inputs: list[str] = field(default_factory=list)  # input_keys
    outputs: list[str] = field(default_factory=list)  # output_keys
    userdata: dict[str, str] = field(default_factory=dict)  # ``c.userdata.k = v``: k -> text
    # YASMIN OrthogonalState: JoinState barriers, each a list of (region label, state in it)
    sync_groups: list[list[tuple[str, str]]] = field(default_factory=list)

    @property
    def name(self) -> str:
        return self.var or f"{self.cls}@{self.line}"


@dataclass
class Analysis:
    """Everything one file builds."""

    containers: list[Container]
    behaviours: dict[str, Container | None]  # FlexBE Behavior class -> container create() returns
    imports: dict[str, str]  # local name -> dotted module path it was imported from
    warnings: list[tuple[int | None, str]] = field(default_factory=list)
    extension: dict[str, object] = field(default_factory=dict)  # ``__fsmbt__`` (written by fsmbt)


@dataclass(frozen=True)
class _Ctx:
    env: ChainMap[str, object]
    opened: tuple[Container, ...]
    loop_line: int | None
    cond_line: int | None
    behaviour: str | None  # the Behavior class whose create() this is
    self_container: Container | None


#: Finds a state class imported from another module: ``(module path, class name)`` -> what
#: its ``__init__`` declares, or ``None`` (the builder looks in the ROS package, never runs it).
ClassResolver = Callable[[str, str], ClassDecl | None]
_POSITION = re.compile(r"#\s*x:\s*(-?\d+)\s+y:\s*(-?\d+)\s*$")


class Analyzer:
    """Walks one module; ``run`` gives the containers it builds."""

    def __init__(
        self, text: str, tree: ast.Module, name: str, resolver: ClassResolver | None = None
    ) -> None:
        self.text = text
        self.tree = tree
        self.name = name
        self.resolver = resolver
        self.lines = text.splitlines()
        self.class_decls: dict[str, ClassDecl] = {}
        self.containers: list[Container] = []
        self.behaviours: dict[str, Container | None] = {}
        self.imports: dict[str, str] = {}
        self.aliases: dict[str, str] = {}  # local name -> original class name
        self.class_outcomes: dict[str, list[str]] = {}
        self.class_bases: dict[str, list[str]] = {}
        self.class_defs: dict[str, ast.ClassDef] = {}
        self.callback_outcomes: dict[str, list[str]] = {}
        self.subclass_containers: dict[str, Container] = {}
        self.warnings: list[tuple[int | None, str]] = []

    # -- errors -------------------------------------------------------------------------------
    def where(self, node: ast.AST | int | None) -> SourceLocation:
        line = node if isinstance(node, int) or node is None else getattr(node, "lineno", None)
        return SourceLocation(self.name, line)

    def unsupported(self, node: ast.AST | int | None, what: str) -> UnsupportedError:
        return UnsupportedError(what, location=self.where(node))

    def invalid(self, node: ast.AST | int | None, what: str) -> InputError:
        return InputError(what, location=self.where(node))

    # -- entry ----------------------------------------------------------------------------------
    def run(self) -> Analysis:
        self.collect_definitions()
        self.walk(self.tree.body, _Ctx(ChainMap(), (), None, None, None, None))
        return Analysis(
            self.containers, self.behaviours, self.imports, self.warnings, self.extension()
        )

    def extension(self) -> dict[str, object]:
        """The module-level ``__fsmbt__ = {...}`` literal the SMACH writer adds, if any."""
        for stmt in self.tree.body:
            if (
                isinstance(stmt, ast.Assign)
                and len(stmt.targets) == 1
                and isinstance(stmt.targets[0], ast.Name)
                and stmt.targets[0].id == "__fsmbt__"
            ):
                try:
                    value = literal(stmt.value)
                except NotStatic:
                    value = None
                if isinstance(value, dict) and value.get("version") == 1:
                    return {str(k): v for k, v in value.items()}
                self.warnings.append(
                    (
                        stmt.lineno,
                        "__fsmbt__ is not a version-1 literal dict written by fsmbt; ignored",
                    )
                )
        return {}

    def collect_definitions(self) -> None:
        """Imports, state classes with their outcomes, ``@cb_interface`` callbacks (a walk over
        statements only: definitions and imports are statements, expressions need no visit)."""
        for node in _statements(self.tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                for alias in node.names:
                    local = alias.asname or alias.name
                    self.imports[local] = f"{node.module}.{alias.name}"
                    self.aliases[local] = alias.name
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    self.imports[alias.asname or alias.name.split(".")[0]] = alias.name
            elif isinstance(node, ast.ClassDef):
                self.class_defs.setdefault(node.name, node)
                self.class_decls.setdefault(node.name, class_declaration(node))
                self.class_bases[node.name] = [b for b in (last_name(x) for x in node.bases) if b]
                outcomes = self.init_outcomes(node)
                if outcomes is not None:
                    self.class_outcomes.setdefault(node.name, outcomes)
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for decorator in node.decorator_list:
                    if (
                        isinstance(decorator, ast.Call)
                        and last_name(decorator.func) == "cb_interface"
                    ):
                        found = self.keyword_literal(decorator, "outcomes")
                        if isinstance(found, list):
                            self.callback_outcomes[node.name] = [str(o) for o in found]

    def init_outcomes(self, cls: ast.ClassDef) -> list[str] | None:
        """Outcomes passed to the base ``__init__`` in the class's own ``__init__``."""
        for item in cls.body:
            if isinstance(item, ast.FunctionDef) and item.name == "__init__":
                for node in ast.walk(item):
                    if (
                        isinstance(node, ast.Call)
                        and isinstance(node.func, ast.Attribute)
                        and node.func.attr == "__init__"
                    ):
                        found = self.keyword_literal(node, "outcomes")
                        if found is None:
                            for arg in node.args:
                                try:
                                    value = literal(arg)
                                except NotStatic:
                                    continue
                                if isinstance(value, list) and all(
                                    isinstance(v, str) for v in value
                                ):
                                    found = value
                                    break
                        if isinstance(found, (list, tuple)):
                            return [str(o) for o in found]
        return None

    def keyword_literal(self, call: ast.Call, name: str) -> object:
        for keyword in call.keywords:
            if keyword.arg == name:
                try:
                    return literal(keyword.value)
                except NotStatic:
                    return None
        return None

    def outcomes_of_class(self, cls: str) -> list[str] | None:
        seen: set[str] = set()
        current: str | None = cls
        while current is not None and current not in seen:
            seen.add(current)
            if current in self.class_outcomes:
                return list(self.class_outcomes[current])
            original = self.aliases.get(current, current)
            if original in LIBRARY_OUTCOMES:
                return list(LIBRARY_OUTCOMES[original])
            bases = self.class_bases.get(current, [])
            current = bases[0] if bases else None
        return None

    def container_kind(self, name: str | None) -> str | None:
        """The container kind of a class name (through import aliases and in-file subclasses)."""
        if name is None:
            return None
        original = self.aliases.get(name, name)
        if original in CONTAINER_CLASSES:
            return CONTAINER_CLASSES[original]
        return None

    def subclass_kind(self, name: str) -> str | None:
        seen: set[str] = set()
        current = name
        while current in self.class_bases and current not in seen:
            seen.add(current)
            for base in self.class_bases[current]:
                kind = self.container_kind(base)
                if kind is not None:
                    return kind
            bases = self.class_bases[current]
            current = bases[0] if bases else ""
        return None

    # -- statements ---------------------------------------------------------------------------
    def walk(self, body: list[ast.stmt], ctx: _Ctx) -> None:
        stack: list[tuple[ast.stmt, _Ctx]] = [(s, ctx) for s in reversed(body)]
        while stack:
            stmt, ctx = stack.pop()
            pushed = self.statement(stmt, ctx)
            stack.extend(reversed(pushed))

    def statement(self, stmt: ast.stmt, ctx: _Ctx) -> list[tuple[ast.stmt, _Ctx]]:
        line = stmt.lineno
        if isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef)):
            behaviour = ctx.behaviour if stmt.name == "create" else None
            inner = _Ctx(ctx.env.new_child(), (), None, None, behaviour, ctx.self_container)
            return [(s, inner) for s in stmt.body]
        if isinstance(stmt, ast.ClassDef):
            bases = self.class_bases.get(stmt.name, [])
            if "Behavior" in [self.aliases.get(b, b) for b in bases]:
                self.behaviours.setdefault(stmt.name, None)
                inner = _Ctx(ctx.env.new_child(), (), None, None, stmt.name, None)
                return [(s, inner) for s in stmt.body]
            if self.subclass_kind(stmt.name) is not None:
                return []  # read when instantiated (see ``subclass_container``)
            inner = _Ctx(ctx.env.new_child(), (), None, None, None, None)
            return [(s, inner) for s in stmt.body if isinstance(s, (ast.FunctionDef, ast.ClassDef))]
        if isinstance(stmt, ast.With | ast.AsyncWith):
            opened = list(ctx.opened)
            for item in stmt.items:
                container = self.opened_container(item.context_expr, ctx)
                if container is not None:
                    if ctx.loop_line is not None:
                        raise self.unsupported(
                            stmt,
                            f"a container opened in a loop (line "
                            f"{ctx.loop_line}): how often it is "
                            "filled is decided at run time",
                        )
                    opened.append(container)
            inner = _Ctx(
                ctx.env,
                tuple(opened),
                ctx.loop_line,
                ctx.cond_line,
                ctx.behaviour,
                ctx.self_container,
            )
            return [(s, inner) for s in stmt.body]
        if isinstance(stmt, (ast.For, ast.AsyncFor, ast.While)):
            inner = _Ctx(
                ctx.env,
                ctx.opened,
                ctx.loop_line or line,
                ctx.cond_line,
                ctx.behaviour,
                ctx.self_container,
            )
            return [(s, inner) for s in [*stmt.body, *stmt.orelse]]
        if isinstance(stmt, ast.If):
            if _is_main_guard(stmt):
                return []  # what runs as a script is not the state machine's construction
            inner = _Ctx(
                ctx.env,
                ctx.opened,
                ctx.loop_line,
                ctx.cond_line or line,
                ctx.behaviour,
                ctx.self_container,
            )
            return [(s, inner) for s in [*stmt.body, *stmt.orelse]]
        if isinstance(stmt, ast.Try | ast.TryStar):
            cond = _Ctx(
                ctx.env,
                ctx.opened,
                ctx.loop_line,
                ctx.cond_line or line,
                ctx.behaviour,
                ctx.self_container,
            )
            out = [(s, ctx) for s in stmt.body]
            for handler in stmt.handlers:
                out.extend((s, cond) for s in handler.body)
            out.extend((s, ctx) for s in [*stmt.orelse, *stmt.finalbody])
            return out
        if isinstance(stmt, ast.Match):
            cond = _Ctx(
                ctx.env,
                ctx.opened,
                ctx.loop_line,
                ctx.cond_line or line,
                ctx.behaviour,
                ctx.self_container,
            )
            return [(s, cond) for case in stmt.cases for s in case.body]
        if isinstance(stmt, ast.Assign):
            value = self.expression(stmt.value, ctx, stmt)
            for target in stmt.targets:
                if not self.userdata_assignment(target, stmt.value, ctx):
                    self.bind(target, value, ctx, stmt.value)
            return []
        if isinstance(stmt, ast.AnnAssign) and stmt.value is not None:
            self.bind(stmt.target, self.expression(stmt.value, ctx, stmt), ctx, stmt.value)
            return []
        if isinstance(stmt, ast.Expr):
            self.expression(stmt.value, ctx, stmt)
            return []
        if isinstance(stmt, ast.Return) and stmt.value is not None:
            value = self.expression(stmt.value, ctx, stmt)
            if ctx.behaviour is not None and isinstance(value, Container):
                self.behaviours[ctx.behaviour] = value
            return []
        return []

    def bind(self, target: ast.expr, value: object, ctx: _Ctx, source: ast.expr) -> None:
        key = _target_key(target)
        if key is None:
            return
        if value is _UNKNOWN:
            try:
                value = literal(source, lambda n: self.lookup_literal(n, ctx))
            except NotStatic:
                value = _UNKNOWN
        if isinstance(value, Container) and value.var is None:
            value.var = key
        if ctx.loop_line is not None or ctx.cond_line is not None:
            if isinstance(value, Container | StateRef):
                ctx.env[key] = value
            else:
                ctx.env[key] = _UNKNOWN  # its value depends on which branch / iteration ran
            return
        ctx.env[key] = value

    def userdata_assignment(self, target: ast.expr, value: ast.expr, ctx: _Ctx) -> bool:
        """``c.userdata.key = v`` / ``c.userdata['key'] = v`` on a container: the key's initial
        value (its literal text, or the expression's source) is kept on the container."""
        if isinstance(target, ast.Attribute):
            holder, key = target.value, target.attr
        elif (
            isinstance(target, ast.Subscript)
            and isinstance(target.slice, ast.Constant)
            and isinstance(target.slice.value, str)
        ):
            holder, key = target.value, target.slice.value
        else:
            return False
        if not (isinstance(holder, ast.Attribute) and holder.attr == "userdata"):
            return False
        container = self.value_of(holder.value, ctx)
        if not isinstance(container, Container):
            return False
        container.userdata[key] = render(value, self.text, lambda n: self.lookup_literal(n, ctx))[0]
        return True

    def lookup(self, name: str, ctx: _Ctx) -> object:
        return ctx.env[name]

    def lookup_literal(self, name: str, ctx: _Ctx) -> object:
        value = self.lookup(name, ctx)
        if value is _UNKNOWN or isinstance(value, Container | StateRef | Embedded):
            raise KeyError(name)
        return value

    def value_of(self, node: ast.expr, ctx: _Ctx) -> object:
        """A name or ``self.x`` bound earlier, else ``_UNKNOWN``."""
        key = _target_key(node)
        if key is None:
            return _UNKNOWN
        if key == "self" and ctx.self_container is not None:
            return ctx.self_container
        try:
            return self.lookup(key, ctx)
        except KeyError:
            return _UNKNOWN

    def opened_container(self, expr: ast.expr, ctx: _Ctx) -> Container | None:
        if (
            isinstance(expr, ast.Call)
            and isinstance(expr.func, ast.Attribute)
            and expr.func.attr == "opened"
            and not expr.args
        ):
            expr = expr.func.value
        value = self.value_of(expr, ctx)
        return value if isinstance(value, Container) else None

    # -- expressions --------------------------------------------------------------------------
    def expression(self, expr: ast.expr, ctx: _Ctx, stmt: ast.stmt) -> object:
        """Containers made, states made, container calls done by ``expr`` (its value)."""
        if isinstance(expr, ast.Call):
            func = expr.func
            if isinstance(func, ast.Attribute) and func.attr in _CONTAINER_METHODS:
                receiver = func.value
                receiver_value = self.value_of(receiver, ctx)
                if (
                    isinstance(receiver_value, Container)
                    or self.container_kind(last_name(receiver)) is not None
                ):
                    target = receiver_value if isinstance(receiver_value, Container) else None
                    return self.container_call(func.attr, expr, target, ctx)
            name = last_name(func)
            kind = self.container_kind(name)
            if kind is not None and name is not None:
                return self.new_container(name, kind, expr, ctx, stmt)
            if name is not None and self.subclass_kind(name) is not None:
                return self.subclass_container(name, expr)
        if isinstance(expr, ast.Name | ast.Attribute):
            return self.value_of(expr, ctx)
        return _UNKNOWN

    def guard_static(self, node: ast.AST, ctx: _Ctx, what: str) -> None:
        if ctx.loop_line is not None:
            raise self.unsupported(
                node,
                f"{what} in a loop (line {ctx.loop_line}): which "
                "states exist is decided at run time",
            )
        if ctx.cond_line is not None:
            raise self.unsupported(
                node,
                f"{what} under a condition (line {ctx.cond_line}): "
                "which states exist is decided at run time",
            )

    def new_container(
        self, cls: str, kind: str, call: ast.Call, ctx: _Ctx, stmt: ast.stmt
    ) -> Container:
        self.guard_static(call, ctx, f"a {cls} created")
        args = self.bind_args(call, _CONSTRUCTOR_PARAMS[self.aliases.get(cls, cls)])
        outcomes = self.string_list(args.get("outcomes"), ctx, call, "the container's outcomes")
        container = Container(self.aliases.get(cls, cls), kind, outcomes, call.lineno)
        container.inputs = string_list(args.get("input_keys"), None) or []
        container.outputs = string_list(args.get("output_keys"), None) or []
        if kind == "sequence":
            container.connector = self.string(
                args.get("connector_outcome"), ctx, call, "the connector outcome"
            )
        elif kind == "concurrence":
            self.concurrence_options(container, args, ctx, call)
        elif kind == "flexbe-concurrency":
            self.flexbe_conditions(container, args.get("conditions"), ctx, call)
        elif kind == "iterator":
            self.iterator_options(container, args, ctx, call)
        self.containers.append(container)
        return container

    def subclass_container(self, cls: str, call: ast.Call) -> Container:
        """A class deriving from a container: its ``__init__`` builds it (read once)."""
        if cls in self.subclass_containers:
            return self.subclass_containers[cls]
        definition = self.class_defs[cls]
        kind = self.subclass_kind(cls) or "sm"
        init = next(
            (s for s in definition.body if isinstance(s, ast.FunctionDef) and s.name == "__init__"),
            None,
        )
        if init is None:
            raise self.unsupported(call, f"container class '{cls}' without __init__")
        base_call = next(
            (
                n
                for n in ast.walk(init)
                if isinstance(n, ast.Call)
                and isinstance(n.func, ast.Attribute)
                and n.func.attr == "__init__"
            ),
            None,
        )
        if base_call is None:
            raise self.unsupported(
                init,
                f"container class '{cls}': its base __init__ call (with the outcomes) is not found",
            )
        base = next(
            (b for b in self.class_bases.get(cls, []) if self.container_kind(b)), "StateMachine"
        )
        original = self.aliases.get(base, base)
        args = list(base_call.args)
        if args and isinstance(args[0], ast.Name) and args[0].id == "self":
            args = args[1:]
        fake = ast.Call(
            func=ast.Name(id=base, ctx=ast.Load()), args=args, keywords=base_call.keywords
        )
        ast.copy_location(fake, base_call)
        ctx0 = _Ctx(ChainMap(), (), None, None, None, None)
        container = self.new_container(original, kind, fake, ctx0, init)
        container.var = cls
        self.subclass_containers[cls] = container
        inner = _Ctx(ChainMap(), (), None, None, None, container)
        self.walk(
            [s for s in init.body if not (isinstance(s, ast.Expr) and s.value is base_call)], inner
        )
        return container

    def bind_args(self, call: ast.Call, params: tuple[str, ...]) -> dict[str, ast.expr]:
        out: dict[str, ast.expr] = {}
        for index, arg in enumerate(call.args):
            if isinstance(arg, ast.Starred):
                raise self.unsupported(
                    arg, "arguments passed with * unpacking (known only at run time)"
                )
            if index >= len(params):
                raise self.invalid(
                    arg, f"too many positional arguments to {last_name(call.func)}()"
                )
            out[params[index]] = arg
        for keyword in call.keywords:
            if keyword.arg is None:
                raise self.unsupported(
                    keyword.value, "arguments passed with ** unpacking (known only at run time)"
                )
            out[keyword.arg] = keyword.value
        return out

    # literal helpers
    def static(self, node: ast.expr, ctx: _Ctx, what: str) -> object:
        try:
            return literal(node, lambda n: self.lookup_literal(n, ctx))
        except NotStatic as exc:
            raise self.unsupported(
                exc.node, f"{what} is {exc.what} ('{source_text(self.text, node, 80)}')"
            ) from None

    def string(self, node: ast.expr | None, ctx: _Ctx, call: ast.AST, what: str) -> str:
        if node is None:
            raise self.invalid(call, f"{what} is missing")
        value = self.static(node, ctx, what)
        if not isinstance(value, str):
            raise self.invalid(node, f"{what} must be a string, not {value!r}")
        return value

    def string_list(self, node: ast.expr | None, ctx: _Ctx, call: ast.AST, what: str) -> list[str]:
        if node is None:
            raise self.invalid(call, f"{what} are missing")
        value = self.static(node, ctx, what)
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            raise self.invalid(node, f"{what} must be a list of strings")
        return [str(v) for v in value]

    def concurrence_options(
        self, container: Container, args: dict[str, ast.expr], ctx: _Ctx, call: ast.Call
    ) -> None:
        for callback in ("outcome_cb", "child_termination_cb"):
            node = args.get(callback)
            if node is not None and not (isinstance(node, ast.Constant) and node.value is None):
                # never run: read as an environment choice (docs/semantics.md §11)
                container.callbacks[callback] = ast.unparse(node)[:80]
        container.default_outcome = self.string(
            args.get("default_outcome"), ctx, call, "the Concurrence default_outcome"
        )
        node = args.get("outcome_map")
        if node is None:
            return
        mapping = self.static(node, ctx, "the Concurrence outcome_map")
        if not isinstance(mapping, dict):
            raise self.invalid(node, "the Concurrence outcome_map must be a dict")
        for outcome, children in mapping.items():
            if (
                not isinstance(outcome, str)
                or not isinstance(children, dict)
                or not all(isinstance(k, str) and isinstance(v, str) for k, v in children.items())
            ):
                raise self.invalid(
                    node,
                    "the Concurrence outcome_map must map each container "
                    "outcome to {child label: child outcome}",
                )
            container.outcome_map.append((outcome, dict(children)))

    def flexbe_conditions(
        self, container: Container, node: ast.expr | None, ctx: _Ctx, call: ast.Call
    ) -> None:
        if node is None:
            return
        value = self.static(node, ctx, "the ConcurrencyContainer conditions")
        if isinstance(value, dict):
            items: list[object] = list(value.items())
        elif isinstance(value, (list, tuple)):
            items = list(value)
        else:
            raise self.invalid(
                node,
                "ConcurrencyContainer conditions must be a list of "
                "(outcome, [(state, outcome), ...])",
            )
        for item in items:
            if (
                not isinstance(item, (list, tuple))
                or len(item) != 2
                or not isinstance(item[0], str)
                or not isinstance(item[1], (list, tuple))
            ):
                raise self.invalid(
                    node,
                    "ConcurrencyContainer conditions must be a list of "
                    "(outcome, [(state, outcome), ...])",
                )
            pairs: dict[str, str] = {}
            for pair in item[1]:
                if (
                    not isinstance(pair, (list, tuple))
                    or len(pair) != 2
                    or not all(isinstance(p, str) for p in pair)
                ):
                    raise self.invalid(
                        node,
                        "a ConcurrencyContainer condition is a list of "
                        "(state label, outcome) pairs",
                    )
                pairs[pair[0]] = pair[1]
            container.outcome_map.append((item[0], pairs))

    def iterator_options(
        self, container: Container, args: dict[str, ast.expr], ctx: _Ctx, call: ast.Call
    ) -> None:
        if "exhausted_outcome" in args:
            container.exhausted_outcome = self.string(
                args["exhausted_outcome"], ctx, call, "the Iterator exhausted_outcome"
            )
        if container.exhausted_outcome not in container.outcomes:
            container.outcomes.append(container.exhausted_outcome)  # as SMACH does
        self.iterator_items(container, args.get("it"), ctx)

    def iterator_items(self, container: Container, node: ast.expr | None, ctx: _Ctx) -> None:
        if node is None:
            container.items = 0
            return
        container.items_text = source_text(self.text, node, 80)
        count = _static_count(node, lambda n: self.lookup_literal(n, ctx))
        container.items = count

    def container_call(
        self, method: str, call: ast.Call, target: Container | None, ctx: _Ctx
    ) -> object:
        if method in ("add_outcome_map", "set_iteritems", "register_outcomes"):
            self.guard_static(call, ctx, f"{method}()")
            container = self.current(call, ctx, target if method != "set_iteritems" else None)
            if method == "add_outcome_map":
                raise self.unsupported(
                    call, "Concurrence.add_outcome_map (give the outcome_map to the constructor)"
                )
            if method == "set_iteritems":
                args = self.bind_args(call, ("it", "it_label"))
                self.iterator_items(container, args.get("it"), ctx)
                return _UNKNOWN
            args = self.bind_args(call, ("outcomes",))
            container.outcomes.extend(
                o
                for o in self.string_list(args.get("outcomes"), ctx, call, "the outcomes")
                if o not in container.outcomes
            )
            return _UNKNOWN
        if method == "set_initial_state":
            self.guard_static(call, ctx, "set_initial_state()")
            container = target if target is not None else self.current(call, ctx, None)
            args = self.bind_args(call, ("initial_states", "userdata"))
            labels = self.string_list(args.get("initial_states"), ctx, call, "the initial states")
            if len(labels) != 1:
                raise self.invalid(
                    call,
                    "set_initial_state needs exactly one label for a "
                    f"state machine (got {len(labels)})",
                )
            container.initial = labels[0]
            container.initial_line = call.lineno
            return _UNKNOWN
        self.guard_static(call, ctx, "a state added")
        container = self.current(call, ctx, None)
        if method == "set_contained_state":
            return self.set_contained(container, call, ctx)
        return self.add(container, method, call, ctx)

    def current(self, call: ast.Call, ctx: _Ctx, fallback: Container | None) -> Container:
        if ctx.opened:
            return ctx.opened[-1]
        if fallback is not None:
            return fallback
        raise self.invalid(
            call,
            f"{last_name(call.func)}() outside a 'with container:' block "
            "(SMACH/FlexBE add to the container opened by 'with')",
        )

    def add(self, container: Container, method: str, call: ast.Call, ctx: _Ctx) -> object:
        if container.kind == "iterator":
            raise self.invalid(
                call, "an Iterator holds one state, set with Iterator.set_contained_state"
            )
        if container.kind == "concurrence":
            params: tuple[str, ...] = ("label", "state", "remapping")
        elif method == "add_auto":
            params = ("label", "state", "connector_outcomes", "transitions", "remapping")
        elif container.cls in FLEXBE_CONTAINERS:
            params = ("label", "state", "transitions", "autonomy", "remapping")
        else:
            params = ("label", "state", "transitions", "remapping")
        args = self.bind_args(call, params)
        if "label" not in args or "state" not in args:
            raise self.invalid(call, f"{method}() needs a label and a state")
        label_node = args["label"]
        if not (isinstance(label_node, ast.Constant) and isinstance(label_node.value, str)):
            try:
                label_value = literal(label_node, lambda n: self.lookup_literal(n, ctx))
            except NotStatic:
                raise self.unsupported(
                    label_node,
                    f"a state label built at run time ('{source_text(self.text, label_node, 60)}')",
                ) from None
            if not isinstance(label_value, str):
                raise self.invalid(label_node, "a state label must be a string")
            label = label_value
        else:
            label = label_node.value
        if label in container.labels:
            raise self.invalid(
                call,
                f"state label '{label}' is already used in this container "
                "(SMACH raises InvalidStateError)",
            )
        state = self.state(args["state"], ctx, label)
        transitions: dict[str, str | None] = {}
        node = args.get("transitions")
        if node is not None and not (isinstance(node, ast.Constant) and node.value is None):
            value = self.static(node, ctx, f"the transitions of '{label}'")
            if not isinstance(value, dict) or not all(
                isinstance(k, str) and (v is None or isinstance(v, str)) for k, v in value.items()
            ):
                raise self.invalid(
                    node,
                    f"the transitions of '{label}' must map outcome names "
                    "to labels or container outcomes",
                )
            transitions = {str(k): (v if v != "" else None) for k, v in value.items()}
        child = Child(label, state, transitions, call.lineno)
        remapping = args.get("remapping")
        if remapping is not None:
            try:
                found_map = literal(remapping, lambda n: self.lookup_literal(n, ctx))
            except NotStatic:
                found_map = None
            if isinstance(found_map, dict):
                child.remapping = {str(k): str(v) for k, v in found_map.items()}
            elif not (isinstance(remapping, ast.Constant) and remapping.value is None):
                self.warnings.append(
                    (
                        call.lineno,
                        f"the remapping of '{label}' is computed at run time "
                        f"('{source_text(self.text, remapping, 60)}'); not read",
                    )
                )
        child.position = self.position_above(call.lineno)
        autonomy = args.get("autonomy")
        if autonomy is not None:
            try:
                found = literal(autonomy, lambda n: self.lookup_literal(n, ctx))
            except NotStatic:
                found = None
            if isinstance(found, dict):
                child.autonomy = {str(k): str(v) for k, v in found.items()}
        if method == "add_auto":
            child.connectors = self.string_list(
                args.get("connector_outcomes"), ctx, call, "the connector outcomes"
            )
        if isinstance(state, Container):
            if state.parent is not None:
                raise self.unsupported(
                    call,
                    f"container '{state.name}' is added twice "
                    f"(as '{label}'); SMACH shares one instance",
                )
            state.parent = container
        container.children.append(child)
        container.labels.add(label)
        return state

    def position_above(self, line: int) -> tuple[int, int] | None:
        """The FlexBE editor's ``# x:120 y:40`` comment on the line above an ``add``."""
        index = line - 2
        if 0 <= index < len(self.lines):
            match = _POSITION.search(self.lines[index])
            if match is not None:
                return int(match.group(1)), int(match.group(2))
        return None

    def set_contained(self, container: Container, call: ast.Call, ctx: _Ctx) -> object:
        if container.kind != "iterator":
            raise self.invalid(call, "set_contained_state() needs an open Iterator")
        args = self.bind_args(
            call, ("label", "state", "loop_outcomes", "break_outcomes", "final_outcome_map")
        )
        label = self.string(args.get("label"), ctx, call, "the contained state's label")
        state = self.state(args["state"], ctx, label) if "state" in args else None
        if state is None:
            raise self.invalid(call, "set_contained_state() needs a state")
        loop = (
            self.string_list(args["loop_outcomes"], ctx, call, "loop_outcomes")
            if "loop_outcomes" in args
            else []
        )
        brk = (
            self.string_list(args["break_outcomes"], ctx, call, "break_outcomes")
            if "break_outcomes" in args
            else []
        )
        final_map: dict[str, str] = {}
        if "final_outcome_map" in args:
            value = self.static(args["final_outcome_map"], ctx, "final_outcome_map")
            if not isinstance(value, dict) or not all(
                isinstance(k, str) and isinstance(v, str) for k, v in value.items()
            ):
                raise self.invalid(call, "final_outcome_map must map outcomes to outcomes")
            final_map = {str(k): str(v) for k, v in value.items()}
        container.children = [Child(label, state, {}, call.lineno)]
        container.loop_outcomes, container.break_outcomes = loop, brk
        container.final_outcome_map = final_map
        container.contained_line = call.lineno
        if isinstance(state, Container):
            state.parent = container
        return state

    def state(self, node: ast.expr, ctx: _Ctx, label: str) -> StateRef | Container | Embedded:
        value = (
            self.expression(node, ctx, ast.Expr(node))
            if isinstance(node, ast.Call)
            else self.value_of(node, ctx)
        )
        if isinstance(value, Container | StateRef | Embedded):
            return value
        if isinstance(node, ast.Call):
            func = node.func
            if isinstance(func, ast.Attribute) and func.attr == "use_behavior":
                if not node.args:
                    raise self.invalid(node, "use_behavior() needs the behaviour class")
                cls = last_name(node.args[0])
                if cls is None:
                    raise self.unsupported(node.args[0], "an embedded behaviour chosen at run time")
                module = self.imports.get(cls)
                return Embedded(cls, module.rsplit(".", 1)[0] if module else None, node.lineno)
            cls = last_name(func)
            if cls is None:
                raise self.unsupported(
                    node,
                    f"state '{label}' is made by an expression "
                    f"('{source_text(self.text, node, 60)}')",
                )
            return self.state_ref(cls, node, ctx)
        raise self.unsupported(
            node,
            f"state '{label}' is {source_text(self.text, node, 60)!r}, "
            "a value known only at run time",
        )

    def state_ref(self, cls: str, call: ast.Call, ctx: _Ctx) -> StateRef:
        original = self.aliases.get(cls, cls)
        outcomes = self.outcomes_of_class(cls)
        callback = None
        if original == "CBState":
            cb = (
                call.args[0]
                if call.args
                else next((k.value for k in call.keywords if k.arg == "cb"), None)
            )
            callback = last_name(cb) if cb is not None else None
            outcomes = list(self.callback_outcomes.get(callback or "", [])) or None
        given = self.keyword_literal(call, "outcomes")
        if isinstance(given, list) and all(isinstance(o, str) for o in given):
            outcomes = list(
                dict.fromkeys([*(outcomes or [] if original == "CBState" else []), *given])
            )
        if original in ("SimpleActionState", "ServiceState"):
            for keyword in call.keywords:
                if keyword.arg in ("result_cb", "response_cb"):
                    extra = self.callback_interface(keyword.value)
                    if extra is None:
                        self.warnings.append(
                            (
                                call.lineno,
                                f"{original} {keyword.arg} may add "
                                "outcomes fsmbt cannot see (no cb_interface); "
                                "only the mapped ones are read",
                            )
                        )
                        outcomes = None
                    elif outcomes is not None:
                        outcomes = list(dict.fromkeys([*outcomes, *extra]))
        display = callback if original == "CBState" and callback else original
        decl = self.declaration_of(cls)
        config = configure(
            call,
            original,
            self.text,
            lambda n: self.lookup_literal(n, ctx),
            decl.arguments if decl is not None else None,
            self.imports,
        )
        if decl is not None:
            config.inputs = list(dict.fromkeys([*(decl.inputs or []), *(config.inputs or [])]))
            config.outputs = list(dict.fromkeys([*(decl.outputs or []), *(config.outputs or [])]))
        declared = outcomes
        if declared is None and decl is not None:
            declared = decl.outcomes
        return StateRef(
            display, outcomes, call.lineno, callback=callback, config=config, declared=declared
        )

    def declaration_of(self, cls: str) -> ClassDecl | None:
        """What the state class declares: in this file (through its in-file bases), else in the
        file its import names (through the resolver), else ``None``."""
        seen: set[str] = set()
        current: str | None = cls
        merged: ClassDecl | None = None
        while current is not None and current not in seen and current in self.class_decls:
            seen.add(current)
            decl = self.class_decls[current]
            if merged is None:
                merged = ClassDecl(decl.outcomes, decl.inputs, decl.outputs, list(decl.arguments))
            else:
                merged.outcomes = merged.outcomes or decl.outcomes
                merged.inputs = merged.inputs or decl.inputs
                merged.outputs = merged.outputs or decl.outputs
            bases = self.class_bases.get(current, [])
            current = bases[0] if bases else None
        if merged is not None:
            return merged
        path = self.imports.get(cls)
        if self.resolver is None or path is None or "." not in path:
            return None
        module, _, name = path.rpartition(".")
        return self.resolver(module, name)

    def callback_interface(self, node: ast.expr) -> list[str] | None:
        if isinstance(node, ast.Call) and last_name(node.func) in ("CBInterface", "cb_interface"):
            found = self.keyword_literal(node, "outcomes")
            return [str(o) for o in found] if isinstance(found, list) else []
        name = last_name(node)
        if name is not None and name in self.callback_outcomes:
            return list(self.callback_outcomes[name])
        return None


_UNKNOWN = object()

_CONSTRUCTOR_PARAMS: dict[str, tuple[str, ...]] = {
    "StateMachine": ("outcomes", "input_keys", "output_keys"),
    "Sequence": ("outcomes", "connector_outcome", "input_keys", "output_keys"),
    "Concurrence": (
        "outcomes",
        "default_outcome",
        "input_keys",
        "output_keys",
        "outcome_map",
        "outcome_cb",
        "child_termination_cb",
    ),
    "Iterator": ("outcomes", "input_keys", "output_keys", "it", "it_label", "exhausted_outcome"),
    "OperatableStateMachine": ("outcomes", "input_keys", "output_keys"),
    "LockableStateMachine": ("outcomes", "input_keys", "output_keys"),
    "PreemptableStateMachine": ("outcomes", "input_keys", "output_keys"),
    "PriorityContainer": ("outcomes", "input_keys", "output_keys"),
    "ConcurrencyContainer": ("conditions", "outcomes", "input_keys", "output_keys"),
}


def _statements(tree: ast.Module) -> list[ast.stmt]:
    """Every statement at every block level, in no particular order (explicit stack)."""
    out: list[ast.stmt] = []
    stack: list[list[ast.stmt]] = [tree.body]
    while stack:
        for stmt in stack.pop():
            out.append(stmt)
            for name in ("body", "orelse", "finalbody"):
                block = getattr(stmt, name, None)
                if isinstance(block, list):
                    stack.append(block)
            for handler in getattr(stmt, "handlers", []) or []:
                stack.append(handler.body)
            for case in getattr(stmt, "cases", []) or []:
                stack.append(case.body)
    return out


def _target_key(node: ast.expr) -> str | None:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
        return f"{node.value.id}.{node.attr}"
    return None


def _is_main_guard(stmt: ast.If) -> bool:
    test = stmt.test
    return (
        isinstance(test, ast.Compare)
        and isinstance(test.left, ast.Name)
        and test.left.id == "__name__"
    )


#: A static item list longer than this is read like a computed one (an environment choice).
MAX_UNROLLED_ITEMS = 256


def _static_count(node: ast.expr, lookup) -> int | None:  # type: ignore[no-untyped-def]
    """How many items a literal list/tuple or ``range(<ints>)`` has, else ``None``."""
    if isinstance(node, ast.Lambda) and not node.args.args:
        node = node.body
    if isinstance(node, ast.Call) and last_name(node.func) == "range" and not node.keywords:
        try:
            bounds = [literal(a, lookup) for a in node.args]
        except NotStatic:
            return None
        if not 1 <= len(bounds) <= 3 or not all(
            isinstance(b, int) and not isinstance(b, bool) for b in bounds
        ):
            return None
        ints = [b for b in bounds if isinstance(b, int)]
        return len(range(*ints))
    try:
        value = literal(node, lookup)
    except NotStatic:
        return None
    if isinstance(value, (list, tuple, str)):
        return len(value)
    return None


def analyze(
    text: str, tree: ast.Module, name: str, resolver: ClassResolver | None = None
) -> Analysis:
    """The containers ``tree`` builds (see the module docstring); ``resolver`` finds state
    classes imported from other files (none: only this file's classes are known)."""
    return Analyzer(text, tree, name, resolver).run()
