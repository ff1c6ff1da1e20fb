"""pytransitions ``MarkupMachine`` configurations <-> fsmbt's hierarchical FSM
(docs/formats/transitions.md).

Reading (pytransitions 0.9 semantics, as ``Machine(**config)`` / ``HierarchicalMachine`` build it):
- ``states``: names, or mappings with ``name`` and optionally ``children`` (or ``states``),
  ``initial``, ``transitions`` (the children's own), ``final``, ``on_enter``/``on_exit``, ``tags``;
  a state with children is composite, entered at its ``initial`` (else its first child);
- ``transitions``: mappings ``{trigger, source, dest}`` or lists ``[trigger, source, dest]``;
  ``source`` a name, a list, or ``"*"`` (every state of that level); ``dest`` ``"="`` is the
  source itself (a reflexive transition: the state is left and entered again);
- ``initial``: the machine's initial state; none means pytransitions' own state ``initial``;
- the triggers are the events; a trigger with no transition from the current state is ignored
  (pytransitions raises ``MachineError`` unless ``ignore_invalid_triggers``: a warning names it);
  of several transitions on one trigger from one state pytransitions takes the first (no
  conditions here), and so does fsmbt: the later ones are dropped with a warning;
- a state's action is its ``on_enter`` callbacks joined with ``+`` (else its name; a final
  state's, else none); ``on_exit``,
  ``tags``, transitions' ``before``/``after``/``prepare`` are kept as ``transitions.*``
  attributes with a warning (fsmbt runs one action on entering a state);
- the convenience triggers ``to_<state>`` that ``auto_transitions`` adds are not modelled (a
  warning says so): they are the library's shortcuts, not the machine's design.
Refused at the entry's path (``UnsupportedError``): ``conditions``/``unless`` (guards), internal
transitions (``dest: null``), parallel states, a transition naming a state of another level (the
nested ``A_B`` names of a top-level transition), unknown keys (``InputError``).

Writing is the inverse (JSON, the ``MarkupMachine`` form): hierarchical machines with their
children's transitions inside the parent state; completion transitions and parallel states are
refused. Explicit work lists. Costs: O(S + T) (``"*"`` costs one transition per state).
"""

from __future__ import annotations

import json
from typing import Any

from fsmbt.formats.registry import ReadContext
from fsmbt.formats.schema.yaml_format import load_yaml
from fsmbt.model import Model
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State

_TOP_KEYS = frozenset(
    {
        "name",
        "states",
        "transitions",
        "initial",
        "auto_transitions",
        "ignore_invalid_triggers",
        "send_event",
        "queued",
        "model_attribute",
        "models",
        "before_state_change",
        "after_state_change",
        "prepare_event",
        "finalize_event",
        "on_exception",
        "on_final",
        "ordered_transitions",
        "model_override",
    }
)
_STATE_KEYS = frozenset(
    {
        "name",
        "children",
        "states",
        "initial",
        "transitions",
        "final",
        "on_enter",
        "on_exit",
        "tags",
        "ignore_invalid_triggers",
        "timeout",
        "on_timeout",
        "on_final",
        "value",
    }
)
_TRANSITION_KEYS = frozenset(
    {"trigger", "source", "dest", "conditions", "unless", "before", "after", "prepare"}
)
A_PREFIX = "transitions."


def _load(text: str, ctx: ReadContext) -> Any:
    if text.lstrip().startswith("{"):
        try:
            return json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(
                f"invalid JSON: {exc.msg}", location=ctx.location(exc.lineno, exc.colno)
            ) from None
        except RecursionError:
            raise InputError("JSON nested too deeply", location=ctx.location()) from None
    return load_yaml(text, ctx)


def _callbacks(value: object, where: str, ctx: ReadContext) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        return [value]
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        return list(value)
    raise InputError(
        f"{where}: callbacks are names (a string or a list of strings)", location=ctx.location()
    )


def read_transitions(text: str, ctx: ReadContext) -> FSM:
    """Read a pytransitions configuration (see the module docstring)."""
    data = _load(text, ctx)
    if not isinstance(data, dict):
        raise InputError("a pytransitions configuration is a mapping", location=ctx.location())
    unknown = sorted(set(map(str, data)) - _TOP_KEYS)
    if unknown:
        raise InputError(
            f"unknown key(s) {', '.join(unknown)} in a pytransitions configuration",
            location=ctx.location(),
        )
    if "parallel" in data:
        raise UnsupportedError("parallel states", location=ctx.location())
    name = data.get("name") if isinstance(data.get("name"), str) else None
    top = FSM(name=name or (ctx.path.name.split(".")[0] if ctx.path is not None else "machine"))
    if data.get("auto_transitions", True):
        ctx.warn(
            "auto_transitions: the to_<state> triggers pytransitions adds are not modelled "
            "(the machine's declared triggers are)"
        )
    if not data.get("ignore_invalid_triggers", False):
        ctx.warn(
            "a trigger a state has no transition for raises MachineError in pytransitions "
            "(ignore_invalid_triggers is not set); fsmbt reads it as ignored"
        )
    for key in ("before_state_change", "after_state_change", "prepare_event", "finalize_event"):
        if data.get(key):
            top.attrs[A_PREFIX + key] = json.dumps(_callbacks(data[key], key, ctx))
    # (machine, states list, transitions list, initial, path)
    work: list[tuple[FSM, object, object, object, str]] = [
        (top, data.get("states"), data.get("transitions", []), data.get("initial"), "$")
    ]
    while work:
        machine, states, transitions, initial, path = work.pop()
        work.extend(_level(machine, states, transitions, initial, path, ctx))
    return top


def _level(
    machine: FSM, states: object, transitions: object, initial: object, path: str, ctx: ReadContext
) -> list[tuple[FSM, object, object, object, str]]:
    pending: list[tuple[FSM, object, object, object, str]] = []
    if not isinstance(states, list) or not states:
        raise InputError(f"{path}.states: a non-empty list of states", location=ctx.location())
    for index, entry in enumerate(states):
        where = f"{path}.states[{index}]"
        if isinstance(entry, str):
            entry = {"name": entry}
        if not isinstance(entry, dict) or not isinstance(entry.get("name"), str):
            raise InputError(
                f"{where}: a state is a name or a mapping with 'name'", location=ctx.location()
            )
        if "parallel" in entry:
            raise UnsupportedError(f"{where}: parallel states", location=ctx.location())
        unknown = sorted(set(map(str, entry)) - _STATE_KEYS)
        if unknown:
            raise InputError(
                f"{where}: unknown key(s) {', '.join(unknown)}", location=ctx.location()
            )
        name = entry["name"]
        if name in machine.states:
            raise InputError(f"{where}: state '{name}' is declared twice", location=ctx.location())
        on_enter = _callbacks(entry.get("on_enter"), where, ctx)
        attrs: dict[str, str] = {}
        for key in ("on_exit", "tags"):
            values = _callbacks(entry.get(key), where, ctx)
            if values:
                attrs[A_PREFIX + key] = json.dumps(values)
        if on_enter:
            attrs[A_PREFIX + "on_enter"] = json.dumps(on_enter)
        final = bool(entry.get("final", False))
        entered = "+".join(on_enter) or None
        state = State(
            name, action=entered if final else (entered or name), final=final, attrs=attrs
        )
        children = entry.get("children", entry.get("states"))
        if children:
            sub = FSM(name=name)
            state.regions.append(sub)
            state.action = "+".join(on_enter) or None
            pending.append(
                (sub, children, entry.get("transitions", []), entry.get("initial"), where)
            )
        elif entry.get("transitions"):
            raise InputError(f"{where}: transitions but no children", location=ctx.location())
        machine.states[name] = state
    if initial is None:
        if path == "$":
            if "initial" not in machine.states:
                machine.states = {"initial": State("initial", action="initial"), **machine.states}
            ctx.warn("no 'initial': pytransitions adds the state 'initial' and starts there")
            machine.initial = "initial"
        else:
            machine.initial = next(iter(machine.states))
    elif isinstance(initial, str) and initial in machine.states:
        machine.initial = initial
    else:
        raise InputError(
            f"{path}.initial: '{initial}' is not a state of this level", location=ctx.location()
        )
    if not isinstance(transitions, list):
        raise InputError(f"{path}.transitions: a list", location=ctx.location())
    taken: set[tuple[str, str]] = set()
    for index, entry in enumerate(transitions):
        where = f"{path}.transitions[{index}]"
        if isinstance(entry, list):
            if len(entry) < 3:
                raise InputError(
                    f"{where}: [trigger, source, dest] expected", location=ctx.location()
                )
            entry = dict(zip(("trigger", "source", "dest", "conditions", "unless"), entry))
        if not isinstance(entry, dict):
            raise InputError(f"{where}: a mapping or a list", location=ctx.location())
        unknown = sorted(set(map(str, entry)) - _TRANSITION_KEYS)
        if unknown:
            raise InputError(
                f"{where}: unknown key(s) {', '.join(unknown)}", location=ctx.location()
            )
        if entry.get("conditions") or entry.get("unless"):
            raise UnsupportedError(
                f"{where}: conditions/unless are guards, which fsmbt's machines do not have",
                location=ctx.location(),
            )
        trigger = entry.get("trigger")
        if not isinstance(trigger, str) or not trigger:
            raise InputError(f"{where}: 'trigger' is a name", location=ctx.location())
        if "dest" not in entry or entry["dest"] is None:
            raise UnsupportedError(
                f"{where}: an internal transition (dest null) changes no state and runs only "
                "callbacks; fsmbt's transitions go to a state",
                location=ctx.location(),
            )
        raw_source = entry.get("source")
        if raw_source == "*":
            sources = [s for s in machine.states if not machine.states[s].final]
        elif isinstance(raw_source, str):
            sources = [raw_source]
        elif isinstance(raw_source, list) and all(isinstance(s, str) for s in raw_source):
            sources = list(raw_source)
        else:
            raise InputError(f"{where}: 'source' is a name, a list or '*'", location=ctx.location())
        attrs = {}
        for key in ("before", "after", "prepare"):
            values = _callbacks(entry.get(key), where, ctx)
            if values:
                attrs[A_PREFIX + key] = json.dumps(values)
        if attrs:
            ctx.warn(
                f"{where}: transition callbacks are kept as annotations "
                "(fsmbt runs actions on states)"
            )
        for source in sources:
            dest = source if entry["dest"] == "=" else entry["dest"]
            for endpoint in (source, dest):
                if not isinstance(endpoint, str) or endpoint not in machine.states:
                    raise UnsupportedError(
                        f"{where}: '{endpoint}' is not a state of this level; transitions "
                        "between levels (nested names) are not in fsmbt's model",
                        location=ctx.location(),
                    )
            if machine.states[source].final:
                raise UnsupportedError(
                    f"{where}: a transition out of final state '{source}'", location=ctx.location()
                )
            if (source, trigger) in taken:
                ctx.warn(
                    f"{where}: '{trigger}' from '{source}' has an earlier transition, "
                    "which pytransitions takes; this one is dropped"
                )
                continue
            taken.add((source, trigger))
            machine.add_transition(source, trigger, dest, attrs=dict(attrs))
    return pending


def write_transitions(model: Model) -> str:
    """The pytransitions configuration of an FSM, as JSON (see the module docstring)."""
    if not isinstance(model, FSM):
        raise UnsupportedError("pytransitions holds state machines, not behavior trees")
    if model.start_name is not None:
        raise UnsupportedError(
            "a start pseudo-state left on an initial event (pytransitions starts in a state)"
        )
    top: dict[str, Any] = {"name": model.name}
    work: list[tuple[FSM, dict[str, Any]]] = [(model, top)]
    while work:
        machine, out = work.pop()
        if machine.initial is None:
            raise UnsupportedError(f"machine '{machine.name}' has no initial state")
        states: list[Any] = []
        for state in machine.states.values():
            if state.is_parallel:
                raise UnsupportedError(f"parallel state '{state.name}'")
            entry: dict[str, Any] = {"name": state.name}
            if state.final:
                entry["final"] = True
            if state.action is not None and (state.final or state.action != state.name):
                entry["on_enter"] = state.action.split("+")
            for key in ("on_exit", "tags"):
                if A_PREFIX + key in state.attrs:
                    entry[key] = json.loads(state.attrs[A_PREFIX + key])
            if state.is_composite:
                work.append((state.regions[0], entry))
            states.append(entry if len(entry) > 1 or state.is_composite else state.name)
        transitions: list[dict[str, Any]] = []
        for t in machine.transitions:
            if t.event is None:
                raise UnsupportedError(
                    f"completion transition {t.source} -> {t.target}: pytransitions moves on "
                    "triggers only"
                )
            transitions.append({"trigger": t.event, "source": t.source, "dest": t.target})
        key = "states" if out is top else "children"
        out[key] = states
        out["transitions"] = transitions
        out["initial"] = machine.initial
    top["auto_transitions"] = False
    top["ignore_invalid_triggers"] = True
    return json.dumps(top, indent=2) + "\n"
