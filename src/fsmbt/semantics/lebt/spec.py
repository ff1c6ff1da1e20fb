"""How the two LEBT leaf types are written in a behavior tree (docs/semantics.md, "The LEBT
runtime protocol"), shared by the converter that writes them, the checkers that read them and
the runtimes (interpreter, fast path, BehaviorTree.CPP, py_trees) that run them.

- ``LebtGuard`` (a Condition): port ``target`` (the state it guards) and ``pairs``, the
  (source, event) pairs that enter the target, as ``source/event`` items separated by ``;``.
  An empty event (``Start/``) is the initialisation pair: it matches when no event is pending.
  Returns FAILURE when (``state``, ``event``) on the blackboard is one of its pairs.
- ``LebtState`` (a stateful Action): ports ``state``, ``action`` (empty = none), ``final``
  (``true``/``false``) and ``exits``, the events that have a transition out of the state,
  separated by ``;``.
  An optional ``params`` port holds the state's parameters for the runtimes' callbacks
  (``name=value`` items separated by ``;``; ``encode_params``): what the state was configured
  with (FlexBE's ``TimedCmdVelState(velocity=...)``), never read by the checkers.
Names with ``;``, ``/`` or ``\\`` are escaped with a backslash.
Blackboard keys: ``state`` (starts at the start pseudo-state) and ``event`` (empty = none).

Costs: ``encode_pairs``/``decode_pairs``/``split_escaped`` are O(length of the text), one pass
each, no recursion.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

GUARD_TYPE = "LebtGuard"
STATE_TYPE = "LebtState"
BB_STATE = "state"
BB_EVENT = "event"
NO_EVENT = ""
DEFAULT_START = "__start__"
#: The optional port of ``LebtState`` holding the state's parameters (runtimes only).
PARAMS_PORT = "params"


def escape(text: str) -> str:
    """Backslash-escape ``\\``, ``;`` and ``/`` so a name survives ``encode_pairs``."""
    return text.replace("\\", "\\\\").replace(";", "\\;").replace("/", "\\/")


def split_escaped(text: str, separator: str) -> list[str]:
    """Split on unescaped ``separator`` and unescape the parts."""
    return [unescape(part) for part in _split_keeping_escapes(text, separator)]


def unescape(text: str) -> str:
    """Drop the backslash escapes of ``escape``."""
    out: list[str] = []
    chars = iter(text)
    for ch in chars:
        out.append(next(chars, "") if ch == "\\" else ch)
    return "".join(out)


def encode_pairs(pairs: Sequence[tuple[str, str]]) -> str:
    """``a/b`` items joined by ``;``, names escaped: the port form of guard pairs and of the
    baselines' transition tables."""
    return ";".join(f"{escape(a)}/{escape(b)}" for a, b in pairs)


def decode_pairs(text: str) -> list[tuple[str, str]]:
    """The inverse of ``encode_pairs``; raises ``ValueError`` on a malformed item."""
    if not text:
        return []
    pairs = []
    for item in _split_keeping_escapes(text, ";"):
        pieces = _split_keeping_escapes(item, "/")
        if len(pieces) != 2:
            raise ValueError(f"malformed pair {item!r}: expected 'a/b'")
        pairs.append((unescape(pieces[0]), unescape(pieces[1])))
    return pairs


def encode_params(params: dict[str, str]) -> str:
    """``name=value`` items joined by ``;`` (``;``, ``/`` and ``\\`` escaped; a name has no
    ``=``): the ``params`` port of a state leaf."""
    return ";".join(f"{escape(name)}={escape(value)}" for name, value in params.items())


def decode_params(text: str) -> dict[str, str]:
    """The inverse of ``encode_params``; raises ``ValueError`` on an item without ``=``."""
    params: dict[str, str] = {}
    if not text:
        return params
    for item in _split_keeping_escapes(text, ";"):
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise ValueError(f"malformed parameter {item!r}: expected 'name=value'")
        params[unescape(name)] = unescape(value)
    return params


def _split_keeping_escapes(text: str, separator: str) -> list[str]:
    """Split on unescaped ``separator``; the parts keep their escapes."""
    parts: list[str] = []
    current: list[str] = []
    escaped = False
    for ch in text:
        if escaped:
            current.append("\\" + ch)
            escaped = False
        elif ch == "\\":
            escaped = True
        elif ch == separator:
            parts.append("".join(current))
            current = []
        else:
            current.append(ch)
    parts.append("".join(current))
    return parts


@dataclass(frozen=True)
class GuardSpec:
    target: str
    pairs: tuple[tuple[str, str], ...]  # (source state, event); event "" = initialisation

    def to_attrs(self) -> dict[str, str]:
        return {"target": self.target, "pairs": encode_pairs(self.pairs)}

    @classmethod
    def from_attrs(cls, attrs: dict[str, str]) -> GuardSpec:
        return cls(attrs.get("target", ""), tuple(decode_pairs(attrs.get("pairs", ""))))

    def matches(self, state: str, event: str) -> bool:
        return (state, event) in self.pairs


@dataclass(frozen=True)
class StateSpec:
    state: str
    action: str | None
    final: bool
    exits: tuple[str, ...]

    def to_attrs(self) -> dict[str, str]:
        return {
            "state": self.state,
            "action": self.action or "",
            "final": "true" if self.final else "false",
            "exits": ";".join(escape(e) for e in self.exits),
        }

    @classmethod
    def from_attrs(cls, attrs: dict[str, str]) -> StateSpec:
        raw = attrs.get("exits", "")
        exits = tuple(split_escaped(raw, ";")) if raw else ()
        return cls(
            attrs.get("state", ""),
            attrs.get("action") or None,
            attrs.get("final", "false").lower() == "true",
            exits,
        )
