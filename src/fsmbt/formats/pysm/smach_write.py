"""FSM -> a SMACH container module (Python) with stub states (docs/formats/smach.md).

The module defines one stub ``smach.State`` class per (action, outgoing events) pair - the
class's outcomes are the events that leave the states running that action; states running
the same action but leaving on different events get one class each (``Move``, ``Move_2``), as
SMACH has no way to say that a state ignores an outcome its class declares - and a function
``build_state_machine()`` that builds the machine with ``with sm: smach.StateMachine.add(...)``.
Mapping:
- final states are container outcomes; a composite state is a nested ``StateMachine`` whose
  outcomes are its final states, mapped by the parent's completion transitions;
- a transition on a composite state (an event that leaves it from any inner state) is pushed
  down: every inner state that does not handle the event gets it as an outcome leading to a
  new container outcome, which the parent maps to the target (same behaviour, docs/semantics.md
  §6: inner transitions first);
- a composite read from a SMACH ``Concurrence`` (its product machine unchanged) is written back
  as that ``Concurrence`` with its outcome map; any other parallel state, and a FlexBE
  ``ConcurrencyContainer``, is written as the nested ``StateMachine`` of its combined
  configurations (SMACH's Concurrence runs children independently and waits for all of them,
  which fsmbt's regions sharing events do not) and named as a loss;
- what SMACH cannot say is kept in a module-level ``__fsmbt__`` dict the SMACH reader honours
  (and SMACH ignores): actions that are not the class name, actions of final states, the start
  pseudo-state and its initial event, the model's name. Each of these is also a loss of the
  SMACH program itself (SMACH runs no action on a container outcome, and starts without
  waiting for an event) and is listed by ``smach_losses``.
Refused (``UnsupportedError``): eventless transitions of atomic states, a composite's final
state that no completion transition leaves (SMACH needs every container outcome mapped).

Everything walks the model with explicit stacks. Costs: O(S + T · D) for S states, T
transitions and nesting depth D (pushed-down transitions are copied into each level).
"""

from __future__ import annotations

import ast
import copy
import json
import keyword
import re
from dataclasses import dataclass, field

from fsmbt.formats.pysm.smach_data import A_CODE, DataPlan, split_data
from fsmbt.formats.registry import refuse_data_loss
from fsmbt.model import Model, state_info
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM, State, Transition

#: ``State.attrs`` the SMACH reader sets on a composite read from a container.
A_CONTAINER = "smach.container"
A_CHILDREN = "smach.children"
A_MAP = "smach.outcome_map"
A_DEFAULT = "smach.default_outcome"
#: (``smach.concurrence`` / ``smach.callbacks``: a concurrence with container children or
#: callbacks, written as the StateMachine of its product; ``translate`` names the loss.)
_READER_ATTRS = frozenset(
    {
        "class",
        A_CONTAINER,
        A_CHILDREN,
        A_MAP,
        A_DEFAULT,
        "flexbe.behaviour",
        A_CODE,
        "smach.concurrence",
        "smach.callbacks",
    }
)
#: ``state_info`` entries the SMACH program holds itself (constructor keyword arguments, the stub
#: class's outcomes and userdata keys, ``remapping=``, a container's keys and ``userdata``).
_WRITTEN_INFO = frozenset(
    {
        state_info.OUTCOMES,
        state_info.PARAMETERS,
        state_info.EXPRESSION_PARAMETERS,
        state_info.INPUT_KEYS,
        state_info.OUTPUT_KEYS,
        state_info.REMAPPING,
        state_info.USERDATA,
    }
)


@dataclass
class Written:
    """The module text and what the SMACH program itself cannot hold."""

    text: str
    losses: list[str] = field(default_factory=list)


def write_smach(model: Model) -> str:
    """The SMACH module for ``model`` (see the module docstring)."""
    return write_smach_with_losses(model).text


def smach_losses(model: Model) -> list[str]:
    """What the written SMACH program cannot hold (kept for fsmbt in ``__fsmbt__``)."""
    return write_smach_with_losses(model).losses


def write_smach_with_losses(model: Model) -> Written:
    """Write ``model`` and list its losses.

    Args:
        model: a (hierarchical) FSM.

    Returns:
        The module text and the losses, one sentence each.
    """
    if not isinstance(model, FSM):
        raise InputError("SMACH holds state machines, not behavior trees")
    refuse_data_loss(model, "smach")  # regions taking turns on data (registry.keeps_data)
    return _Writer(copy.deepcopy(model)).run()


# -- normalisation -------------------------------------------------------------------------------
def _machines(top: FSM) -> list[tuple[str, FSM, State | None]]:
    """Every machine with its label path and owning state, parents before children."""
    out: list[tuple[str, FSM, State | None]] = [("", top, None)]
    stack: list[tuple[str, FSM]] = [("", top)]
    while stack:
        path, machine = stack.pop()
        for state in machine.states.values():
            if state.is_composite:
                sub_path = f"{path}/{state.name}" if path else state.name
                out.append((sub_path, state.regions[0], state))
                stack.append((sub_path, state.regions[0]))
    return out


def _product_of_parallel(state: State, machine: FSM) -> None:
    """Replace parallel ``state`` by a composite whose machine is its flattened product.

    The sub-machine gets one final state per transition leaving ``state`` (the product's
    configurations reach it exactly when ``state`` would be left that way), and the parent's
    transitions become completion transitions on those finals.
    """
    leaving = [t for t in machine.transitions if t.source == state.name]
    inner = FSM(name=state.name)
    inner.states[state.name] = State(state.name, action=None, regions=state.regions)
    inner.initial = state.name
    exits: list[str] = []
    for index, t in enumerate(leaving):
        exit_name = f"to {t.target} #{index + 1}"
        exits.append(exit_name)
        inner.states[exit_name] = State(exit_name, action=None, final=True)
        inner.add_transition(state.name, t.event, exit_name, exit=t.exit)
    flat = flatten(inner)
    flat.name = state.name
    finals: dict[str, str] = {}
    for name, flat_state in flat.states.items():
        if flat_state.final and name in exits:
            finals[name] = name
    state.regions = [flat]
    state.attrs = {k: v for k, v in state.attrs.items() if k not in _READER_ATTRS}
    for t, exit_name in zip(leaving, exits):
        t.event = None
        t.exit = exit_name


def _push_down(top: FSM) -> None:
    """Move event transitions of composite states onto their inner states (parents first)."""
    for _path, machine, _owner in _machines(top):
        for state in list(machine.states.values()):
            if not state.is_composite:
                continue
            region = state.regions[0]
            moved = [
                t for t in machine.transitions if t.source == state.name and t.event is not None
            ]
            for t in moved:
                exit_name = _unique(f"on {t.event}", region.states)
                region.states[exit_name] = State(exit_name, action=None, final=True)
                handled = {s.source for s in region.transitions if s.event == t.event}
                for inner in region.states.values():
                    if inner.final or inner.name in handled:
                        continue
                    region.add_transition(inner.name, t.event, exit_name)
                t.event = None
                t.exit = exit_name


def _unique(name: str, taken: dict[str, State] | set[str]) -> str:
    if name not in taken:
        return name
    index = 2
    while f"{name} #{index}" in taken:
        index += 1
    return f"{name} #{index}"


def _identifier(text: str) -> str:
    words = re.findall(r"[A-Za-z0-9]+", text)
    name = "".join(w[:1].upper() + w[1:] for w in words) or "State"
    if name[0].isdigit():
        name = f"S{name}"
    if keyword.iskeyword(name) or name in ("State", "StateMachine", "Concurrence", "smach"):
        name = f"{name}State"
    return name


# -- writing ------------------------------------------------------------------------------------
class _Writer:
    def __init__(self, fsm: FSM) -> None:
        self.fsm = fsm
        self.losses: list[str] = []
        self.classes: dict[
            tuple[str | None, tuple[str, ...], tuple[str, ...], tuple[str, ...]], str
        ] = {}
        self.class_actions: dict[str, str | None] = {}
        self.class_order: list[
            tuple[str, tuple[str, ...], str | None, tuple[str, ...], tuple[str, ...]]
        ] = []
        self.undeclared: list[str] = []  # states whose declared outcomes the model did not know
        self.ros_states: list[str] = []  # generic ROS states written as stubs (a loss)
        self.final_actions: dict[str, dict[str, str | None]] = {}
        self.lines: list[str] = []
        self.counter = 0
        self.outgoing: dict[int, dict[str, list[Transition]]] = {}
        self.data = DataPlan()
        self.generated: list[tuple[str, tuple[str, ...], str]] = []  # (class, outcomes, code)

    def run(self) -> Written:
        self.data = split_data(self.fsm)  # docs/formats/smach.md, "Data"
        self.losses.extend(self.data.losses)
        self.prepare()
        body = self.machine_code()
        header = self.header()
        return Written("\n".join([*header, *body]) + "\n", self.losses)

    def prepare(self) -> None:
        top_attrs = {k for k in self.fsm.attrs if k not in _READER_ATTRS | _WRITTEN_INFO}
        if top_attrs:
            self.losses.append(
                f"model attributes {', '.join(sorted(top_attrs))} have no place in SMACH; dropped"
            )
        for path, machine, _owner in _machines(self.fsm):
            for state in list(machine.states.values()):
                where = f"'{path}/{state.name}'" if path else f"'{state.name}'"
                if state.is_parallel:
                    self.losses.append(
                        f"parallel state {where} written as the StateMachine of its combined "
                        "configurations: SMACH's Concurrence runs its children independently, "
                        "fsmbt's regions share events (docs/formats/smach.md)"
                    )
                    _product_of_parallel(state, machine)
                elif state.attrs.get(A_CONTAINER) == "ConcurrencyContainer":
                    self.losses.append(
                        f"FlexBE ConcurrencyContainer {where} written as the StateMachine of its "
                        "child-outcome combinations (SMACH's Concurrence waits for every child)"
                    )
                    state.attrs.pop(A_CONTAINER)
                if not state.is_atomic and state.action is not None:
                    self.losses.append(
                        f"composite state {where} has action '{state.action}', "
                        "which no semantics runs (docs/semantics.md §6); dropped"
                    )
                    state.action = None
                if state.attrs.get("class") == "CBState":
                    self.losses.append(
                        f"state {where} was a CBState calling "
                        f"'{state.action}'; written as a stub state class"
                    )
                self.info_losses(where, state)
                extra = {
                    k: v
                    for k, v in state.attrs.items()
                    if k not in _READER_ATTRS | _WRITTEN_INFO and k not in state_info.KEYS
                }
                if extra:
                    self.losses.append(
                        f"state {where}: attributes {', '.join(extra)} have no "
                        "place in SMACH; dropped"
                    )
            for t in machine.transitions:
                source = machine.states.get(t.source)
                if source is None or t.target not in machine.states:
                    raise InputError(
                        f"transition {t.source} -> {t.target} names an unknown state",
                        element=machine.name,
                    )
                if t.event is None and source.is_atomic:
                    raise UnsupportedError(
                        f"state '{t.source}' has an eventless transition to '{t.target}': a "
                        "SMACH state always returns an outcome; flatten the model first "
                        "(fsmbt translate --flatten) or remove the transient state"
                    )
                if "autonomy" in t.attrs and not any("autonomy" in x for x in self.losses):
                    self.losses.append(
                        "FlexBE autonomy levels of transitions have no place in SMACH; dropped"
                    )
                dropped = sorted(k for k in t.attrs if k != "autonomy")
                if dropped:
                    self.losses.append(
                        f"transition {t.source} -> {t.target}: attributes "
                        f"{', '.join(dropped)} have no place in SMACH; "
                        "dropped"
                    )
            acting = [s.name for s in machine.states.values() if s.final and s.action is not None]
            if acting:
                where = f" of '{path}'" if path else ""
                self.losses.append(
                    f"final state(s) {', '.join(acting)}{where} run an action in "
                    "the model; a SMACH container outcome runs nothing (kept in "
                    "__fsmbt__)"
                )
        if self.ros_states:
            shown = ", ".join(self.ros_states[:5])
            more = f" and {len(self.ros_states) - 5} more" if len(self.ros_states) > 5 else ""
            self.losses.append(
                f"{len(self.ros_states)} ROS action/service state(s) written as stub state "
                f"classes (the interface is not called): {shown}{more}"
            )
        _push_down(self.fsm)
        if self.fsm.start_name is not None and self.fsm.initial_event is not None:
            self.losses.append(
                f"the machine waits for '{self.fsm.initial_event}' in start "
                f"state '{self.fsm.start_name}' before '{self.fsm.initial}'; "
                "SMACH starts at once (kept in __fsmbt__)"
            )

    def info_losses(self, where: str, state: State) -> None:
        """What SMACH cannot hold of a state's ``state_info`` (the rest is written)."""
        ros = state_info.ros_interface(state)
        if ros is not None:
            self.ros_states.append(
                f"{where} ({ros[0]} {ros[1]}" + (f" on '{ros[2]}'" if ros[2] else "") + ")"
            )
        if state.attrs.get(state_info.CHILD_STATES) and (
            state.attrs.get(A_CONTAINER) != "Concurrence"
        ):
            self.losses.append(
                f"the configuration of the concurrent children of {where} (their parameters, "
                "userdata keys and remappings) has no place in the StateMachine written; dropped"
            )
        behaviour = state.attrs.get("flexbe.behaviour")
        if behaviour is not None:
            self.losses.append(
                f"state {where} embedded the FlexBE behaviour '{behaviour}'; written as "
                + ("a stub state class" if state.is_atomic else "a nested StateMachine")
                + " (the behaviour's name dropped)"
            )
        odd = [n for n in state_info.parameters(state) if n not in ("*", "**")]
        odd = [n for n in odd if not _is_identifier(n)]
        if odd:
            self.losses.append(
                f"state {where}: parameter(s) {', '.join(odd)} are not Python names; dropped"
            )
        if state_info.CLASS in state.attrs and state.attrs[state_info.CLASS] not in (
            "CBState",
            state.action,
        ):
            self.losses.append(
                f"state {where}: class '{state.attrs[state_info.CLASS]}' differs from its "
                "action; written as a stub class named after the action"
            )

    def state_class(
        self,
        action: str | None,
        outcomes: tuple[str, ...],
        inputs: tuple[str, ...] = (),
        outputs: tuple[str, ...] = (),
    ) -> str:
        key = (action, outcomes, inputs, outputs)
        if key not in self.classes:
            base = _identifier(action) if action is not None else "NoAction"
            name, index = base, 2
            while name in self.class_actions:  # a dict: O(1) per probe
                name, index = f"{base}_{index}", index + 1
            self.classes[key] = name
            self.class_actions[name] = action
            self.class_order.append((name, outcomes, action, inputs, outputs))
        return self.classes[key]

    def header(self) -> list[str]:
        title = self.fsm.name
        lines = [
            '"""SMACH state machine ' + repr(title) + ", written by fsmbt.",
            "",
            "Each state class is a stub: its execute() must return one of its outcomes.",
            "Build the machine with build_state_machine(); __fsmbt__ keeps what SMACH cannot",
            "say, for fsmbt to read back (SMACH ignores it).",
            '"""',
            "",
            "import smach",
            "",
        ]
        extension: dict[str, object] = {"version": 1, "name": self.fsm.name}
        actions = {name: action for name, action in self.class_actions.items() if action != name}
        if actions:
            extension["actions"] = actions
        finals = {path: acts for path, acts in self.final_actions.items() if acts}
        if finals:
            extension["final_actions"] = finals
        if self.fsm.start_name is not None and self.fsm.initial_event is not None:
            extension["start"] = {"name": self.fsm.start_name, "event": self.fsm.initial_event}
        if self.undeclared:
            extension["undeclared_outcomes"] = self.undeclared
        if self.data.variables:
            extension["data"] = self.data.extension()
        lines.append("__fsmbt__ = " + _py(extension))
        lines.append("")
        data_keys = [name for name, _expr in self.data.variables]
        for name, outcomes, code in self.generated:
            lines += [
                "",
                f"class {name}(smach.State):",
                '    """Generated by fsmbt from the data model (guards and assignments on',
                '    userdata; docs/formats/smach.md, "Data"). Not a stub: do not edit."""',
                "",
                "    def __init__(self):",
                f"        smach.State.__init__(self, outcomes={_py(list(outcomes))}, "
                f"input_keys={_py(data_keys)}, output_keys={_py(data_keys)})",
                "",
                code,
                "",
            ]
        for name, outcomes, action, inputs, outputs in self.class_order:
            keys = (f", input_keys={_py(list(inputs))}" if inputs else "") + (
                f", output_keys={_py(list(outputs))}" if outputs else ""
            )
            lines += [
                "",
                f"class {name}(smach.State):",
                f'    """Runs action {action!r}."""'
                if action is not None
                else '    """Runs nothing."""',
                "",
                "    def __init__(self, **parameters):",
                f"        smach.State.__init__(self, outcomes={_py(list(outcomes))}{keys})",
                "        self.parameters = parameters",
                "",
                "    def execute(self, userdata):",
                f"        raise NotImplementedError({_py(f'{name}: return one of ' + ', '.join(outcomes))})",
                "",
            ]
        return lines

    def machine_code(self) -> list[str]:
        lines = [
            "",
            "def build_state_machine():",
            '    """The top-level container (not executed here)."""',
        ]
        root_var = self.emit_machine(self.fsm, "", 1, lines)
        lines.append(f"    return {root_var}")
        lines += ["", "", 'if __name__ == "__main__":', "    build_state_machine().execute()"]
        return lines

    def emit_machine(self, top: FSM, top_path: str, indent: int, lines: list[str]) -> str:
        """Emit ``top`` and every nested machine (explicit stack); returns the top's variable."""
        # frames: (machine, path, var, indent, remaining states, pending add line after sub)
        first_var = self.new_container(top, top_path, indent, lines, top)
        stack: list[tuple[FSM, str, str, int, list[State], list[str] | None]] = [
            (
                top,
                top_path,
                first_var,
                indent + 1,
                [s for s in reversed(top.states.values()) if not s.final],
                self.initial_line(top, first_var, indent),
            )
        ]
        while stack:
            machine, path, var, level, remaining, after = stack[-1]
            if not remaining:
                stack.pop()
                if after is not None:
                    lines.extend(after)
                continue
            state = remaining.pop()  # the lists are reversed: pop() takes the next state
            pad = "    " * level
            transitions = self.transitions_of(machine, state)
            if state.is_composite:
                sub_path = f"{path}/{state.name}" if path else state.name
                region = state.regions[0]
                concurrence = self.concurrence(state, region)
                if concurrence is not None:
                    sub_var = self.emit_concurrence(state, concurrence, level, lines, sub_path)
                    lines.extend(_position_comment(state, pad))
                    lines.append(
                        f"{pad}smach.StateMachine.add({_py(state.name)}, {sub_var}, "
                        f"transitions={_py(transitions)}{_remapping(state)})"
                    )
                    continue
                sub_var = self.new_container(region, sub_path, level, lines, state)
                after_lines = [
                    *self.initial_line(region, sub_var, level),
                    *_position_comment(state, pad),
                    f"{pad}smach.StateMachine.add({_py(state.name)}, {sub_var}, "
                    f"transitions={_py(transitions)}{_remapping(state)})",
                ]
                stack.append(
                    (
                        region,
                        sub_path,
                        sub_var,
                        level + 1,
                        [s for s in reversed(region.states.values()) if not s.final],
                        after_lines,
                    )
                )
                continue
            if A_CODE in state.attrs:  # a decision or reset state (smach_data)
                cls = f"FsmbtData{len(self.generated) + 1}"
                self.generated.append((cls, tuple(transitions), state.attrs[A_CODE]))
                lines.append(
                    f"{pad}smach.StateMachine.add({_py(state.name)}, {cls}(), "
                    f"transitions={_py(transitions)})"
                )
                continue
            cls = self.state_class(
                state.action,
                tuple(transitions),
                tuple(state_info.input_keys(state)),
                tuple(state_info.output_keys(state)),
            )
            if state_info.declared_outcomes(state) is None:
                self.undeclared.append(f"{path}/{state.name}" if path else state.name)
            lines.extend(_position_comment(state, pad))
            lines.append(
                f"{pad}smach.StateMachine.add({_py(state.name)}, {cls}({_arguments(state)}), "
                f"transitions={_py(transitions)}{_remapping(state)})"
            )
        return first_var

    def new_container(
        self, machine: FSM, path: str, level: int, lines: list[str], holder: State | FSM
    ) -> str:
        """``smach.StateMachine(...)`` for ``machine`` with the userdata keys and initial
        values of ``holder`` (its composite state, or the top FSM), then ``with``."""
        finals = [s for s in machine.states.values() if s.final]
        if machine.initial is None or machine.states.get(machine.initial) is None:
            raise InputError(
                "a machine without initial state cannot be written", element=machine.name
            )
        if machine.states[machine.initial].final:
            raise UnsupportedError(
                f"machine '{machine.name}' starts in a final state; a SMACH "
                "container needs a state to run first"
            )
        self.final_actions[path] = {s.name: s.action for s in finals if s.action is not None}
        var = f"sm_{self.counter}"
        self.counter += 1
        pad = "    " * level
        variables = [name for name, _expr in self.data.variables]
        nested = holder is not self.fsm and bool(variables)  # data passes through containers
        keys = "".join(
            f", {name}={_py(found)}"
            for name, found in (
                ("input_keys", _merged(state_info.input_keys(holder), variables, nested)),
                ("output_keys", _merged(state_info.output_keys(holder), variables, nested)),
            )
            if found
        )
        lines.append(
            f"{pad}{var} = smach.StateMachine(outcomes={_py([s.name for s in finals])}{keys})"
        )
        for key, value in state_info.userdata_values(holder).items():
            target = f"{var}.userdata.{key}" if _is_identifier(key) else f"{var}.userdata[{key!r}]"
            lines.append(f"{pad}{target} = {_python_value(value, False)}")
        if holder is self.fsm:
            for name, expr in self.data.initial:  # the data model's initial values
                lines.append(f"{pad}{var}.userdata.{name} = {expr}")
        lines.append(f"{pad}with {var}:")
        return var

    def initial_line(self, machine: FSM, var: str, level: int) -> list[str]:
        """``set_initial_state`` after the ``with`` block, when the first state is not it."""
        ordered = [s for s in machine.states.values() if not s.final]
        if ordered and ordered[0].name != machine.initial:
            return [f"{'    ' * level}{var}.set_initial_state([{_py(machine.initial)}])"]
        return []

    def transitions_of(self, machine: FSM, state: State) -> dict[str, str]:
        out: dict[str, str] = {}
        index = self.outgoing.get(id(machine))
        if index is None:
            index = {}
            for t in machine.transitions:
                index.setdefault(t.source, []).append(t)
            self.outgoing[id(machine)] = index
        for t in index.get(state.name, []):
            if state.is_atomic:
                key = t.event
            else:
                key = t.exit
                if key is None:
                    raise UnsupportedError(
                        f"composite state '{state.name}' has a completion "
                        "transition on any final state; SMACH maps each "
                        "container outcome: name the final state (exit)"
                    )
            assert key is not None
            if key not in out:
                out[key] = t.target
        if not state.is_atomic:
            region = state.regions[0]
            for inner in region.states.values():
                if inner.final and inner.name not in out:
                    raise UnsupportedError(
                        f"composite state '{state.name}': its final state '{inner.name}' has no "
                        "completion transition; SMACH needs every container outcome mapped"
                    )
        return out

    # -- concurrence --------------------------------------------------------------------------
    def concurrence(self, state: State, region: FSM) -> dict[str, object] | None:
        """The Concurrence spec when ``state`` is an unchanged SMACH Concurrence product."""
        if state.attrs.get(A_CONTAINER) != "Concurrence":
            return None
        try:
            children = json.loads(state.attrs[A_CHILDREN])
            outcome_map = json.loads(state.attrs.get(A_MAP, "[]"))
        except (KeyError, ValueError):
            return None
        spec = {
            "children": children,
            "outcome_map": outcome_map,
            "default": state.attrs.get(A_DEFAULT),
            "outcomes": [s.name for s in region.states.values() if s.final],
        }
        if "smach.callbacks" in state.attrs:
            self.losses.append(
                f"Concurrence '{state.name}' had callbacks ({state.attrs['smach.callbacks']}), "
                "read as environment choices: written as the StateMachine of its combinations, "
                "with a state for its outcome_cb (its children's configuration dropped)"
            )
            return None
        if not _product_matches(spec, region):
            self.losses.append(
                f"Concurrence '{state.name}' was changed after reading; written "
                "as the StateMachine of its combinations (its children's configuration "
                "dropped)"
            )
            return None
        return spec

    def emit_concurrence(
        self, state: State, spec: dict[str, object], level: int, lines: list[str], path: str
    ) -> str:
        """The ``Concurrence`` read back unchanged, with its own keys and userdata and each
        child's parameters, keys and remapping (``state_info.CHILD_STATES``)."""
        var = f"cc_{self.counter}"
        self.counter += 1
        pad = "    " * level
        outcome_map: dict[str, dict[str, str]] = {}
        for outcome, required in spec["outcome_map"]:  # type: ignore[attr-defined]
            outcome_map[outcome] = required
        keys = "".join(
            f", {name}={_py(found)}"
            for name, found in (
                ("input_keys", state_info.input_keys(state)),
                ("output_keys", state_info.output_keys(state)),
            )
            if found
        )
        lines.append(
            f"{pad}{var} = smach.Concurrence(outcomes={_py(spec['outcomes'])}, "
            f"default_outcome={_py(spec['default'])}, outcome_map={_py(outcome_map)}{keys})"
        )
        for key, value in state_info.userdata_values(state).items():
            target = f"{var}.userdata.{key}" if _is_identifier(key) else f"{var}.userdata[{key!r}]"
            lines.append(f"{pad}{target} = {_python_value(value, False)}")
        lines.append(f"{pad}with {var}:")
        children = state_info.child_states(state)
        for label, action, outcomes in spec["children"]:  # type: ignore[attr-defined]
            child = State(label, action=action, attrs=children.get(label, {}))
            cls = self.state_class(
                action,
                tuple(outcomes),
                tuple(state_info.input_keys(child)),
                tuple(state_info.output_keys(child)),
            )
            if state_info.declared_outcomes(child) is None:
                self.undeclared.append(f"{path}/{label}" if path else label)
            lines.extend(_position_comment(child, pad + "    "))
            lines.append(
                f"{pad}    smach.Concurrence.add({_py(label)}, {cls}({_arguments(child)})"
                f"{_remapping(child)})"
            )
        return var


def _product_matches(spec: dict[str, object], region: FSM) -> bool:
    """Does ``region`` equal the product the reader builds from ``spec``?"""
    from fsmbt.formats.pysm.analyze import Child, Container, StateRef
    from fsmbt.formats.pysm.build import build_concurrence

    container = Container("Concurrence", "concurrence", list(spec["outcomes"]), 0)  # type: ignore[call-overload]
    container.default_outcome = spec["default"]  # type: ignore[assignment]
    container.outcome_map = [(o, dict(m)) for o, m in spec["outcome_map"]]  # type: ignore[attr-defined]
    for label, action, outcomes in spec["children"]:  # type: ignore[attr-defined]
        container.children.append(Child(label, StateRef(action, list(outcomes), 0), {}, 0))
    try:
        rebuilt = build_concurrence(container, region.name)
    except InputError:
        return False
    return (
        rebuilt.states.keys() == region.states.keys()
        and all(
            rebuilt.states[n].action == region.states[n].action
            and rebuilt.states[n].final == region.states[n].final
            for n in region.states
        )
        and rebuilt.initial == region.initial
        and [(t.source, t.event, t.target) for t in rebuilt.transitions]
        == [(t.source, t.event, t.target) for t in region.transitions]
    )


def _merged(found: list[str], variables: list[str], add: bool) -> list[str]:
    """A container's userdata keys, with the data model's variables when ``add``."""
    if not add:
        return list(found)
    return list(dict.fromkeys([*found, *variables]))


def _is_identifier(name: str) -> bool:
    return name.isidentifier() and not keyword.iskeyword(name)


def _python_value(text: str, expression: bool) -> str:
    """A parameter's Python source: an expression's own text (when it parses as one), a JSON
    number / boolean / null / list / dict as that Python literal, any other text a string
    (reading it back gives the same text, docs/formats/smach.md)."""
    if expression:
        try:
            ast.parse(text, mode="eval")
            return text
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            return repr(text)
    try:
        value = json.loads(text)
    except ValueError:
        return repr(text)
    if isinstance(value, str) or json.dumps(value) != text:
        return repr(text)
    return repr(value)


def _arguments(state: State) -> str:
    """The stub state's constructor arguments: its parameters as keywords (``*`` / ``**``
    expression parameters as unpacking)."""
    expressions = set(state_info.expression_parameters(state))
    parts: list[str] = []
    for name, value in state_info.parameters(state).items():
        source = _python_value(value, name in expressions)
        if name == "*":
            parts.insert(0, f"*{source}")
        elif name == "**":
            parts.append(f"**{source}")
        elif _is_identifier(name):
            parts.append(f"{name}={source}")
    return ", ".join(parts)


def _position_comment(state: State, pad: str) -> list[str]:
    """The FlexBE editor's ``# x:.. y:..`` comment above the ``add`` (read back as the
    state's position, docs/formats/flexbe.md)."""
    at = state_info.position(state)
    return [f"{pad}# x:{at[0]} y:{at[1]}"] if at is not None else []


def _remapping(state: State) -> str:
    remap = state_info.remapping(state)
    return f", remapping={_py(remap)}" if remap else ""


def _py(value: object) -> str:
    """A Python literal for strings, lists, dicts and None (``repr`` is exact for these)."""
    return repr(value)
