"""state-machine-cat syntax tree <-> fsmbt's hierarchical FSM (docs/formats/smcat.md).

Reading (rules):
- one FSM per machine (the top one, each composite state's ``{ ... }``); a state declared only
  by a transition belongs to the machine whose transition names it, unless it is declared
  somewhere (state-machine-cat's ``extractUndeclaredStates``); names are global;
- ``regular`` states are states (action: the ``entry/`` action of ``: ...``, else the name);
  ``final`` states are final (action: their ``entry/`` action, else none); a state with ``{ ... }`` is composite; a ``parallel`` state's inner
  states are its regions (each composite);
- a ``parallel`` state's atomic inner state is a region holding just that state;
- the ``initial`` state of a machine is its start pseudo-state: its one transition names the
  initial state; with an event, that event is the machine's initial event;
- ``a => b: ev;`` is ``a --ev--> b``; without an event it is a completion transition, and the
  condition ``[in X]`` (which fsmbt writes) names the final state ``X`` it waits for;
- transition actions and attributes (color, class, labels, notes, ``active``, ``width``) are kept
  in ``attrs`` (``smcat.*``), transition actions with a warning (fsmbt's semantics runs actions
  on states only).
Refused at their line (``UnsupportedError``): ``history``/``deephistory``, ``choice``,
``fork``/``join``/``junction``, ``terminate``, guards other than ``[in X]``, a transition between
machines of different levels, a machine with several initial states or an initial state with
other than one transition.

Writing is the inverse: ``initial`` (a fresh name) ``=> S``; a state whose name state-machine-cat
would type (``final_check`` contains ``final``) gets ``[type=regular]``; names that are not
identifiers are quoted. Explicit work lists. Costs: O(S + T).
"""

from __future__ import annotations

import json
import re

from fsmbt.formats.registry import ReadContext
from fsmbt.formats.smcat.parse import SMachine, SState, STransition, parse_smcat, type_from_name
from fsmbt.model import Model
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.model.fsm import FSM, State

_REFUSED = {
    "history": "history states",
    "deephistory": "deep history states",
    "choice": "choice pseudo-states",
    "fork": "fork pseudo-states",
    "join": "join pseudo-states",
    "junction": "junction pseudo-states",
    "forkjoin": "fork/join pseudo-states",
    "terminate": "terminate states",
}
_EXIT = re.compile(r"in\s+(?P<state>.+)\Z", re.S)
_IDENT = re.compile(r"[^;, \"\t\n\r=\-><:{\[\]#/*}]+\Z")
A_ATTR = "smcat."


def read_smcat(text: str, ctx: ReadContext) -> FSM:
    """Read a ``.smcat`` text (see the module docstring)."""
    tree = parse_smcat(text, ctx.display_name)
    return _Builder(ctx).build(tree)


class _Builder:
    def __init__(self, ctx: ReadContext) -> None:
        self.ctx = ctx

    def loc(self, line: int) -> SourceLocation:
        return self.ctx.location(line)

    def build(self, tree: SMachine) -> FSM:
        name = self.ctx.path.stem if self.ctx.path is not None else "smcat"
        declared: dict[str, SMachine] = {}
        work = [tree]
        while work:
            machine = work.pop()
            for state in machine.states:
                if state.name in declared:
                    raise InputError(
                        f"state '{state.name}' is declared twice (state names are global in "
                        "state-machine-cat)",
                        location=self.loc(state.line),
                    )
                declared[state.name] = machine
                if state.machine is not None:
                    work.append(state.machine)
        # undeclared states join the machine whose transition names them first
        work = [tree]
        while work:
            machine = work.pop()
            for t in machine.transitions:
                for endpoint in (t.source, t.target):
                    if endpoint not in declared:
                        declared[endpoint] = machine
                        machine.states.append(SState(endpoint, t.line, type_from_name(endpoint)))
            work.extend(s.machine for s in machine.states if s.machine is not None)
        top = FSM(name=name)
        jobs: list[tuple[SMachine, FSM, SState | None]] = [(tree, top, None)]
        while jobs:
            machine, fsm, owner = jobs.pop()
            jobs.extend(self.machine(machine, fsm, owner, declared))
        return top

    def machine(
        self,
        machine: SMachine,
        fsm: FSM,
        owner: SState | None,
        declared: dict[str, SMachine],
    ) -> list[tuple[SMachine, FSM, SState | None]]:
        pending: list[tuple[SMachine, FSM, SState | None]] = []
        initials = [s for s in machine.states if s.kind == "initial"]
        if len(initials) > 1:
            raise UnsupportedError(
                f"{len(initials)} initial states in one machine ("
                + ", ".join(s.name for s in initials)
                + ")",
                location=self.loc(initials[1].line),
            )
        for state in machine.states:
            if state.kind in _REFUSED:
                raise UnsupportedError(
                    f"state '{state.name}': {_REFUSED[state.kind]} are not in fsmbt's model "
                    "(docs/formats/smcat.md)",
                    location=self.loc(state.line),
                )
            if state.kind == "initial":
                if state.machine is not None:
                    raise UnsupportedError(
                        f"initial state '{state.name}' has states inside",
                        location=self.loc(state.line),
                    )
                continue
            attrs = {f"{A_ATTR}{k}": v for k, v in state.attrs.items()}
            if state.notes:
                attrs[f"{A_ATTR}note"] = json.dumps(state.notes)
            action: str | None = state.name
            if state.actions is not None:
                entries = [a.strip() for a in re.split(r"\n\s*", state.actions) if a.strip()]
                entry = [a.split("/", 1)[1].strip() for a in entries if re.match(r"entry\s*/", a)]
                if entry:
                    action = entry[0]
                others = [a for a in entries if not re.match(r"entry\s*/", a)]
                if others or len(entry) > 1:
                    attrs[f"{A_ATTR}actions"] = state.actions
                    self.ctx.warn(
                        f"state '{state.name}': actions other than one entry/ action are kept "
                        "as an annotation (fsmbt runs one action on entering a state)",
                        state.line,
                    )
            if state.kind == "final":
                action = action if state.actions is not None else None
            new = State(
                state.name,
                action=action,
                final=state.kind == "final",
                attrs=attrs,
                location=self.loc(state.line),
            )
            if state.kind == "parallel":
                if state.machine is None or not state.machine.states:
                    raise UnsupportedError(
                        f"parallel state '{state.name}' has no regions",
                        location=self.loc(state.line),
                    )
                if state.machine.transitions:
                    raise UnsupportedError(
                        f"parallel state '{state.name}' has transitions between its regions",
                        location=self.loc(state.machine.transitions[0].line),
                    )
                new.action = None
                for region in state.machine.states:
                    sub = FSM(name=region.name)
                    new.regions.append(sub)
                    if region.machine is None:  # an atomic region: that one state
                        if region.kind != "regular":
                            raise UnsupportedError(
                                f"region '{region.name}' of parallel state '{state.name}' is "
                                f"a {region.kind} state",
                                location=self.loc(region.line),
                            )
                        sub.add_state(State(region.name, action=region.name))
                        continue
                    pending.append((region.machine, sub, region))
            elif state.machine is not None:
                new.action = None if state.actions is None else new.action
                sub = FSM(name=state.name)
                new.regions.append(sub)
                pending.append((state.machine, sub, state))
            fsm.states[state.name] = new
        for t in machine.transitions:
            self.transition(machine, fsm, t, declared, initials[0] if initials else None)
        if fsm.initial is None:
            first = next((s for s in fsm.states.values() if not s.final), None)
            if first is None:
                where = owner.line if owner is not None else 1
                raise UnsupportedError(
                    f"machine{' of ' + repr(owner.name) if owner else ''} has no state to start in",
                    location=self.loc(where),
                )
            fsm.initial = first.name
            if initials:
                raise UnsupportedError(
                    f"initial state '{initials[0].name}' has no transition",
                    location=self.loc(initials[0].line),
                )
        return pending

    def transition(
        self,
        machine: SMachine,
        fsm: FSM,
        t: STransition,
        declared: dict[str, SMachine],
        initial: SState | None,
    ) -> None:
        where = self.loc(t.line)
        for endpoint in (t.source, t.target):
            if declared.get(endpoint) is not machine:
                raise UnsupportedError(
                    f"transition {t.source} => {t.target} crosses machine levels ('{endpoint}' "
                    "is declared in another machine); fsmbt's transitions stay in one machine",
                    location=where,
                )
        attrs = {f"{A_ATTR}{k}": v for k, v in t.attrs.items()}
        if t.notes:
            attrs[f"{A_ATTR}note"] = json.dumps(t.notes)
        if t.action is not None:
            attrs[f"{A_ATTR}action"] = t.action
            self.ctx.warn(
                f"transition {t.source} => {t.target}: its action '{t.action}' is kept as an "
                "annotation (fsmbt runs actions on states only)",
                t.line,
            )
        exit_state: str | None = None
        if t.cond is not None:
            match = _EXIT.match(t.cond)
            if t.event is None and match is not None:
                exit_state = match.group("state").strip()
            else:
                raise UnsupportedError(
                    f"transition {t.source} => {t.target} has the condition [{t.cond}]: "
                    "guards are not in fsmbt's model",
                    location=where,
                )
        if initial is not None and t.source == initial.name:
            if fsm.initial is not None:
                raise UnsupportedError(
                    f"initial state '{initial.name}' has more than one transition",
                    location=where,
                )
            fsm.initial = t.target
            if t.event is not None:
                fsm.start_name = initial.name
                fsm.initial_event = t.event
            return
        if initial is not None and t.target == initial.name:
            raise UnsupportedError(
                f"a transition into the initial state '{initial.name}'", location=where
            )
        source = fsm.states.get(t.source)
        if source is not None and source.final:
            raise UnsupportedError(
                f"final state '{t.source}' has an outgoing transition", location=where
            )
        if exit_state is not None:
            owner = next((s for s in machine.states if s.name == t.source), None)
            inner = owner.machine if owner is not None and owner.kind != "parallel" else None
            if inner is None or declared.get(exit_state) is not inner:
                raise InputError(
                    f"[in {exit_state}] names no final state inside '{t.source}'", location=where
                )
        fsm.add_transition(
            t.source, t.event, t.target, exit=exit_state, attrs=attrs, location=where
        )


# -- writing ------------------------------------------------------------------------------------
def write_smcat(model: Model) -> str:
    """The ``.smcat`` text of an FSM (see the module docstring)."""
    if not isinstance(model, FSM):
        raise UnsupportedError("state-machine-cat holds state machines, not behavior trees")
    names = _all_names(model)
    lines: list[str] = []
    work: list[tuple[FSM, int] | str] = [(model, 0)]  # lines and machines still to write
    while work:
        item = work.pop()
        if isinstance(item, str):
            lines.append(item)
            continue
        machine, depth = item
        pad = "  " * depth
        if machine.initial is None:
            raise UnsupportedError(f"machine '{machine.name}' has no initial state")
        start = machine.start_name or _fresh("initial", names)
        names.add(start)
        items: list[tuple[FSM, int] | str] = []
        declared = [start, *machine.states]
        for index, name in enumerate(declared):
            sep = ";" if index == len(declared) - 1 else ","
            if index == 0:
                typed = "" if type_from_name(start) == "initial" else " [type=initial]"
                items.append(f"{pad}{_name(start)}{typed}{sep}")
                continue
            state = machine.states[name]
            items.extend(_notes(state.attrs, pad))
            text = f"{pad}{_name(state.name)}"
            attributes = _state_attributes(state)
            if attributes:
                text += f" [{attributes}]"
            if state.final and state.action is not None:
                text += f": {_quote('entry/ ' + state.action)}"
            elif not state.final and not state.regions and state.action != state.name:
                if state.action is None:
                    raise UnsupportedError(
                        f"state '{state.name}' runs no action; state-machine-cat's states "
                        "have no way to say so that fsmbt reads back"
                    )
                text += f": {_quote('entry/ ' + state.action)}"
            if state.is_parallel:
                raise UnsupportedError(
                    f"parallel state '{state.name}': regions that share events have no "
                    "state-machine-cat form fsmbt reads back the same"
                )
            if state.is_composite:
                items.extend([f"{text} {{", (state.regions[0], depth + 1), f"{pad}}}{sep}"])
            else:
                items.append(f"{text}{sep}")
        items.extend(_transition_lines(machine, pad, start))
        work.extend(reversed(items))
    return "\n".join(lines) + "\n"


def _transition_lines(machine: FSM, pad: str, start: str) -> list[str]:
    out: list[str] = []
    initial = f"{pad}{_name(start)} => {_name(str(machine.initial))}"
    if machine.initial_event is not None:
        initial += f": {_label(machine.initial_event)}"
    out.append(initial + ";")
    for t in machine.transitions:
        out.extend(_notes(t.attrs, pad))
        line = f"{pad}{_name(t.source)} => {_name(t.target)}"
        label = ""
        if t.event is not None:
            label = _label(t.event)
        elif t.exit is not None:
            label = f"[in {_label(t.exit)}]"
        action = t.attrs.get(f"{A_ATTR}action")
        if action is not None and "\n" not in action and ";" not in action:
            label += f" / {action}"
        if label:
            line += f": {label.strip()}"
        out.append(line + ";")
    return out


def _notes(attrs: dict[str, str], pad: str) -> list[str]:
    notes = json.loads(attrs.get(f"{A_ATTR}note", "[]"))
    return [f"{pad}# {note}" for note in notes if isinstance(note, str) and "\n" not in note]


def _state_attributes(state: State) -> str:
    parts: list[str] = []
    inferred = type_from_name(state.name)
    wanted = "final" if state.final else ("parallel" if state.is_parallel else "regular")
    if inferred != wanted:
        parts.append(f"type={wanted}")
    for key in ("label", "color", "class"):
        value = state.attrs.get(f"{A_ATTR}{key}")
        if value is not None and '"' not in value:
            parts.append(f'{key}="{value}"')
    return " ".join(parts)


def _all_names(model: FSM) -> set[str]:
    names: set[str] = set()
    for machine in model.machines():
        names.update(machine.states)
        if machine.start_name:
            names.add(machine.start_name)
    return names


def _fresh(base: str, names: set[str]) -> str:
    name, index = base, 1
    while name in names:
        index += 1
        name = f"{base}_{index}"
    return name


def _name(name: str) -> str:
    if _IDENT.match(name) and not name.startswith(("//", "#")):
        return name
    if "\n" in name or "\\" in name:
        raise UnsupportedError(f"state name {name!r}: state-machine-cat cannot quote it")
    return '"' + name.replace('"', '\\"') + '"'


def _quote(text: str) -> str:
    if '"' in text or "\n" in text:
        raise UnsupportedError(f"{text!r} cannot be written as a state-machine-cat string")
    return f'"{text}"'


def _label(event: str) -> str:
    if re.search(r"[\[\]/;{\"\n]", event) or event != event.strip() or not event:
        raise UnsupportedError(
            f"event {event!r}: state-machine-cat's labels cannot hold [ ] / ; {{ or quotes"
        )
    return event
