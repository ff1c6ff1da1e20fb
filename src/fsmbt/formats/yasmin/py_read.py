"""YASMIN Python state machines, read statically (docs/formats/yasmin.md, 'Python').

The file is parsed with ``ast`` (``pysm.source.parse_source``) and never imported or run. What
is understood, in the order the statements are written (module level and every function body,
each statement list walked with an explicit stack):

- ``x = StateMachine(outcomes=[...])`` (or positional), ``Concurrence(states={...},
  default_outcome=..., outcome_map={...})``, ``OrthogonalState(default_outcome, outcome_map)``
  with ``x.add_region("A", sm)``, ``JoinState(sync_id, outcome)``, ``CbState([outcomes], cb)``,
  and any other call ``Cls(...)`` as a state of class ``Cls`` (its outcomes are those of the
  class's ``super().__init__(outcomes=[...])`` when the class is in the file, else unknown);
- ``x.add_state("NAME", state, transitions={...}, remappings={...},
  parameter_mappings={...})`` in positional or keyword form, ``x.set_start_state("NAME")``;
- literal values may come through names bound to literals earlier, and the outcome constants
  of ``yasmin_ros.basic_outcomes`` (``SUCCEED`` is ``"succeeded"``...) imported by name.
The machine is the first ``StateMachine`` that is not added to another. An ``add_state`` in a
loop or under a condition, a computed name or transitions, and code that would run when the
file is imported (a call at module level that is not one of the calls above, outside
``if __name__ == "__main__":``) are located errors. Costs: O(n) syntax nodes.
"""

from __future__ import annotations

import ast
import json
from collections.abc import Iterator

from fsmbt.formats.pysm.analyze import Child, Container, StateRef
from fsmbt.formats.pysm.source import NotStatic, last_name, literal, parse_source
from fsmbt.formats.registry import ReadContext
from fsmbt.formats.yasmin.xml_read import A_SYNC, A_TAG, Records
from fsmbt.model import state_info
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError

_CONTAINER_METHODS = frozenset({"add_state", "set_start_state", "add_region"})
#: Calls on a state or machine that only set metadata (allowed anywhere, ignored).
_METADATA_METHODS = frozenset(
    {
        "set_description",
        "add_input_key",
        "add_output_key",
        "declare_parameter",
        "set_outcome_description",
        "set_parameter_mappings",
        "add_start_cb",
        "add_transition_cb",
        "add_end_cb",
        "set_name",
    }
)


#: ``yasmin_ros.basic_outcomes``: the outcome constants YASMIN programs import by name.
BASIC_OUTCOMES = {
    "SUCCEED": "succeeded",
    "ABORT": "aborted",
    "FAIL": "failed",
    "CANCEL": "canceled",
    "TIMEOUT": "timeout",
    "RETRY": "retry",
}


class _Reader:
    def __init__(self, text: str, ctx: ReadContext) -> None:
        self.ctx = ctx
        self.name = ctx.display_name
        self.tree = parse_source(text, self.name)
        self.env: dict[str, object] = {}
        self.containers: list[Container] = []
        self.added: set[int] = set()
        self.info: dict[int, dict[str, str]] = {}
        self.class_outcomes: dict[str, list[str]] = {}
        self.cb_count = 0

    def lookup(self, name: str) -> object:
        value = self.env[name]
        if isinstance(value, (Container, StateRef)):
            raise KeyError(name)
        return value

    def where(self, node: ast.AST) -> SourceLocation:
        return SourceLocation(self.name, getattr(node, "lineno", None))

    def unsupported(self, node: ast.AST, what: str) -> UnsupportedError:
        return UnsupportedError(what, location=self.where(node))

    def lit(self, node: ast.AST, what: str) -> object:
        try:
            return literal(node, self.lookup)
        except NotStatic as exc:
            raise self.unsupported(
                exc.node, f"{what} is {exc.what}; fsmbt reads literals only"
            ) from None

    # -- entry ----------------------------------------------------------------------------------
    def read(self) -> Records:
        for node in ast.walk(self.tree):
            if isinstance(node, ast.ImportFrom) and node.module == "yasmin_ros.basic_outcomes":
                for alias in node.names:
                    if alias.name in BASIC_OUTCOMES:
                        self.env[alias.asname or alias.name] = BASIC_OUTCOMES[alias.name]
        self.collect_classes()
        self.check_import_time(self.tree.body)
        # statement lists in source order, depth first: (remaining statements, loop line)
        stack: list[tuple[Iterator[ast.stmt], int | None]] = [(iter(self.tree.body), None)]
        while stack:
            body, loop_line = stack[-1]
            stmt = next(body, None)
            if stmt is None:
                stack.pop()
                continue
            self.statement(stmt, loop_line, stack)
        roots = [c for c in self.containers if c.cls == "StateMachine" and id(c) not in self.added]
        if not roots:
            raise InputError(
                "no YASMIN StateMachine is built in this file", location=SourceLocation(self.name)
            )
        root = roots[0]
        if len(roots) > 1:
            self.ctx.warn(
                f"{len(roots)} top-level state machines; read '{root.name}' (line {root.line})"
            )
        for container in self.containers:
            if container.kind == "sm" and not container.children:
                raise InputError(
                    f"state machine '{container.name}' has no states",
                    location=SourceLocation(self.name, container.line),
                )
        for container in self.containers:
            if container.cls == "OrthogonalState":
                self.barriers(container)
        records = Records(root, root.name, self.info)
        return records

    def barriers(self, container: Container) -> None:
        """JoinStates directly in the regions of an OrthogonalState, grouped by sync_id."""
        groups: dict[str, list[tuple[str, str]]] = {}
        for region in container.children:
            if not isinstance(region.state, Container):
                continue
            for child in region.state.children:
                state = child.state
                if isinstance(state, StateRef) and state.cls == "JoinState":
                    sync_id = self.info.get(id(state), {}).get(A_SYNC, "")
                    groups.setdefault(sync_id, []).append((region.label, child.label))
        for sync_id, members in groups.items():
            if len(members) < 2:
                raise InputError(
                    f"JoinState sync_id '{sync_id}' of OrthogonalState '{container.name}' has "
                    "fewer than 2 participants (YASMIN refuses it when it configures the state)",
                    location=SourceLocation(self.name, container.line),
                )
            container.sync_groups.append(members)

    def collect_classes(self) -> None:
        """Outcomes of state classes defined in the file (``super().__init__(outcomes=...)``)."""
        for node in ast.walk(self.tree):
            if not isinstance(node, ast.ClassDef):
                continue
            for inner in ast.walk(node):
                if (
                    isinstance(inner, ast.Call)
                    and isinstance(inner.func, ast.Attribute)
                    and inner.func.attr == "__init__"
                ):
                    value = None
                    for kw in inner.keywords:
                        if kw.arg == "outcomes":
                            value = kw.value
                    args = [
                        a for a in inner.args if not (isinstance(a, ast.Name) and a.id == "self")
                    ]
                    if value is None and args:
                        value = args[0]
                    if value is None:
                        continue
                    try:
                        outcomes = literal(value)
                    except NotStatic:
                        continue
                    if isinstance(outcomes, (list, tuple)) and all(
                        isinstance(o, str) for o in outcomes
                    ):
                        self.class_outcomes[node.name] = [str(o) for o in outcomes]

    def check_import_time(self, body: list[ast.stmt]) -> None:
        """Refuse module-level code that runs on import (it is never run here either)."""
        for stmt in body:
            if isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant):
                continue  # docstring
            if isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Call):
                func = stmt.value.func
                if isinstance(func, ast.Attribute) and (
                    func.attr in _CONTAINER_METHODS | _METADATA_METHODS
                ):
                    continue
                raise InputError(
                    f"code that runs when the file is imported ({ast.unparse(func)}(...) at "
                    "module level); fsmbt reads state machine declarations and runs nothing - "
                    "move it into a function or under if __name__ == '__main__'",
                    location=self.where(stmt),
                )
            if isinstance(
                stmt, (ast.For, ast.While, ast.With, ast.Try, ast.AsyncFor, ast.AsyncWith)
            ):
                raise InputError(
                    "code that runs when the file is imported (a module-level "
                    f"{type(stmt).__name__.lower()} block); fsmbt reads declarations only",
                    location=self.where(stmt),
                )

    # -- statements -----------------------------------------------------------------------------
    def statement(
        self,
        stmt: ast.stmt,
        loop_line: int | None,
        stack: list[tuple[Iterator[ast.stmt], int | None]],
    ) -> None:
        if isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef)):
            stack.append((iter(stmt.body), None))
        elif isinstance(stmt, ast.If):
            if _is_main_guard(stmt.test):
                return
            stack.append((iter([*stmt.body, *stmt.orelse]), stmt.lineno))
        elif isinstance(stmt, (ast.For, ast.While)):
            stack.append((iter([*stmt.body, *stmt.orelse]), stmt.lineno))
        elif isinstance(stmt, ast.With):
            stack.append((iter(stmt.body), loop_line))
        elif isinstance(stmt, ast.Try):
            stack.append((iter([*stmt.body, *stmt.orelse, *stmt.finalbody]), loop_line))
        elif isinstance(stmt, ast.Assign) and len(stmt.targets) == 1:
            target = stmt.targets[0]
            if isinstance(target, ast.Name):
                value = self.value(stmt.value)
                if value is not None:
                    self.env[target.id] = value
                if isinstance(value, Container) and value.var is None:
                    value.var = target.id
        elif isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Call):
            self.call(stmt.value, loop_line)

    def value(self, node: ast.expr) -> object:
        """A container record, a state, a literal, or ``None`` when none of these."""
        if isinstance(node, ast.Call):
            return self.construct(node)
        try:
            return literal(node, self.lookup)
        except NotStatic:
            return None

    def construct(self, call: ast.Call) -> object:
        cls = last_name(call.func)
        if cls is None:
            return None
        kwargs = {kw.arg: kw.value for kw in call.keywords if kw.arg}
        line = call.lineno
        if cls == "StateMachine":
            node = kwargs.get("outcomes") or (call.args[0] if call.args else None)
            if node is None:
                raise self.unsupported(call, "StateMachine() without outcomes")
            outcomes = self.lit(node, "the outcomes of StateMachine()")
            container = Container("StateMachine", "sm", _strings(outcomes, call, self), line)
            self.containers.append(container)
            return container
        if cls in ("Concurrence", "OrthogonalState"):
            return self.concurrence(call, cls, kwargs)
        if cls == "JoinState":
            sync = call.args[0] if call.args else kwargs.get("sync_id")
            out = call.args[1] if len(call.args) > 1 else kwargs.get("outcome")
            sync_id = str(self.lit(sync, "sync_id")) if sync is not None else ""
            outcome = str(self.lit(out, "the JoinState outcome")) if out is not None else "joined"
            ref = StateRef("JoinState", [outcome], line)
            self.info[id(ref)] = {A_SYNC: sync_id, A_TAG: "JoinState"}
            return ref
        if cls == "CbState":
            node = kwargs.get("outcomes") or (call.args[0] if call.args else None)
            if node is None:
                raise self.unsupported(call, "CbState() without outcomes")
            outcomes = _strings(self.lit(node, "the outcomes of CbState()"), call, self)
            callback = call.args[1] if len(call.args) > 1 else kwargs.get("cb")
            name = ast.unparse(callback) if callback is not None else "callback"
            return StateRef("CbState", outcomes, line, callback=name)
        if cls[:1].isupper():
            ref = StateRef(cls, self.class_outcomes.get(cls), line)
            params: dict[str, str] = {}
            expression: list[str] = []
            for index, arg in enumerate(call.args):
                _param(f"arg{index}", arg, params, expression)
            for key, arg in kwargs.items():
                _param(key, arg, params, expression)
            self.info[id(ref)] = state_info.encode(params=params, expression_params=expression)
            return ref
        return None

    def concurrence(self, call: ast.Call, cls: str, kwargs: dict[str, ast.expr]) -> Container:
        default_node = kwargs.get("default_outcome")
        map_node = kwargs.get("outcome_map")
        states_node = kwargs.get("states")
        if cls == "OrthogonalState":
            if default_node is None and call.args:
                default_node = call.args[0]
            if map_node is None and len(call.args) > 1:
                map_node = call.args[1]
        elif states_node is None and call.args:
            states_node = call.args[0]
        if default_node is None:
            raise self.unsupported(call, f"{cls}() without default_outcome")
        default = str(self.lit(default_node, "default_outcome"))
        outcome_map: list[tuple[str, dict[str, str]]] = []
        if map_node is not None:
            raw = self.lit(map_node, "the outcome map")
            if not isinstance(raw, dict):
                raise self.unsupported(call, "the outcome map is not a dict")
            for outcome, required in raw.items():
                if not isinstance(required, dict) or not required:
                    raise InputError(
                        f"outcome '{outcome}' in the outcome map must have at least one requirement",
                        location=self.where(call),
                    )
                outcome_map.append((str(outcome), {str(k): str(v) for k, v in required.items()}))
        outcomes = list(dict.fromkeys([default, *(o for o, _ in outcome_map)]))
        container = Container(cls, "concurrence", outcomes, call.lineno)
        container.default_outcome = default
        container.outcome_map = outcome_map
        self.containers.append(container)
        if cls == "Concurrence":
            if not isinstance(states_node, ast.Dict):
                raise self.unsupported(call, "Concurrence(states=...) is not a literal dict")
            for key_node, value_node in zip(states_node.keys, states_node.values):
                if key_node is None:
                    raise self.unsupported(call, "** in Concurrence states")
                label = str(self.lit(key_node, "a Concurrence state name"))
                state = self.state_of(value_node)
                child = Child(label, state, {}, value_node.lineno)
                self.record(child, state)
                container.children.append(child)
        return container

    def state_of(self, node: ast.expr) -> StateRef | Container:
        value = self.env.get(node.id) if isinstance(node, ast.Name) else self.value(node)
        if isinstance(value, (StateRef, Container)):
            return value
        raise self.unsupported(
            node, f"the state {ast.unparse(node)} is not a state constructed in this file"
        )

    def record(self, child: Child, state: StateRef | Container) -> None:
        info = dict(self.info.get(id(state), {}))
        if isinstance(state, Container):
            self.added.add(id(state))
            info[state_info.CLASS] = state.cls
            info[state_info.OUTCOMES] = json.dumps(state.outcomes)
            state.var = state.var or child.label
        else:
            info[state_info.CLASS] = state.cls
            outcomes = state.outcomes or list(child.transitions)
            if outcomes:
                info[state_info.OUTCOMES] = json.dumps(outcomes)
        info.setdefault(A_TAG, "State" if isinstance(state, StateRef) else state.cls)
        self.info[id(child)] = info

    def call(self, call: ast.Call, loop_line: int | None) -> None:
        func = call.func
        if not isinstance(func, ast.Attribute) or func.attr not in _CONTAINER_METHODS:
            return
        owner = self.env.get(func.value.id) if isinstance(func.value, ast.Name) else None
        if not isinstance(owner, Container):
            return
        if loop_line is not None:
            raise self.unsupported(
                call,
                f"{func.attr} inside a loop or condition (line {loop_line}): the machine "
                "depends on the run; fsmbt reads machines built unconditionally",
            )
        kwargs = {kw.arg: kw.value for kw in call.keywords if kw.arg}
        if func.attr == "set_start_state":
            node = call.args[0] if call.args else kwargs.get("state_name")
            if node is None:
                raise self.unsupported(call, "set_start_state() without a name")
            owner.initial = str(self.lit(node, "the start state"))
            owner.initial_line = call.lineno
            return
        if func.attr == "add_region":
            if len(call.args) < 2:
                raise self.unsupported(call, "add_region(name, state_machine) expected")
            label = str(self.lit(call.args[0], "the region name"))
            region = self.state_of(call.args[1])
            if not isinstance(region, Container):
                raise self.unsupported(call, "a region is a StateMachine")
            region.var = label
            child = Child(label, region, {}, call.lineno)
            self.record(child, region)
            owner.children.append(child)
            return
        args = list(call.args)
        name_node = args[0] if args else kwargs.get("name")
        state_node = args[1] if len(args) > 1 else kwargs.get("state")
        trans_node = args[2] if len(args) > 2 else kwargs.get("transitions")
        remap_node = args[3] if len(args) > 3 else kwargs.get("remappings")
        pmap_node = args[4] if len(args) > 4 else kwargs.get("parameter_mappings")
        if name_node is None or state_node is None:
            raise self.unsupported(call, "add_state(name, state, ...) expected")
        label = str(self.lit(name_node, "the state name"))
        if label in owner.labels:
            raise InputError(
                f"state '{label}' already registered in the state machine",
                location=self.where(call),
            )
        state = self.state_of(state_node)
        transitions: dict[str, str | None] = {}
        if trans_node is not None:
            raw = self.lit(trans_node, "the transitions")
            if not isinstance(raw, dict):
                raise self.unsupported(call, "transitions is not a dict")
            transitions = {str(k): str(v) for k, v in raw.items()}
        child = Child(label, state, transitions, call.lineno)
        self.record(child, state)
        info = self.info[id(child)]
        if remap_node is not None:
            raw = self.lit(remap_node, "the remappings")
            if isinstance(raw, dict) and raw:
                info.update(state_info.encode(remap={str(k): str(v) for k, v in raw.items()}))
        if pmap_node is not None:
            raw = self.lit(pmap_node, "the parameter mappings")
            if isinstance(raw, dict) and raw:
                params = {str(k): str(v) for k, v in raw.items()}
                info.update(state_info.encode(params=params, expression_params=list(params)))
        owner.children.append(child)
        owner.labels.add(label)


def _param(name: str, node: ast.expr, params: dict[str, str], expression: list[str]) -> None:
    try:
        value = literal(node)
    except NotStatic:
        params[name] = ast.unparse(node)
        expression.append(name)
        return
    params[name] = value if isinstance(value, str) else json.dumps(value)


def _strings(value: object, node: ast.AST, reader: _Reader) -> list[str]:
    if isinstance(value, (list, tuple, set)) and all(isinstance(v, str) for v in value):
        return [str(v) for v in value]
    raise reader.unsupported(node, "outcomes are not a literal list of strings")


def _is_main_guard(test: ast.expr) -> bool:
    return (
        isinstance(test, ast.Compare)
        and isinstance(test.left, ast.Name)
        and test.left.id == "__name__"
        and len(test.comparators) == 1
        and isinstance(test.comparators[0], ast.Constant)
        and test.comparators[0].value == "__main__"
    )


def read_python(text: str, ctx: ReadContext) -> Records:
    """The records of a YASMIN Python file (see the module docstring)."""
    return _Reader(text, ctx).read()
