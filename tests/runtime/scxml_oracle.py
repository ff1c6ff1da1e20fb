"""python-statemachine (a W3C SCXML engine written by others) as the oracle for fsmbt's SCXML.

Two sides, fed the same events one at a time:

- the engine: ``statemachine.io.loader.load(text, format="scxml")`` (its safe evaluator, so a
  guard is evaluated, never executed as Python); its configuration is a set of state ids;
- fsmbt: ``FSMMachine`` over ``fsmbt.model.flatten`` of a model (the HFSM a conversion proved, or
  what fsmbt's reader made of the file); its state is a flat configuration name
  (``a/a1``, ``p/[x|y]``, docs/formats/scxml.md).

The engine's configuration is turned into fsmbt's flat name with the document's own tree
(lxml, not fsmbt's reader): an active compound state is ``name/<its active child>``, a parallel
one ``name/[<child 1>|...]`` (one child: ``name/<child>``); ``name`` is ``fsmbt:name`` when the
writer had to give a state another id, else the id. Two names equal means the same active states
at every level, so the same active leaf. Costs: one engine class per document (python-statemachine
builds it in O(states + transitions)), O(depth) per configuration name.
"""

from __future__ import annotations

import contextlib
import functools
import io
import random
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

from lxml import etree
from statemachine import StateChart
from statemachine.io.loader import load

from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import FINAL, FSMMachine

FSMBT_NAME = "{https://fsmbt.dev/ns/scxml}name"
FSMBT_REGION = "{https://fsmbt.dev/ns/scxml}region"
STATE_TAGS = ("state", "parallel", "final")


def _local(element: etree._Element) -> str:
    return etree.QName(element).localname


@dataclass
class Document:
    """The state tree of an SCXML document: ids, children, display names."""

    children: dict[str | None, list[str]] = field(default_factory=dict)  # None = <scxml>
    kind: dict[str, str] = field(default_factory=dict)  # id -> state | parallel | final
    name: dict[str, str] = field(default_factory=dict)
    wrappers: set[str] = field(default_factory=set)  # fsmbt's region wrappers: not in names

    @classmethod
    def parse(cls, text: str) -> Document:
        parser = etree.XMLParser(resolve_entities=False, no_network=True)
        root = etree.fromstring(text.encode(), parser)
        doc = cls()
        stack: list[tuple[etree._Element, str | None]] = [(root, None)]
        while stack:
            element, owner = stack.pop()
            kids = []
            for child in element:
                if not isinstance(child.tag, str) or _local(child) not in STATE_TAGS:
                    continue
                state_id = child.get("id")
                if state_id is None:
                    raise ValueError("a state without id (the engine names it its own way)")
                kids.append(state_id)
                doc.kind[state_id] = _local(child)
                doc.name[state_id] = child.get(FSMBT_NAME, state_id)
                if child.get(FSMBT_REGION) == "true":
                    doc.wrappers.add(state_id)
                stack.append((child, state_id))
            doc.children[owner] = kids
        return doc

    def flat_name(self, active: set[str]) -> str:
        """fsmbt's flat configuration name for the engine's set of active ids."""
        top = [s for s in self.children[None] if s in active]
        if len(top) != 1:
            raise AssertionError(
                f"engine configuration {sorted(active)} has {len(top)} top-level states"
            )
        # explicit stack: (state id, parts list to fill, is-done marker)
        out: list[str] = []
        stack: list[str | tuple[str]] = [top[0]]
        while stack:
            item = stack.pop()
            if isinstance(item, tuple):  # a literal piece of text
                out.append(item[0])
                continue
            kids = self.children.get(item, [])
            if item in self.wrappers:  # the region itself: its active state stands for it
                stack.extend(k for k in kids if k in active)
                continue
            out.append(self.name[item])
            if not kids:
                continue
            if self.kind[item] == "parallel":
                if len(kids) == 1:
                    stack.extend([kids[0], ("/",)])
                    continue
                pieces: list[str | tuple[str]] = [("/[",)]
                for index, kid in enumerate(kids):
                    if index:
                        pieces.append(("|",))
                    pieces.append(kid)
                pieces.append(("]",))
                stack.extend(reversed(pieces))
            else:
                chosen = [k for k in kids if k in active]
                if len(chosen) != 1:
                    raise AssertionError(f"compound '{item}' has {len(chosen)} active children")
                stack.extend([chosen[0], ("/",)])
        return "".join(out)


#: python-statemachine 3.2.2 splits an ``event`` list on single spaces: an attribute with two
#: blanks in a row (a list written across lines: XML turns each line break into a blank) gets
#: an empty descriptor that matches every event. W3C splits on any whitespace, so the engine
#: gets the document with each event list's blanks collapsed (the same document to W3C).
EVENT_LIST_BLANKS = "engine reads an event list with two blanks in a row as matching every event"
_EVENT_ATTRIBUTE = re.compile(r"""(\sevent\s*=\s*)(["'])(.*?)\2""", re.S)


def engine_text(text: str) -> str:
    """``text`` with every ``event`` list's whitespace collapsed (``EVENT_LIST_BLANKS``)."""
    return _EVENT_ATTRIBUTE.sub(
        lambda m: m.group(1) + m.group(2) + " ".join(m.group(3).split()) + m.group(2), text
    )


_ECMASCRIPT_WORDS = {
    "true": "True",
    "false": "False",
    "===": "==",
    "!==": "!=",
    "&amp;&amp;": " and ",
    "||": " or ",
}
_EXPRESSION_ATTRIBUTE = re.compile(r"""(\s(?:cond|expr)\s*=\s*)(["'])(.*?)\2""", re.S)
_ECMASCRIPT_TOKEN = re.compile(r"===|!==|&amp;&amp;|\|\||\btrue\b|\bfalse\b")


def python_spelled(text: str) -> str | None:
    """An ``ecmascript`` document with its expressions spelled for the engine's Python data
    model (``true`` -> ``True``, ``===`` -> ``==``, ``&&`` -> ``and``), else ``None``. The
    engine evaluates expressions in Python; on the subset fsmbt computes (numbers, booleans,
    strings compared with their own kind) the two spellings have the same values, and fsmbt
    reads the copy with its Python dialect."""
    if not re.search(r"""datamodel\s*=\s*["']ecmascript["']""", text):
        return None
    body = _EXPRESSION_ATTRIBUTE.sub(
        lambda m: (
            m.group(1)
            + m.group(2)
            + _ECMASCRIPT_TOKEN.sub(lambda t: _ECMASCRIPT_WORDS[t.group(0)], m.group(3))
            + m.group(2)
        ),
        text,
    )
    return re.sub(r"""datamodel\s*=\s*["']ecmascript["']""", 'datamodel="python"', body)


@functools.lru_cache(maxsize=8)
def _compiled(text: str) -> tuple[Document, type[StateChart]]:
    """The document's tree and the engine's class (built once per text: the sequences of one
    model share it, each gets a fresh instance)."""
    with contextlib.redirect_stdout(io.StringIO()):
        return Document.parse(text), load(engine_text(text), format="scxml")


class Engine:
    """One python-statemachine instance of an SCXML document."""

    def __init__(self, text: str) -> None:
        self.doc, chart = _compiled(text)
        if any(word in text for word in ("<assign", "<data", "_event")):  # ASSIGN_SHARED_CLASS
            with contextlib.redirect_stdout(io.StringIO()):
                chart = load(engine_text(text), format="scxml")
        with contextlib.redirect_stdout(io.StringIO()):  # the engine prints <log> content
            self.machine = chart()

    def send(self, event: str) -> None:
        with contextlib.redirect_stdout(io.StringIO()):
            self.machine.send(event)

    @property
    def terminated(self) -> bool:
        return bool(self.machine.is_terminated)

    def top_parallel_completed(self) -> bool:
        """Is the active top-level state a <parallel> whose every region rests in a final
        state (the case where the engine stops and W3C does not)?"""
        active = {s.id for s in self.machine.configuration}
        top = [s for s in self.doc.children[None] if s in active]
        if len(top) != 1 or self.doc.kind[top[0]] != "parallel":
            return False
        stack = [top[0]]
        while stack:
            item = stack.pop()
            kids = self.doc.children.get(item, [])
            if self.doc.kind[item] == "parallel":
                stack.extend(kids)
            elif kids:
                chosen = [k for k in kids if k in active]
                if len(chosen) != 1 or self.doc.kind[chosen[0]] != "final":
                    return False
            elif self.doc.kind[item] != "final":
                return False
        return True

    def configuration(self) -> str:
        return self.doc.flat_name({s.id for s in self.machine.configuration})


@dataclass
class Mismatch:
    events: list[str]
    engine: str
    fsmbt: str

    def __str__(self) -> str:
        return f"after {self.events}: engine {self.engine}, fsmbt {self.fsmbt}"


def random_events(
    machine: FSMMachine, state: str, rng: random.Random, alphabet: Sequence[str], noise: float
) -> str:
    """An event that does something in ``state`` (most of the time) or any event of the
    alphabet (``noise``: ignored events must be ignored by both)."""
    active = list(machine.active_inputs(state))
    if active and rng.random() >= noise:
        return rng.choice(active)
    return rng.choice(list(alphabet))


#: python-statemachine 3.2.2: in the second and later instances of one class loaded from a
#: document, reading a ``<data>`` variable fails: an ``<assign>`` reading one fails and the
#: rest of its block (a ``<raise>`` after it) is skipped, a ``cond`` reading one is false; the
#: first instance runs both as W3C says; likewise ``_event`` stays bound from one instance to
#: the next. ``Engine`` therefore loads a fresh class per instance for documents with
#: ``<assign>``, ``<data>`` or ``_event``.
ASSIGN_SHARED_CLASS = "engine skips a block after <assign> in a reused class"

#: The engine's known departure from the W3C algorithm that a replay meets (see
#: docs/formats/scxml.md): it stops when a top-level <parallel> completes; W3C stops only on
#: entering a top-level <final> (the parallel's done.state event is raised and the machine runs
#: on, so the parallel's own transitions still fire).
PARALLEL_STOPS = "engine stops when a top-level <parallel> completes"


@dataclass
class Replay:
    sent: int
    mismatch: Mismatch | None = None
    departure: str | None = None  # a documented engine departure ended the comparison


def replay(
    text: str,
    model: FSM,
    rng: random.Random,
    *,
    length: int,
    alphabet: Sequence[str] | None = None,
    noise: float = 0.2,
    machine: FSMMachine | None = None,
) -> Replay:
    """Drive the engine on ``text`` and fsmbt's machine of ``model`` with one random sequence
    (stops at termination, at the first mismatch, or at a documented engine departure)."""
    fsmbt = machine if machine is not None else FSMMachine(model)
    events_alphabet = alphabet if alphabet is not None else fsmbt.alphabet or ("none",)
    engine = Engine(text)
    state, _ = fsmbt.start()
    sent: list[str] = []
    for _ in range(length + 1):
        seen = engine.configuration()
        done = engine.terminated
        fsmbt_done = fsmbt.status(state) == FINAL
        shown = state if seen == state else configuration_of(state)  # ids may hold '#' too
        if seen == shown and done and not fsmbt_done and engine.top_parallel_completed():
            return Replay(len(sent), departure=PARALLEL_STOPS)
        if seen != shown or done != fsmbt_done:
            return Replay(
                len(sent),
                Mismatch(
                    list(sent), f"{seen} (terminated={done})", f"{state} ({fsmbt.status(state)})"
                ),
            )
        if done or len(sent) == length:
            break
        event = random_events(fsmbt, state, rng, events_alphabet, noise)
        base = event_of(event)
        sent.append(base)
        engine.send(base)
        state = follow(fsmbt, state, base, engine.configuration(), events_alphabet, event)
    return Replay(len(sent))


def configuration_of(state: str) -> str:
    """fsmbt's flat name without the history and data values (``a/a1#h=x`` -> ``a/a1``,
    ``a/x#2#n=1`` -> ``a/x#2``) and the configurations of invoked sessions (``s{s.1=here}`` -> ``s``; the engine's configuration
    is the parent's only)."""
    name = state.split("{", 1)[0]
    while "#" in name and "=" in name.rsplit("#", 1)[1]:  # values, not a '#' of a state name
        name = name.rsplit("#", 1)[0]
    return name


def event_of(symbol: str) -> str:
    """The event of an input symbol (``e[g1,!g2]`` -> ``e``; docs/formats/scxml.md)."""
    return symbol.split("[", 1)[0]


def follow(
    fsmbt: FSMMachine, state: str, event: str, seen: str, alphabet: Sequence[str], chosen: str
) -> str:
    """fsmbt's step on ``event``: the guard valuation is the environment's choice, so among the
    symbols of ``event`` the one that reaches the engine's configuration is taken (the engine's
    behaviour must be one of fsmbt's); without one, the randomly chosen symbol's successor."""
    symbols = [s for s in alphabet if event_of(s) == event] or [chosen]
    for symbol in [chosen, *symbols]:
        successor, _ = fsmbt.step(state, symbol)
        if seen in (successor, configuration_of(successor)):
            return successor
    return fsmbt.step(state, chosen)[0]
