"""The paper's "States / Transitions" text form of an (H)FSM (format ``paper-text``, ``.txt``).

Layout (indentation = two spaces per level; ``#`` starts a comment line)::

    FSM paper_aj
    Start: Start --eventSA--> A        (or ``Initial: A`` when there is no start event)
    States:
      A                                 (action = the name)
      B [action=Move B]                 (another action; ``[action=]`` = none)
      H [final]
      Seq [composite]                   (a sub-FSM follows, indented)
        Initial: x
        States:
          x
          SUCCESS [final]
        Transitions:
          x --success--> SUCCESS
    Transitions:
      A --eventAB--> B
      Seq --(exit SUCCESS)--> B          (completion transition; ``--()-->`` = on any end)

Names may not contain whitespace, ``[``, ``]`` or ``--``; the writer refuses such a model with
an ``UnsupportedError``. Parallel states are not expressible here. Reading is line by line with
an explicit stack: O(lines).
"""

from __future__ import annotations

import re

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model import Model
from fsmbt.model.errors import Hint, InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State

HEADER = "FSM"
_TRANSITION = re.compile(r"^(\S+)\s+--(.*?)-->\s+(\S+)$")
_STATE = re.compile(r"^(\S+)(?:\s+\[(.*)\])?$")
_EXIT = re.compile(r"^\(\s*(?:exit\s+(\S+))?\s*\)$")


def _check_name(name: str, what: str) -> str:
    if not name or re.search(r"\s|\[|\]|--", name):
        raise UnsupportedError(
            f"{what} name {name!r} cannot be written in paper-text "
            "(no whitespace, brackets or '--')"
        )
    return name


# -- writing ------------------------------------------------------------------------------------
def write_paper_text(model: Model) -> str:
    if not isinstance(model, FSM):
        raise InputError("paper-text holds state machines only")
    lines = [f"{HEADER} {_check_name(model.name or 'fsm', 'machine')}"]
    # explicit stack of (machine, indent, top-level?) blocks, written depth first
    _write_machine(model, 0, lines, top=True)
    return "\n".join(lines) + "\n"


def _write_machine(fsm: FSM, indent: int, lines: list[str], *, top: bool) -> None:
    work: list[tuple[str, object, int]] = [("machine", fsm, indent)]
    while work:
        what, item, level = work.pop()
        pad = "  " * level
        if what == "line":
            lines.append(str(item))
            continue
        machine: FSM = item  # type: ignore[assignment]
        block: list[tuple[str, object, int]] = []
        if machine.initial_event is not None and machine is fsm and top:
            start = _check_name(machine.start_name or "Start", "start")
            block.append(
                ("line", f"{pad}Start: {start} --{machine.initial_event}--> {machine.initial}", 0)
            )
        elif machine.initial is not None:
            block.append(("line", f"{pad}Initial: {machine.initial}", 0))
        block.append(("line", f"{pad}States:", 0))
        for state in machine.states.values():
            _check_name(state.name, "state")
            tags = []
            if state.final:
                tags.append("final")
            if state.action != state.name:
                tags.append(f"action={state.action or ''}")
            if state.is_parallel:
                raise UnsupportedError(
                    "parallel states cannot be written in paper-text", element=state.name
                )
            if state.is_composite:
                tags.append("composite")
            suffix = f" [{', '.join(tags)}]" if tags else ""
            block.append(("line", f"{pad}  {state.name}{suffix}", 0))
            if state.is_composite:
                block.append(("machine", state.regions[0], level + 2))
        block.append(("line", f"{pad}Transitions:", 0))
        for t in machine.transitions:
            if t.event is None:
                label = f"(exit {t.exit})" if t.exit is not None else "()"
            else:
                label = t.event
                if "-->" in label or not label.strip() or label != label.strip():
                    raise UnsupportedError(f"event {label!r} cannot be written in paper-text")
            block.append(("line", f"{pad}  {t.source} --{label}--> {t.target}", 0))
        work.extend(reversed(block))


# -- reading ------------------------------------------------------------------------------------
def read_paper_text(text: str, ctx: ReadContext) -> Model:
    fsm: FSM | None = None
    # stack of (indent of the block's keywords, machine, current section)
    stack: list[list] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        if not raw.strip() or raw.lstrip().startswith("#"):
            continue
        if "\t" in raw[: len(raw) - len(raw.lstrip())]:
            raise InputError("indent with spaces, not tabs", location=ctx.location(number))
        indent = len(raw) - len(raw.lstrip(" "))
        line = raw.strip()
        if fsm is None:
            if not line.startswith(HEADER + " ") and line != HEADER:
                raise InputError(
                    "not fsmbt's paper-text format (it starts with 'FSM <name>'); "
                    "a description in prose needs an LLM to extract the model",
                    location=ctx.location(number),
                    hints=(Hint.LLM_ENGINE,),
                )
            fsm = FSM(name=line[len(HEADER) :].strip() or "fsm")
            stack.append([0, fsm, None])
            continue
        while stack and indent < stack[-1][0]:
            stack.pop()
        if not stack:
            raise InputError("unexpected indentation", location=ctx.location(number))
        block = stack[-1]
        machine: FSM = block[1]
        where = ctx.location(number)
        if indent == block[0]:
            if line.startswith("Start:"):
                match = _TRANSITION.match(line[6:].strip())
                if match is None:
                    raise InputError("expected 'Start: S --event--> A'", location=where)
                machine.start_name, machine.initial_event, machine.initial = match.groups()
            elif line.startswith("Initial:"):
                machine.initial = line[8:].strip()
            elif line in ("States:", "Transitions:"):
                block[2] = line[:-1]
            else:
                raise InputError(
                    f"expected States:, Transitions:, Initial: or Start:, not {line!r}",
                    location=where,
                )
            continue
        if block[2] == "States":
            match = _STATE.match(line)
            if match is None:
                raise InputError(f"malformed state line {line!r}", location=where)
            name, tags = match.group(1), match.group(2) or ""
            state = State(name, action=name, location=where)
            composite = False
            for tag in (t.strip() for t in tags.split(",") if t.strip()):
                if tag == "final":
                    state.final = True
                elif tag == "composite":
                    composite = True
                elif tag.startswith("action="):
                    state.action = tag[7:] or None
                else:
                    raise InputError(f"unknown state tag {tag!r}", location=where)
            if name in machine.states:
                raise InputError(f"duplicate state '{name}'", location=where)
            keep_initial = machine.initial
            machine.add_state(state)
            machine.initial = keep_initial if keep_initial is not None else name
            if composite:
                sub = FSM(name=name)
                state.regions.append(sub)
                stack.append([indent + 2, sub, None])
        elif block[2] == "Transitions":
            match = _TRANSITION.match(line)
            if match is None:
                raise InputError(f"malformed transition {line!r}", location=where)
            source, label, target = match.groups()
            exit_match = _EXIT.match(label.strip())
            if exit_match is not None:
                machine.add_transition(
                    source, None, target, exit=exit_match.group(1), location=where
                )
            else:
                machine.add_transition(source, label, target, location=where)
        else:
            raise InputError(
                "a state or transition line before 'States:'/'Transitions:'", location=where
            )
    if fsm is None:
        raise InputError("empty paper-text input", location=ctx.location())
    for _path, owner, parent in [("", fsm, None), *fsm.walk()]:
        machines = [owner] if parent is None else list(parent.regions)
        for m in machines:
            for t in m.transitions:
                for end in (t.source, t.target):
                    if end not in m.states:
                        raise InputError(
                            f"transition refers to unknown state '{end}'",
                            location=t.location,
                            element=m.name,
                        )
    return fsm


def _sniff(text: str) -> bool:
    for line in text.splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            return stripped.startswith(HEADER + " ") and "States:" in text
    return False


register(
    Format(
        "paper-text",
        (".txt",),
        frozenset({"fsm"}),
        "the paper's 'States / Transitions' text (hierarchy by indentation)",
        read_paper_text,
        write_paper_text,
        _sniff,
        priority=60,
        cannot_hold="parallel states",
    )
)
