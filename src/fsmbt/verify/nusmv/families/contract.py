"""What a family's NuSMV rule writes into and how it is called (docs/semantics.md, "Node
families"; docs/nusmv.md).

A rule is ``rule(core, x, here, called, resets)``: it adds node ``x``'s tick rules to ``core`` (the
BT encoder, ``encode_bt.BTCore``) in the encoder's micro-step style: ``called`` is the condition
"``x`` is ticked with no result yet", ``here`` "the current node is ``x``" (a child's return is
``here & res != NONE``, ``res`` its status, ``lidx`` which child), and ``resets[c]`` collects the
conditions under which child ``c`` is reset (halted when RUNNING). The rule mirrors the
interpreter's tick rule of the same name (``fsmbt.semantics.families``, the module of the same
name as the rule's).

A rule that serves several rule names and reads which one it encodes is a ``NamedNusmvRule``,
``rule(core, x, name, here, called, resets)``; ``named(rule, name)`` makes it a ``NusmvRule`` for
one name.

The order of a rule's calls is part of the encoding: the rows of each variable's ``case`` are
emitted in the order they were added (the first that holds wins).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from fsmbt.semantics.compiled import CompiledNode

Resets = dict[int, list[str]]


class BTCore(Protocol):
    """What the rules write into: the BT encoder (``encode_bt.BTCore``), which imports the
    rules (so they name the encoder's members they use, not the encoder)."""

    #: ``(name, expression)`` DEFINEs of the module (a parallel's counts).
    defines: list[tuple[str, str]]
    #: Per node id: whether the node can return SKIPPED (``encode_bt.BTCore._may_skip``).
    may_skip: list[bool]
    #: Variable -> SMV type, in declaration order (a rule declares a frame variable here).
    var_types: dict[str, str]
    #: Variable -> initial value.
    init: dict[str, str]

    def st(self, nid: int) -> str:
        """The status variable of node ``nid``."""
        ...

    def rule(self, var: str, cond: str, value: str) -> None:
        """Add ``cond -> var := value``."""
        ...

    def memory(self, name: str, nid: int, top: int, *, reset_by_halt: bool = True) -> str:
        """Declare a memory variable ``0..top`` of node ``nid``; its name."""
        ...

    def call(self, cond: str, child: int) -> None:
        """The current node calls ``child``."""
        ...

    def ret(self, cond: str, nid: int, status: str) -> None:
        """``nid`` returns ``status`` to its parent."""
        ...


#: A family's NuSMV rule (the module docstring).
NusmvRule = Callable[[BTCore, CompiledNode, str, str, Resets], None]
#: A rule serving several names, told which: ``rule(core, x, name, here, called, resets)``.
NamedNusmvRule = Callable[[BTCore, CompiledNode, str, str, str, Resets], None]


def named(rule: NamedNusmvRule, name: str) -> NusmvRule:
    """``rule`` for the rule name ``name``, in the ``NusmvRule`` calling convention."""

    def encode(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
        rule(core, x, name, here, called, resets)

    return encode
