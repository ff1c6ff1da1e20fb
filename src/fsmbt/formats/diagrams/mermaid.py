"""Mermaid ``stateDiagram-v2`` (read and write), flat and hierarchical (docs/formats/mermaid.md).

What is read, line by line (one statement a line, Mermaid's usual form):

- ``[*] --> A`` initial state of the current level; ``[*] --> A : ev`` also an initial event
  (the start pseudo-state is named by a preceding ``%% fsmbt-start: "Name"`` line, else
  ``Start``); ``A --> [*]`` marks ``A`` final;
- ``A --> B : event`` a transition; ``A --> B`` without a label is eventless (a completion
  transition: from a composite state it fires when the sub-machine reaches a final state);
- ``state "text" as X`` / ``X : text`` the state's action (its description); on a composite
  state the text is kept as ``attrs["description"]``, because composite states run no action;
- ``state C {`` ... ``}`` a composite state whose body is its sub-machine (``State.regions``);
- ignored, by design: ``%%`` comments, notes (one-line and ``note ... end note``), ``direction``,
  ``classDef``/``class``/``style``/``click``/``:::class``, ``accTitle``/``accDescr``; a
  ``---``/``title:`` front matter gives the machine's name;
- refused with ``UnsupportedError`` and the line: ``<<fork>>``, ``<<join>>``, ``<<choice>>``,
  concurrency (``--``), a labelled transition to ``[*]``, and a transition between states of
  different levels (Mermaid ids are global; our transitions stay within one level).

Writer directives (comments Mermaid ignores, the reader honours): ``%% fsmbt-name: id = "name"``
for a state name that is not a Mermaid identifier, ``%% fsmbt-no-action: id`` for a state
without action, ``%% fsmbt-start: "Name"`` for the start pseudo-state's name, and
``%% fsmbt-exit: "X"`` before a completion transition that fires only when the composite state's
sub-machine ends in its final state ``X`` (a BT -> FSM conversion leaves a unit by ``SUCCESS`` or
``FAILURE``): the transition is drawn ``U --> T : X``, so a person reads "when U ends in X, go
to T", and the directive tells fsmbt's reader that ``X`` is an exit, not an event.
Parsing is O(lines); nesting is handled with an explicit stack.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model import Model
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State

_ID = r"[\w.]+(?:-[\w.]+)*"
_HEADER = re.compile(r"^stateDiagram(?:-v2)?\s*$")
_TRANSITION = re.compile(rf"^({_ID}|\[\*\])\s*-->\s*({_ID}|\[\*\])\s*(?::(.*))?$")
_STATE_AS = re.compile(rf'^state\s+"([^"]*)"\s+as\s+({_ID})\s*(\{{)?\s*$')
_STATE_SPECIAL = re.compile(rf"^state\s+({_ID})\s*<<\s*(\w+)\s*>>\s*$")
_STATE_PLAIN = re.compile(rf"^state\s+({_ID})\s*(\{{)?\s*$")
_DESCRIPTION = re.compile(rf"^({_ID})\s*:(.*)$")
_BARE_ID = re.compile(rf"^({_ID})$")
_CLASS_SUFFIX = re.compile(r":::[\w-]+")
_NOTE_ONE_LINE = re.compile(r"^note\s+(left|right)\s+of\s+\S+\s*:")
_IGNORED_KEYWORDS = (
    "direction",
    "classDef",
    "class",
    "style",
    "click",
    "accTitle",
    "accDescr",
    "linkStyle",
)
_DIRECTIVE_NAME = re.compile(r'^%%\s*fsmbt-name:\s*(\S+)\s*=\s*(".*")\s*$')
_DIRECTIVE_NO_ACTION = re.compile(r"^%%\s*fsmbt-no-action:\s*(\S+)\s*$")
_DIRECTIVE_START = re.compile(r'^%%\s*fsmbt-start:\s*(".*")\s*$')
_DIRECTIVE_EXIT = re.compile(r'^%%\s*fsmbt-exit:\s*(".*")\s*$')
_WRITABLE_ID = re.compile(r"^[A-Za-z_]\w*$")
_KEYWORDS = frozenset(
    {
        "state",
        "note",
        "end",
        "direction",
        "class",
        "classDef",
        "style",
        "click",
        "as",
        "stateDiagram",
        "accTitle",
        "accDescr",
        "linkStyle",
    }
)


@dataclass
class _Level:
    machine: FSM
    owner: str | None  # composite state's name, None at the top
    line: int
    initial: str | None = None
    describes: dict[str, int] = field(default_factory=dict)  # state -> line of its description


class _MermaidReader:
    def __init__(self, ctx: ReadContext) -> None:
        self.ctx = ctx
        self.top = FSM(name=ctx.path.stem if ctx.path is not None else "fsm")
        self.levels: list[_Level] = [_Level(self.top, None, 0)]
        self.home: dict[str, _Level] = {}  # Mermaid id -> the level that holds the state
        self.names: dict[str, str] = {}  # Mermaid id -> fsmbt name (fsmbt-name directives)
        self.no_action: set[str] = set()
        self.pending_start: str | None = None
        self.pending_exit: tuple[str, int] | None = None  # fsmbt-exit directive, its line

    # -- helpers ---------------------------------------------------------------------------
    def fail(self, message: str, line: int, unsupported: bool = False) -> InputError:
        cls = UnsupportedError if unsupported else InputError
        return cls(message, location=self.ctx.location(line))

    @property
    def level(self) -> _Level:
        return self.levels[-1]

    def declare(self, mermaid_id: str, line: int) -> State:
        """The state ``mermaid_id`` of the current level, created on first use."""
        home = self.home.get(mermaid_id)
        if home is not None and home is not self.level:
            where = f"inside composite state '{home.owner}'" if home.owner else "at the top level"
            raise self.fail(
                f"state '{mermaid_id}' belongs {where}; transitions across "
                "composite state boundaries are not supported",
                line,
                True,
            )
        name = self.names.get(mermaid_id, mermaid_id)
        machine = self.level.machine
        if home is None:
            self.home[mermaid_id] = self.level
            action = None if mermaid_id in self.no_action else name
            machine.add_state(State(name, action=action, location=self.ctx.location(line)))
        return machine.states[name]

    def describe(self, mermaid_id: str, text: str, line: int) -> None:
        state = self.declare(mermaid_id, line)
        text = text.strip()
        earlier = self.level.describes.get(state.name)
        if earlier is not None and state.action != text:
            raise self.fail(
                f"state '{mermaid_id}' is described twice ('{state.action}' on line "
                f"{earlier}, '{text}' here)",
                line,
            )
        self.level.describes[state.name] = line
        state.action = text

    # -- statements -------------------------------------------------------------------------
    def transition(self, source: str, target: str, label: str | None, line: int) -> None:
        event = label.strip() if label is not None and label.strip() else None
        if self.pending_exit is not None:
            self.exit_transition(source, target, event, line)
            return
        if source == "[*]" and target == "[*]":
            raise self.fail("'[*] --> [*]' names no state", line)
        if source == "[*]":
            state = self.declare(target, line)
            if self.level.initial is not None and self.level.initial != state.name:
                raise self.fail(
                    f"two initial states at one level: '{self.level.initial}' and '{state.name}'",
                    line,
                )
            self.level.initial = state.name
            if event is not None:
                self.level.machine.initial_event = event
                self.level.machine.start_name = self.pending_start or "Start"
            self.pending_start = None
            return
        if target == "[*]":
            if event is not None:
                raise self.fail(
                    f"a labelled transition to [*] ('{event}'); add an explicit "
                    "final state and a transition to it",
                    line,
                    True,
                )
            self.declare(source, line).final = True
            return
        src = self.declare(source, line)
        dst = self.declare(target, line)
        self.level.machine.add_transition(
            src.name, event, dst.name, location=self.ctx.location(line)
        )

    def exit_transition(self, source: str, target: str, label: str | None, line: int) -> None:
        """The transition after an ``fsmbt-exit`` directive: a completion transition by exit."""
        assert self.pending_exit is not None
        exit_name, directive_line = self.pending_exit
        self.pending_exit = None
        if "[*]" in (source, target):
            raise self.fail(
                f"the fsmbt-exit directive on line {directive_line} must precede a "
                "transition between two states",
                line,
            )
        if label is not None and label != exit_name:
            raise self.fail(
                f"the transition's label '{label}' differs from the exit "
                f"'{exit_name}' named by the fsmbt-exit directive on line "
                f"{directive_line}",
                line,
            )
        src = self.declare(source, line)
        dst = self.declare(target, line)
        self.level.machine.add_transition(
            src.name, None, dst.name, exit=exit_name, location=self.ctx.location(line)
        )

    def open_composite(self, mermaid_id: str, description: str | None, line: int) -> None:
        state = self.declare(mermaid_id, line)
        if state.regions:
            raise self.fail(f"composite state '{mermaid_id}' is opened twice", line)
        if description is not None:
            self.describe(mermaid_id, description, line)
        region = FSM(name=state.name)
        state.regions.append(region)
        self.levels.append(_Level(region, state.name, line))

    def close_level(self, line: int) -> None:
        if len(self.levels) == 1:
            raise self.fail("'}' closes no composite state", line)
        self.finish(self.levels.pop())

    def finish(self, level: _Level) -> None:
        machine = level.machine
        machine.initial = level.initial
        for state in machine.states.values():
            if state.regions:  # composite: its description is not an action
                if state.action not in (None, state.name):
                    state.attrs["description"] = state.action
                state.action = None

    # -- driver -----------------------------------------------------------------------------
    def read(self, text: str) -> FSM:
        lines = text.splitlines()
        index = self.skip_front_matter(lines)
        seen_header = False
        skip_until: str | None = None
        for number in range(index, len(lines)):
            line_no = number + 1
            line = _CLASS_SUFFIX.sub("", lines[number]).strip()
            if skip_until is not None:
                if line == skip_until or (skip_until == "}" and line.endswith("}")):
                    skip_until = None
                continue
            if not line:
                continue
            if line.startswith("%%"):
                self.directive(line, line_no)
                continue
            if not seen_header:
                if not _HEADER.match(line):
                    raise self.fail(
                        f"not a Mermaid state diagram: expected 'stateDiagram-v2', "
                        f"found {line[:40]!r}",
                        line_no,
                    )
                seen_header = True
                continue
            if self.pending_exit is not None and not _TRANSITION.match(line):
                raise self.fail(
                    f"the fsmbt-exit directive on line {self.pending_exit[1]} must "
                    "be followed by a transition",
                    line_no,
                )
            skip_until = self.statement(line, line_no)
        if not seen_header:
            raise self.fail("not a Mermaid state diagram: no 'stateDiagram-v2' line", 1)
        if skip_until is not None:
            raise self.fail(f"unterminated block: expected '{skip_until}'", len(lines))
        if len(self.levels) > 1:
            raise self.fail(
                f"composite state '{self.level.owner}' opened here is never closed", self.level.line
            )
        self.finish(self.levels[0])
        if not self.top.states:
            raise self.fail("the state diagram has no states", len(lines))
        return self.top

    def skip_front_matter(self, lines: list[str]) -> int:
        """Skip a leading ``---`` block; its ``title:`` names the machine."""
        first = next((i for i, text in enumerate(lines) if text.strip()), None)
        if first is None or lines[first].strip() != "---":
            return 0
        for i in range(first + 1, len(lines)):
            stripped = lines[i].strip()
            if stripped == "---":
                return i + 1
            if stripped.startswith("title:"):
                title = stripped[len("title:") :].strip()
                if title.startswith('"'):
                    try:
                        title = str(json.loads(title))
                    except json.JSONDecodeError:
                        title = title.strip('"')
                self.top.name = title or self.top.name
        raise self.fail("front matter '---' is never closed", first + 1)

    def directive(self, line: str, line_no: int) -> None:
        if match := _DIRECTIVE_EXIT.match(line):
            if self.pending_exit is not None:
                raise self.fail(
                    "two fsmbt-exit directives without a transition between them", line_no
                )
            try:
                self.pending_exit = (str(json.loads(match.group(1))), line_no)
            except json.JSONDecodeError:
                raise self.fail("the fsmbt-exit directive needs a quoted name", line_no) from None
        elif match := _DIRECTIVE_NAME.match(line):
            if match.group(1) in self.home:  # the state exists under its id: too late to rename
                raise self.fail(
                    f"the fsmbt-name directive for '{match.group(1)}' comes after "
                    "that state is used; put it before the first use",
                    line_no,
                )
            try:
                self.names[match.group(1)] = str(json.loads(match.group(2)))
            except json.JSONDecodeError:
                raise self.fail("the fsmbt-name directive needs a quoted name", line_no) from None
        elif match := _DIRECTIVE_NO_ACTION.match(line):
            self.no_action.add(match.group(1))
        elif match := _DIRECTIVE_START.match(line):
            self.pending_start = json.loads(match.group(1))

    def statement(self, line: str, line_no: int) -> str | None:
        """Handle one statement; returns the line that ends a block to skip, if any."""
        if line == "}":
            self.close_level(line_no)
            return None
        if line == "--":
            raise self.fail("concurrent regions ('--') are not supported", line_no, True)
        first_word = line.split(None, 1)[0].rstrip(":")
        if first_word == "note":
            return None if _NOTE_ONE_LINE.match(line) else "end note"
        if first_word in _IGNORED_KEYWORDS:
            return "}" if line.endswith("{") else None
        if match := _TRANSITION.match(line):
            self.transition(match.group(1), match.group(2), match.group(3), line_no)
            return None
        if match := _STATE_SPECIAL.match(line):
            kind = match.group(2)
            raise self.fail(
                f"<<{kind}>> pseudo-states are not supported",
                line_no,
                unsupported=kind in ("fork", "join", "choice"),
            )
        if match := _STATE_AS.match(line):
            if match.group(3):
                self.open_composite(match.group(2), match.group(1), line_no)
            else:
                self.describe(match.group(2), match.group(1), line_no)
            return None
        if match := _STATE_PLAIN.match(line):
            if match.group(2):
                self.open_composite(match.group(1), None, line_no)
            else:
                self.declare(match.group(1), line_no)
            return None
        if match := _DESCRIPTION.match(line):
            self.describe(match.group(1), match.group(2), line_no)
            return None
        if match := _BARE_ID.match(line):
            self.declare(match.group(1), line_no)
            return None
        raise self.fail(f"cannot read this Mermaid statement: {line[:60]!r}", line_no)


def read_mermaid(text: str, ctx: ReadContext) -> Model:
    return _MermaidReader(ctx).read(text)


# -- writer ---------------------------------------------------------------------------------
class _IdMaker:
    """Mermaid ids for state names: the name itself when it is a plain identifier."""

    def __init__(self) -> None:
        self.ids: dict[int, dict[str, str]] = {}
        self.used: set[str] = set()
        self.directives: list[str] = []

    def assign(self, machine: FSM) -> None:
        table = self.ids.setdefault(id(machine), {})
        for name in machine.states:
            candidate = name if _WRITABLE_ID.match(name) and name not in _KEYWORDS else None
            if candidate is None or candidate in self.used:
                base = re.sub(r"\W", "_", name) or "s"
                base = base if re.match(r"[A-Za-z_]", base) else f"s_{base}"
                candidate, counter = base, 1
                while candidate in self.used or candidate in _KEYWORDS:
                    counter += 1
                    candidate = f"{base}_{counter}"
                if candidate != name:
                    self.directives.append(f"%% fsmbt-name: {candidate} = {json.dumps(name)}")
            self.used.add(candidate)
            table[name] = candidate

    def of(self, machine: FSM, name: str) -> str:
        return self.ids[id(machine)][name]


def write_mermaid(model: Model) -> str:
    """``stateDiagram-v2`` text; composite states become nested blocks. O(states+transitions)."""
    if not isinstance(model, FSM):
        raise UnsupportedError("Mermaid state diagrams hold FSMs, not behavior trees")
    ids = _IdMaker()
    machines = [model]
    for _path, _owner, state in model.walk():
        if state.is_parallel:
            raise UnsupportedError(
                f"parallel state '{state.name}' (concurrent regions) cannot be written as Mermaid"
            )
        machines.extend(state.regions)
    for machine in machines:
        ids.assign(machine)
    body: list[str] = []
    # explicit stack: a level item expands into its own lines and its composite states' levels
    stack: list[tuple[str, object, int]] = [("level", model, 1)]
    while stack:
        item, payload, depth = stack.pop()
        pad = "    " * depth
        if item == "line":
            body.append(f"{pad}{payload}")
            continue
        assert isinstance(payload, FSM)
        machine = payload
        head: list[str] = []
        tail: list[str] = []
        for state in machine.states.values():
            sid = ids.of(machine, state.name)
            if state.regions:
                continue
            if state.action is None:
                head.append(f"%% fsmbt-no-action: {sid}")
                head.append(sid)
            elif state.action != state.name or sid != state.name:
                head.append(f"{sid} : {state.action}")
        if machine.initial is not None:
            if machine.initial_event is not None:
                if machine.start_name not in (None, "Start"):
                    tail.append(f"%% fsmbt-start: {json.dumps(machine.start_name)}")
                tail.append(f"[*] --> {ids.of(machine, machine.initial)} : {machine.initial_event}")
            else:
                tail.append(f"[*] --> {ids.of(machine, machine.initial)}")
        for t in machine.transitions:
            if t.source not in machine.states or t.target not in machine.states:
                raise InputError(f"transition {t.source} --> {t.target} names an unknown state")
            if t.exit is not None:  # completion by exit state: drawn with the exit's name
                tail.append(f"%% fsmbt-exit: {json.dumps(t.exit)}")
                label = f" : {t.exit}"
            else:
                label = f" : {t.event}" if t.event is not None else ""
            tail.append(f"{ids.of(machine, t.source)} --> {ids.of(machine, t.target)}{label}")
        for state in machine.states.values():
            if state.final:
                tail.append(f"{ids.of(machine, state.name)} --> [*]")
        mentioned = {machine.initial, *(s.name for s in machine.states.values() if s.final)}
        mentioned |= {t.source for t in machine.transitions} | {
            t.target for t in machine.transitions
        }
        for state in machine.states.values():
            sid = ids.of(machine, state.name)
            if state.name not in mentioned and not state.regions and sid not in head:
                head.append(sid)  # an isolated state still exists
        composites = [s for s in machine.states.values() if s.regions]
        # pushed in reverse: head lines, then each composite block, then the tail lines
        for line in reversed(tail):
            stack.append(("line", line, depth))
        for state in reversed(composites):
            sid = ids.of(machine, state.name)
            stack.append(("line", "}", depth))
            stack.append(("level", state.regions[0], depth + 1))
            description = state.attrs.get("description")
            opener = (
                f'state "{description}" as {sid} {{'
                if description and '"' not in description
                else f"state {sid} {{"
            )
            stack.append(("line", opener, depth))
        for line in reversed(head):
            stack.append(("line", line, depth))
    front = ["---", f"title: {json.dumps(model.name)}", "---"] if model.name else []
    directives = [f"    {d}" for d in ids.directives]
    return "\n".join(front + ["stateDiagram-v2"] + directives + body) + "\n"


def _sniff(text: str) -> bool:
    """The first statement (after front matter and ``%%`` lines) is ``stateDiagram``."""
    in_front = False
    for line in text[:4096].splitlines():
        stripped = line.strip()
        if not stripped or stripped.startswith("%%"):
            continue
        if stripped == "---":
            in_front = not in_front
            continue
        if in_front:
            continue
        return stripped.startswith("stateDiagram")
    return False


register(
    Format(
        "mermaid",
        (".mmd", ".mermaid"),
        frozenset({"fsm"}),
        "Mermaid stateDiagram-v2 (flat and composite states)",
        read_mermaid,
        write_mermaid,
        _sniff,
        priority=25,
        cannot_hold="parallel states",
    )
)
