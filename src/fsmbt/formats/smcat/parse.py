"""The state-machine-cat (``.smcat``) notation -> a syntax tree (docs/formats/smcat.md).

A hand-written scanner for the grammar of state-machine-cat 15 (``smcat-parser.peggy``):

    program      = _ machine _
    machine      = [state ("," state)* ";"] transition*
    state        = note* identifier ["[" state-attr* "]"] [":" string] ["{" machine "}"]
    transition   = note* identifier arrow identifier ["[" trans-attr* "]"] [":" label] ";"
    arrow        = "->" "=>>" "=>" ">>" ":>" "--" "=="  (or backwards "<-" "<<=" "<=" "<<" "<:")
    identifier   = [^;, "\\t\\n\\r=\\-><:{\\[]+  |  "quoted"
    note         = "#" to the end of the line;  comments: // and /* */

State types come from the name as state-machine-cat infers them (``initial``, ``final``,
``parallel``, ``history``, ``deep...history``, ``^choice``, ``]forkjoin``) unless
``[type=...]`` says otherwise; a transition's label is ``event [condition] / action``.
Nesting (``{ ... }``) is read with an explicit stack of open machines, never by recursion.
Every error is an ``InputError`` at its line and column. Costs: O(n) characters.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from fsmbt.model.errors import InputError, SourceLocation

FORWARD = ("=>>", "->", "=>", ">>", ":>", "--", "==")
BACKWARD = ("<<=", "<-", "<=", "<<", "<:")
STATE_TYPES = frozenset(
    {
        "regular",
        "initial",
        "terminate",
        "final",
        "parallel",
        "history",
        "deephistory",
        "choice",
        "forkjoin",
        "fork",
        "join",
        "junction",
    }
)
_IDENTIFIER = re.compile(r"[^;, \"\t\n\r=\-><:{\[]+")
_TYPE_BY_NAME = (
    (re.compile(r"initial"), "initial"),
    (re.compile(r"final"), "final"),
    (re.compile(r"parallel"), "parallel"),
    (re.compile(r"(deep.*history)|(history.*deep)"), "deephistory"),
    (re.compile(r"history"), "history"),
    (re.compile(r"^\^"), "choice"),
    (re.compile(r"^\]"), "forkjoin"),
)
_LABEL = re.compile(
    r"(?P<event>[^\[/]{1,256})?(?P<cond>\[[^\]]{1,256}\])?[^/]{0,100}(?P<action>/.{1,2048})?", re.S
)


def type_from_name(name: str) -> str:
    """The state type state-machine-cat infers from a name (``getStateType``)."""
    for pattern, kind in _TYPE_BY_NAME:
        if pattern.search(name):
            return kind
    return "regular"


@dataclass
class SState:
    name: str
    line: int
    kind: str
    explicit_type: bool = False
    attrs: dict[str, str] = field(default_factory=dict)
    actions: str | None = None
    machine: SMachine | None = None
    notes: list[str] = field(default_factory=list)


@dataclass
class STransition:
    source: str
    target: str
    line: int
    label: str | None = None
    event: str | None = None
    cond: str | None = None
    action: str | None = None
    attrs: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


@dataclass
class SMachine:
    states: list[SState] = field(default_factory=list)
    transitions: list[STransition] = field(default_factory=list)


def split_label(label: str) -> tuple[str | None, str | None, str | None]:
    """``event [cond] / action`` as state-machine-cat splits it (``parseTransitionExpression``)."""
    match = _LABEL.match(label)
    if match is None:
        return None, None, None
    event = match.group("event")
    cond = match.group("cond")
    action = match.group("action")
    return (
        event.strip() or None if event else None,
        cond[1:-1].strip() if cond else None,
        action[1:].strip() if action else None,
    )


class _Scanner:
    def __init__(self, text: str, name: str) -> None:
        self.text = text
        self.name = name
        self.pos = 0

    def location(self, pos: int | None = None) -> SourceLocation:
        at = self.pos if pos is None else pos
        line = self.text.count("\n", 0, at) + 1
        column = at - (self.text.rfind("\n", 0, at) + 1) + 1
        return SourceLocation(self.name, line, column)

    def line(self, pos: int | None = None) -> int:
        return self.text.count("\n", 0, self.pos if pos is None else pos) + 1

    def error(self, message: str, pos: int | None = None) -> InputError:
        return InputError(message, location=self.location(pos))

    def skip(self) -> None:
        """Whitespace and comments (``_`` of the grammar)."""
        text = self.text
        while self.pos < len(text):
            char = text[self.pos]
            if char in " \t\r\n":
                self.pos += 1
            elif text.startswith("//", self.pos):
                end = text.find("\n", self.pos)
                self.pos = len(text) if end < 0 else end
            elif text.startswith("/*", self.pos):
                end = text.find("*/", self.pos + 2)
                if end < 0:
                    raise self.error("comment /* is never closed")
                self.pos = end + 2
            else:
                break

    def notes(self) -> list[str]:
        notes: list[str] = []
        while True:
            self.skip()
            if self.peek() != "#":
                return notes
            end = self.text.find("\n", self.pos)
            end = len(self.text) if end < 0 else end
            notes.append(self.text[self.pos + 1 : end].strip())
            self.pos = end

    def peek(self, count: int = 1) -> str:
        return self.text[self.pos : self.pos + count]

    def at_end(self) -> bool:
        return self.pos >= len(self.text)

    def expect(self, token: str, what: str) -> None:
        self.skip()
        if not self.text.startswith(token, self.pos):
            found = self.peek(12).split("\n")[0] or "the end of the text"
            raise self.error(f"expected {what} ('{token}'), found '{found}'")
        self.pos += len(token)

    def quoted(self) -> str:
        start = self.pos
        self.pos += 1
        out: list[str] = []
        while self.pos < len(self.text):
            if self.text.startswith('\\"', self.pos):
                out.append('"')
                self.pos += 2
            elif self.text[self.pos] == '"':
                self.pos += 1
                return "".join(out)
            else:
                out.append(self.text[self.pos])
                self.pos += 1
        raise self.error("a quoted string is never closed", start)

    def identifier(self) -> str:
        self.skip()
        if self.peek() == '"':
            return self.quoted()
        match = _IDENTIFIER.match(self.text, self.pos)
        if match is None:
            found = self.peek(12).split("\n")[0] or "the end of the text"
            raise self.error(f"expected a state name, found '{found}'")
        self.pos = match.end()
        return match.group(0)

    def arrow(self) -> str | None:
        self.skip()
        for token in (*FORWARD, *BACKWARD):
            if self.text.startswith(token, self.pos):
                self.pos += len(token)
                return "back" if token in BACKWARD else "forward"
        return None

    def until(self, stops: str) -> str:
        """An unquoted string up to one of ``stops`` (not included), stripped."""
        start = self.pos
        while self.pos < len(self.text) and self.text[self.pos] not in stops:
            self.pos += 1
        return self.text[start : self.pos].strip()

    def attributes(self, transition: bool) -> tuple[dict[str, str], bool]:
        """``[name=value ...]`` after its ``[``; returns the attributes and whether a type was set."""
        attrs: dict[str, str] = {}
        typed = False
        while True:
            self.skip()
            if self.peek() == "]":
                self.pos += 1
                return attrs, typed
            start = self.pos
            match = re.compile(r"[A-Za-z]+").match(self.text, self.pos)
            if match is None:
                raise self.error("expected an attribute name or ']'")
            name = match.group(0).lower()
            self.pos = match.end()
            allowed = (
                {"color", "class", "type", "width"}
                if transition
                else {"label", "color", "class", "active", "type"}
            )
            if name not in allowed:
                raise self.error(
                    f"unknown {'transition' if transition else 'state'} attribute '{name}' "
                    f"(state-machine-cat knows {', '.join(sorted(allowed))})",
                    start,
                )
            if name == "active":
                attrs[name] = "true"
                continue
            self.expect("=", f"'=' after {name}")
            self.skip()
            if name == "width":
                number = re.compile(r"[0-9]+(\.[0-9]+)?").match(self.text, self.pos)
                if number is None:
                    raise self.error("width is a positive number")
                self.pos = number.end()
                attrs[name] = number.group(0)
                continue
            if name == "type":
                word = re.compile(r"[a-z]+").match(self.text, self.pos)
                value = word.group(0) if word else ""
                kinds = {"external", "internal"} if transition else STATE_TYPES
                if value not in kinds:
                    raise self.error(
                        f"type '{value}' is not one of {', '.join(sorted(kinds))}", start
                    )
                self.pos = word.end() if word else self.pos
                attrs[name] = value
                typed = not transition
                continue
            if self.peek() != '"':
                raise self.error(f"the value of {name} is a double-quoted string")
            attrs[name] = self.quoted()


def parse_smcat(text: str, name: str) -> SMachine:
    """The syntax tree of a ``.smcat`` text (see the module docstring).

    Raises:
        InputError: a syntax error, at its line and column.
    """
    scanner = _Scanner(text, name)
    top = SMachine()
    # open machines: (machine, the state that owns it or None, phase: 0 states, 1 transitions)
    stack: list[tuple[SMachine, SState | None]] = [(top, None)]
    phase: list[int] = [0]
    while True:
        machine, owner = stack[-1]
        notes = scanner.notes()
        scanner.skip()
        if scanner.at_end():
            if owner is not None:
                raise scanner.error(f"state '{owner.name}' opens '{{' that is never closed")
            return top
        if scanner.peek() == "}":
            if owner is None:
                raise scanner.error("'}' closes no state")
            scanner.pos += 1
            stack.pop()
            phase.pop()
            # the owning state's declaration goes on: "," or ";"
            _after_state(scanner, phase)
            continue
        start = scanner.pos
        ident = scanner.identifier()
        line = scanner.line(start)
        save = scanner.pos
        direction = scanner.arrow()
        if direction is not None:
            if phase[-1] == 2:
                raise scanner.error("a state list ended with ',' needs another state", start)
            phase[-1] = 1
            other = scanner.identifier()
            source, target = (ident, other) if direction == "forward" else (other, ident)
            transition = STransition(source, target, line, notes=notes)
            scanner.skip()
            if scanner.peek() == "[":
                scanner.pos += 1
                transition.attrs, _ = scanner.attributes(transition=True)
                scanner.skip()
            if scanner.peek() == ":":
                scanner.pos += 1
                scanner.skip()
                label = scanner.quoted() if scanner.peek() == '"' else scanner.until(";{")
                transition.label = label
                transition.event, transition.cond, transition.action = split_label(label)
            scanner.expect(";", "';' at the end of a transition")
            machine.transitions.append(transition)
            continue
        scanner.pos = save
        if phase[-1] == 1:
            raise scanner.error(
                f"state '{ident}' is declared after a transition; state-machine-cat wants "
                "every state of a machine declared before its transitions",
                start,
            )
        state = SState(ident, line, type_from_name(ident), notes=notes)
        scanner.skip()
        if scanner.peek() == "[":
            scanner.pos += 1
            attrs, typed = scanner.attributes(transition=False)
            if "type" in attrs:
                state.kind = attrs.pop("type")
            state.explicit_type = typed
            state.attrs = attrs
            scanner.skip()
        if scanner.peek() == ":":
            scanner.pos += 1
            scanner.skip()
            state.actions = scanner.quoted() if scanner.peek() == '"' else scanner.until(",;{")
            scanner.skip()
        existing = [i for i, s in enumerate(machine.states) if s.name == state.name]
        if existing:  # state-machine-cat keeps the last declaration, in the first place
            machine.states[existing[0]] = state
        else:
            machine.states.append(state)
        if scanner.peek() == "{":
            scanner.pos += 1
            state.machine = SMachine()
            stack.append((state.machine, state))
            phase.append(0)
            continue
        _after_state(scanner, phase)


def _after_state(scanner: _Scanner, phase: list[int]) -> None:
    scanner.skip()
    char = scanner.peek()
    if char == ",":
        scanner.pos += 1
        phase[-1] = 2
    elif char == ";":
        scanner.pos += 1
        phase[-1] = 1
    else:
        found = scanner.peek(12).split("\n")[0] or "the end of the text"
        raise scanner.error(f"expected ',' or ';' after a state, found '{found}'")
