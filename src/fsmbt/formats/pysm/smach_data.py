"""A machine's data model (``fsmbt.model.fsm_data``) in SMACH: userdata and generated decision
states (docs/formats/smach.md, "Data: userdata and decision states"; docs/semantics.md §6a).

SMACH maps each outcome of a state to one target, and has no guards. Writing (``split_data``,
on the writer's own copy of the model):

- every variable becomes a userdata key of the top container (``sm.userdata.x = 0``, the
  declared initial value) and an input and output key of every nested container, so the
  decision states below read and write it;
- the transitions of one state on one event that carry a guard or an assignment become one
  transition to a new **decision state**; its generated class's ``execute(userdata)`` tries the
  guards in document order (W3C: the first transition whose guard holds is taken), runs that
  transition's assignments on ``userdata`` and returns ``to_<k>``, mapped to the k-th
  transition's target. When no transition is unguarded the model ignores the event in a
  valuation where no guard holds, which a SMACH state cannot do: the generated code raises
  there, and the writer names it as a loss;
- a composite's ``<onexit>`` assignments become a **reset state** on each transition leaving
  it (``execute`` runs the assignments and returns ``done``); where that transition is itself
  guarded, its decision state runs them instead, after the guard and before the transition's
  own assignments (the W3C order: select on the old values, exit, then the transition's
  content).

The guards and assignments are fsmbt's expression subset (``fsmbt.formats.scxml.expr``): they are
parsed with ``ast`` (never run) and only names, literals, comparisons, ``and``/``or``/``not``,
``+`` and ``-`` are written as code; each name ``x`` becomes ``userdata.x``.

Reading back (``fold_data``): the ``__fsmbt__`` entry ``data`` lists the decision and reset
states with their guards and assignments; the reader puts the guarded transitions back in
their place and drops those states, so the model read back is the model written.

Costs: O(T) for T transitions, plus the expressions' length.
"""

from __future__ import annotations

import ast
import keyword
from dataclasses import dataclass, field

from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM, State, Transition
from fsmbt.model.fsm_data import (
    ASSIGN,
    COND,
    DATAMODEL,
    ONEXIT,
    SUBSET_NODES,
    has_data,
    parse_lines,
)

#: The outcome of a reset state.
DONE = "done"
#: ``State.attrs`` key marking a generated state (its class source, for the writer).
A_CODE = "fsmbt:smach.code"


@dataclass
class DataPlan:
    """What ``split_data`` did: the variables, the generated states, the losses."""

    variables: list[tuple[str, str]] = field(default_factory=list)  # (name, initial expr)
    initial: list[tuple[str, str]] = field(default_factory=list)  # (name, Python code)
    decisions: list[list[object]] = field(default_factory=list)  # [path, name, [[cond, assign]]]
    resets: list[list[object]] = field(default_factory=list)  # [path, name]
    onexit: list[list[object]] = field(default_factory=list)  # [path, composite, assign]
    losses: list[str] = field(default_factory=list)

    def extension(self) -> dict[str, object]:
        """The ``__fsmbt__["data"]`` entry."""
        return {
            "datamodel": "\n".join(f"{n}={e}" for n, e in self.variables),
            "decisions": self.decisions,
            "resets": self.resets,
            "onexit": self.onexit,
        }


def python_code(expr: str, names: set[str], where: str) -> str:
    """``expr`` as Python over ``userdata`` (each variable ``x`` -> ``userdata.x``).

    Raises:
        UnsupportedError: ``expr`` is not in the subset (module docstring), or reads a name
            that is not a variable.
    """
    try:
        tree = ast.parse(expr.strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        raise UnsupportedError(
            f"SMACH: {where}: '{expr}' is not an expression fsmbt writes as code"
        ) from None
    for node in ast.walk(tree):
        if not isinstance(node, SUBSET_NODES):
            raise UnsupportedError(
                f"SMACH: {where}: '{expr}' uses {type(node).__name__}, which fsmbt does not "
                "write as code (names, literals, comparisons, and/or/not, + and -)"
            )
        if isinstance(node, ast.Name) and node.id not in names and node.id not in ("True", "False"):
            raise UnsupportedError(
                f"SMACH: {where}: '{expr}' reads '{node.id}', which is not a variable of the "
                "data model"
            )

    class _ToUserdata(ast.NodeTransformer):
        def visit_Name(self, node: ast.Name) -> ast.AST:  # noqa: N802 - ast's visitor name
            if node.id not in names:
                return node
            return ast.copy_location(
                ast.Attribute(ast.Name("userdata", ast.Load()), node.id, ast.Load()), node
            )

    return ast.unparse(_ToUserdata().visit(tree))


def _machines(top: FSM) -> list[tuple[list[str], FSM]]:
    """Every composite's machine with its path of composite state names (parents first)."""
    out: list[tuple[list[str], FSM]] = [([], top)]
    stack: list[tuple[list[str], FSM]] = [([], top)]
    while stack:
        path, machine = stack.pop()
        for state in machine.states.values():
            for region in state.regions[:1] if state.is_composite else ():
                out.append(([*path, state.name], region))
                stack.append(([*path, state.name], region))
    return out


def _unique(base: str, taken: dict[str, State]) -> str:
    name, n = base, 2
    while name in taken:
        name, n = f"{base} #{n}", n + 1
    return name


def split_data(top: FSM) -> DataPlan:
    """Rewrite ``top`` (the writer's copy) so SMACH can hold its data (module docstring)."""
    plan = DataPlan()
    if not has_data(top):
        return plan
    plan.variables = parse_lines(top.attrs.pop(DATAMODEL))
    names = {n for n, _e in plan.variables}
    for name, expr in plan.variables:
        if not name.isidentifier() or keyword.iskeyword(name) or name == "userdata":
            raise UnsupportedError(f"SMACH: variable '{name}' is not a userdata key name")
        plan.initial.append((name, python_code(expr, set(), f"the initial value of '{name}'")))
    for path, machine in _machines(top):
        exits: dict[str, list[str]] = {}  # composite -> its <onexit> assignments as code
        for state in machine.states.values():
            assign = state.attrs.pop(ONEXIT, None)
            if assign is not None:
                at = f"'{'/'.join([*path, state.name])}' (on exit)"
                exits[state.name] = [
                    f"userdata.{n} = {python_code(e, names, at)}" for n, e in parse_lines(assign)
                ]
                plan.onexit.append([path, state.name, assign])
        groups: dict[tuple[str, str | None], list[Transition]] = {}
        for t in machine.transitions:
            groups.setdefault((t.source, t.event), []).append(t)
        rebuilt: list[Transition] = []
        done: set[tuple[str, str | None]] = set()
        for t in machine.transitions:
            key = (t.source, t.event)
            group = groups[key]
            if not any(COND in g.attrs or ASSIGN in g.attrs for g in group):
                rebuilt.append(t)
                continue
            if key in done:
                continue
            done.add(key)
            label = f"{t.source} on {t.event}" if t.event is not None else f"{t.source} done"
            decision = _unique(f"{label} [guards]", machine.states)
            at = f"'{'/'.join([*path, t.source])}' on '{t.event}'"
            branches: list[list[object]] = []
            code = ["    def execute(self, userdata):"]
            for k, g in enumerate(group, start=1):
                cond, assign = g.attrs.get(COND), g.attrs.get(ASSIGN)
                # W3C order: the guard on the values before the step, then the source's
                # <onexit>, then the transition's own assignments
                body = [
                    *exits.get(t.source, []),
                    *(
                        f"userdata.{n} = {python_code(e, names, at)}"
                        for n, e in parse_lines(assign or "")
                    ),
                    f"return {f'to_{k}'!r}",
                ]
                if cond is not None:
                    code.append(f"        if {python_code(cond, names, at)}:")
                    code.extend(f"            {line}" for line in body)
                else:
                    code.extend(f"        {line}" for line in body)
                branches.append([cond, assign])
            if group[-1].attrs.get(COND) is not None:
                code.append(
                    f"        raise RuntimeError({f'no guard of {at} holds: the model ignores the event here'!r})"
                )
                plan.losses.append(
                    f"state {at}: where no guard holds the model ignores the event; a SMACH "
                    "state cannot, so the generated decision state raises there"
                )
            state = State(decision, action=None)
            state.attrs[A_CODE] = "\n".join(code)
            machine.states[decision] = state
            rebuilt.append(Transition(t.source, t.event, decision, exit=t.exit))
            for k, g in enumerate(group, start=1):
                rebuilt.append(Transition(decision, f"to_{k}", g.target))
            plan.decisions.append([path, decision, branches])
        machine.transitions = rebuilt
        deciding = {str(d[1]) for d in plan.decisions if d[0] == path}
        for source, lines in exits.items():
            for t in [t for t in machine.transitions if t.source == source]:
                if t.target in deciding:
                    continue  # the decision state runs the <onexit> after its guard
                reset = _unique(f"{state.name} exit", machine.states)
                made = State(reset, action=None)
                made.attrs[A_CODE] = "\n".join(
                    ["    def execute(self, userdata):"]
                    + [f"        {line}" for line in lines]
                    + [f"        return {DONE!r}"]
                )
                machine.states[reset] = made
                machine.transitions.append(Transition(reset, DONE, t.target))
                t.target = reset
                plan.resets.append([path, reset])
    return plan


def fold_data(top: FSM, data: object) -> None:
    """Undo ``split_data`` on a model read back: the ``__fsmbt__["data"]`` entry's decision and
    reset states become guarded transitions and ``<onexit>`` assignments again (entries that do
    not match the model are left as read)."""
    if not isinstance(data, dict) or not isinstance(data.get("datamodel"), str):
        return
    machines = {tuple(path): machine for path, machine in _machines(top)}
    for path, name, branches in data.get("decisions", []):
        machine = machines.get(tuple(path))
        if machine is None or name not in machine.states:
            continue
        outs = {t.event: t.target for t in machine.transitions if t.source == name}
        rebuilt: list[Transition] = []
        for t in machine.transitions:
            if t.source == name:
                continue
            if t.target != name:
                rebuilt.append(t)
                continue
            for k, (cond, assign) in enumerate(branches, start=1):
                attrs = {}
                if cond is not None:
                    attrs[COND] = cond
                if assign is not None:
                    attrs[ASSIGN] = assign
                rebuilt.append(Transition(t.source, t.event, outs[f"to_{k}"], t.exit, attrs))
        machine.transitions = rebuilt
        del machine.states[name]
    for path, name in data.get("resets", []):
        machine = machines.get(tuple(path))
        if machine is None or name not in machine.states:
            continue
        after = next(t.target for t in machine.transitions if t.source == name)
        for t in machine.transitions:
            if t.target == name:
                t.target = after
        machine.transitions = [t for t in machine.transitions if t.source != name]
        del machine.states[name]
    for path, composite, assign in data.get("onexit", []):
        machine = machines.get(tuple(path))
        if machine is not None and composite in machine.states:
            machine.states[composite].attrs[ONEXIT] = assign
    top.attrs[DATAMODEL] = data["datamodel"]
