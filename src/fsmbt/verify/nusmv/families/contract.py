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

Beside its rules a family module exports ``TRAITS: dict[str, RuleTraits]``: what the encoder's
whole-tree checks read of each rule (SKIPPED, the frame variables the encoder declares, the
livelock test; docs/nusmv.md, "SKIPPED" and "Livelock"). A rule without an entry has the
default ``RuleTraits()``: it refuses a child that may skip, never returns SKIPPED itself, has no
``idx_n``/``prev_n``, and guarantees no leaf tick (the livelock test then counts on its
ancestors). So the encoder names no rule and no kind: adding a rule touches its family module.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics

Resets = dict[int, list[str]]


class BTCore(Protocol):
    """What the rules write into: the BT encoder (``encode_bt.BTCore``), which imports the
    rules (so they name the encoder's members they use, not the encoder)."""

    #: ``(name, expression)`` DEFINEs of the module (a parallel's counts).
    defines: list[tuple[str, str]]
    #: Per node id: whether the node can return SKIPPED (``encode_bt.BTCore``, from the rules' ``RuleTraits``).
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


#: ``(node, declaration) -> bool``: a trait that depends on the node's ports or declaration.
NodeTest = Callable[[CompiledNode, NodeSemantics], bool]
#: ``(node, declaration, may_skip) -> bool``, ``may_skip`` per node id (children already set).
SkipTest = Callable[[CompiledNode, NodeSemantics, Sequence[bool]], bool]
#: ``(node, declaration, sure, busy, may_skip) -> (sure, busy)``, per node id, children already
#: set (``encode_bt.BTCore`` reads the facts bottom-up; docs/nusmv.md, "Livelock").
LeafFacts = Callable[
    [CompiledNode, NodeSemantics, Sequence[bool], Sequence[bool], Sequence[bool]],
    tuple[bool, bool],
]


@dataclass(frozen=True)
class RuleTraits:
    """What the encoder's whole-tree checks read of one rule (the module docstring).

    Attributes:
        skip_aware: the rule encodes a child that returns SKIPPED (``None``: never; a parent of
            a child that may skip whose rule is not skip-aware is refused).
        returns_skipped: whether the node may return SKIPPED, given its children's answers
            (``None``: never). A skip-aware rule usually returns it when every child may
            (``common.every_child_skips``).
        index: the encoder declares ``idx_n``, the running child's index (reset by the node's
            halt unless its declaration has ``with_memory``).
        prev: the encoder declares ``prev_n``, the child's status when called (a wake-up test).
        keeps_completed: an action child under this rule is ticked again only after a reset
            (never ticked stale, so each of its ticks asks the environment).
        leaf_facts: ``(sure, busy)`` of the node from its children's: every tick of it ticks an
            environment leaf, every tick while RUNNING does (``None``: neither).
        answers_alone: a tick of the node may end without ticking any leaf (``None``: never).
        ticks_forever: the node may keep its child ticking without end (``None``: never).
    """

    skip_aware: NodeTest | None = None
    returns_skipped: SkipTest | None = None
    index: bool = False
    prev: bool = False
    keeps_completed: bool = False
    leaf_facts: LeafFacts | None = None
    answers_alone: NodeTest | None = None
    ticks_forever: NodeTest | None = None


#: The traits of a rule its family does not describe (``RuleTraits``' defaults).
NO_TRAITS = RuleTraits()
