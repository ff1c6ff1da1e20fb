"""Guarded YAML parsing, shared by every place fsmbt reads YAML (the YAML model format, the
pytransitions configuration, node-library files given with ``--nodes``).

Two hazards of YAML are closed here, because PyYAML's ``safe_load`` leaves both open:

- alias bombs ("billion laughs"): ``&a [*b, *b, ...]`` chains build a small graph of shared
  lists that explodes the moment anything walks it. fsmbt's inputs never need shared nodes, so
  an alias (``*name``) is refused at the first one, before anything is constructed.
- deep nesting: PyYAML's composer recurses once per nesting level (``RecursionError`` near
  depth 300) and libyaml's scanner is quadratic in flow depth (100 000 levels: minutes).
  ``_GuardedLoader`` composes with an explicit stack and stops at ``max_yaml_depth`` levels
  (``fsmbt.limits``; ``FSMBT_MAX_YAML_DEPTH``) while the parser is still reading lazily, so a
  100 000-deep document is refused in milliseconds. Cost: O(n) time in the number of nodes
  below the bound.

Lives in the model layer (it needs nothing but PyYAML and the limits) so that readers below
``fsmbt.formats`` - the node libraries of ``fsmbt.model.nodes`` - get the same guards.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import yaml
from yaml.events import (
    AliasEvent,
    MappingEndEvent,
    MappingStartEvent,
    ScalarEvent,
    SequenceEndEvent,
    SequenceStartEvent,
)
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from fsmbt import limits
from fsmbt.model.errors import InputError, SourceLocation

#: ``(line, column) -> location`` of the text being read (both 1-based, ``None`` when unknown).
Locate = Callable[[int | None, int | None], SourceLocation]


class _Refused(Exception):
    """Raised inside the composer; turned into an ``InputError`` with the location."""

    def __init__(self, message: str, line: int, column: int) -> None:
        super().__init__(message)
        self.message, self.line, self.column = message, line, column


try:  # libyaml's parser when PyYAML was built with it (the pinned wheels are)
    from yaml.cyaml import CParser as _Parser  # type: ignore[attr-defined]  # public, unstubbed

    _PURE_PYTHON = False
except ImportError:  # pragma: no cover - pure-Python fallback
    _Parser = yaml.parser.Parser  # type: ignore[assignment,misc]
    _PURE_PYTHON = True


class _GuardedLoader(_Parser, yaml.constructor.SafeConstructor, yaml.resolver.Resolver):
    """A safe loader (libyaml parser when available) whose composer uses an explicit stack,
    bounds the depth and refuses aliases. Only the composer is replaced; construction is
    PyYAML's ``SafeConstructor`` (generator based, so not recursive in depth)."""

    def __init__(self, stream: str) -> None:
        if _PURE_PYTHON:  # pragma: no cover - needs its reader and scanner
            # the stubs type these mixin initialisers' self as their own class
            yaml.reader.Reader.__init__(self, stream)  # type: ignore[arg-type]
            yaml.scanner.Scanner.__init__(self)  # type: ignore[arg-type]
            yaml.parser.Parser.__init__(self)  # type: ignore[arg-type]
        else:
            _Parser.__init__(self, stream)
        yaml.constructor.SafeConstructor.__init__(self)
        yaml.resolver.Resolver.__init__(self)

    def get_single_node(self) -> Node | None:
        self.get_event()  # stream start
        document = None
        if not self.check_event(yaml.events.StreamEndEvent):
            self.get_event()  # document start
            document = self._compose_tree()
            self.get_event()  # document end
        if not self.check_event(yaml.events.StreamEndEvent):
            following = self.peek_event()
            assert following is not None  # check_event saw an event
            mark = following.start_mark
            raise _Refused(
                "expected one YAML document, found several", mark.line + 1, mark.column + 1
            )
        self.get_event()
        return document

    def _compose_tree(self) -> Node:
        stack: list[list[Any]] = []  # [collection node, pending mapping key or None]
        max_depth = limits.current().max_yaml_depth
        while True:
            event = self.get_event()
            if event is None:
                raise _Refused("unexpected end of the YAML stream", 1, 1)
            mark = event.start_mark
            if isinstance(event, AliasEvent):
                raise _Refused(
                    "YAML aliases (*name) are not allowed in fsmbt models (they can "
                    "expand exponentially); write the value out",
                    mark.line + 1,
                    mark.column + 1,
                )
            node: Node
            if isinstance(event, ScalarEvent):
                tag = event.tag
                if tag is None or tag == "!":
                    tag = self.resolve(ScalarNode, event.value, event.implicit)  # type: ignore[no-untyped-call]
                node = ScalarNode(tag, event.value, mark, event.end_mark, style=event.style)
            elif isinstance(event, (SequenceStartEvent, MappingStartEvent)):
                if len(stack) >= max_depth:
                    raise _Refused(
                        limits.exceeded(
                            f"YAML nested deeper than {max_depth} levels",
                            "max_yaml_depth",
                            max_depth,
                        ),
                        mark.line + 1,
                        mark.column + 1,
                    )
                kind = SequenceNode if isinstance(event, SequenceStartEvent) else MappingNode
                tag = event.tag
                if tag is None or tag == "!":
                    tag = self.resolve(kind, None, event.implicit)  # type: ignore[no-untyped-call]
                stack.append([kind(tag, [], mark, None, flow_style=event.flow_style), None])
                continue
            elif isinstance(event, (SequenceEndEvent, MappingEndEvent)):
                node = stack.pop()[0]
                node.end_mark = event.end_mark
            else:  # pragma: no cover - the parser yields nothing else inside a document
                raise _Refused(
                    f"unexpected YAML event {type(event).__name__}", mark.line + 1, mark.column + 1
                )
            if not stack:
                return node
            top = stack[-1]
            if isinstance(top[0], SequenceNode):
                top[0].value.append(node)
            elif top[1] is None:
                top[1] = node
            else:
                top[0].value.append((top[1], node))
                top[1] = None


def load_guarded_yaml(text: str, locate: Locate) -> Any:
    """Plain data from YAML text (one document), with the guards above; every error is an
    ``InputError`` located by ``locate``."""
    try:
        # safe constructor only; the stubs list PyYAML's own loader classes
        return yaml.load(text, Loader=_GuardedLoader)  # type: ignore[arg-type]  # noqa: S506
    except _Refused as exc:
        raise InputError(exc.message, location=locate(exc.line, exc.column)) from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        location = locate(mark.line + 1, mark.column + 1) if mark else locate(None, None)
        raise InputError(f"invalid YAML: {exc.problem or exc.context}", location=location) from None
    except yaml.YAMLError as exc:
        raise InputError(f"invalid YAML: {exc}", location=locate(None, None)) from None
    except RecursionError:
        raise InputError("YAML nested too deeply", location=locate(None, None)) from None


__all__ = ["Locate", "load_guarded_yaml"]
