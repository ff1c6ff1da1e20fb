"""The contract between the interpreter and a node family (docs/semantics.md, "Node families").

A family module exports ``RULES: dict[str, FamilyRule]``, keyed by the ``handler`` name its
kinds declare in ``fsmbt.model.nodes``. Each ``FamilyRule`` has:

- ``tick(ip, w, node, frame, result, hook) -> TickAction``: one step of the node's ``tick()``
  written as a resumable state machine (``bt_interpreter``'s module docstring). ``frame[1]`` is
  the pc (0: the node is ticked; otherwise a child just returned ``result``). The rule returns
  ``("call", child, new_frame)`` to tick a child and be resumed with ``new_frame``, or
  ``("ret", status)``. It reads and writes statuses in ``w.st``, its memory through
  ``ip.mem``/``ip.set_mem`` (stored only when it differs from the declared memory at rest), sets
  ``w.wake`` for the tree's wake-up signal, and resets children with ``ip.reset_child`` /
  ``ip.reset_children`` (``haltChild``: a RUNNING child is halted first).
- ``params(node, ctype, exact) -> tuple``: read the node's ports into ``CompiledNode.params``
  and check what BehaviorTree.CPP checks when it builds the tree (``InputError`` for a malformed
  node, ``UnsupportedError`` for what fsmbt cannot model exactly); ``None``: no ports. ``exact``
  is False when the kind is used as an abstraction (docs/semantics.md §10).
- ``extra_children(node, params) -> list[BTNode]``: synthetic condition leaves added after the
  node's children at compile time (ManualSelector's picks); ``None``: none.
- ``restarts``: a node of the rule ticks its children from the first on every tick and keeps
  no memory (the ``reactive`` rule): ``leaf_fast``'s static tables read it.
- ``canonical``: a ``CanonicalReads`` when the rule's nodes may be in the canonical class of
  ``semantics/leaf_canonical.py`` (docs/semantics.md §4a): who reads what a node of the rule
  stores; ``None``: a tree with such a node keeps faithful snapshots.

``halt()`` is not a function: every node's halt halts its RUNNING children and resets their
statuses (``bt_interpreter._halt``), and whether it also forgets its memory is the declared
``halt_resets_memory`` - data, read once into a set, so halting stays a set lookup per node.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from fsmbt.model.bt import BTNode
from fsmbt.semantics.compiled import CompiledNode, Frame, HaltHook, TickAction, Work


class Interp(Protocol):
    """What a tick rule may use of the interpreter (``bt_interpreter.BTInterpreter``)."""

    #: sequence kinds -> (is a fallback, asynchronous, with memory), from the declarations
    seq_flags: dict[str, tuple[bool, bool, bool]]
    #: reactive kinds of the fallback family
    reactive_fallbacks: frozenset[str]
    #: status-mapping decorator -> the statuses its child's SUCCESS/FAILURE become
    result_maps: dict[str, tuple[int, int]]

    def mem(self, w: Work, node: CompiledNode) -> tuple[Any, ...]:
        """The node's memory (its declared memory at rest when none is stored)."""
        ...

    def set_mem(self, w: Work, node: CompiledNode, value: tuple[Any, ...]) -> None:
        """Store the node's memory (dropped when equal to the memory at rest)."""
        ...

    def reset_child(self, w: Work, child: int, hook: HaltHook | None) -> None:
        """``ControlNode::haltChild``: halt ``child`` if RUNNING, then reset its status."""
        ...

    def reset_children(
        self, w: Work, node: CompiledNode, hook: HaltHook | None, first: int = 0
    ) -> None:
        """``resetChildren()`` from child ``first`` on."""
        ...


TickFn = Callable[[Interp, Work, CompiledNode, Frame, "int | None", "HaltHook | None"], TickAction]
ParamsFn = Callable[[BTNode, str, bool], tuple[Any, ...]]
ExtraChildrenFn = Callable[[BTNode, tuple[Any, ...]], list[BTNode]]


#: ``(node) -> bool``: a fact of one compiled node of the rule (its ports are ``node.params``).
NodeFact = Callable[[CompiledNode], bool]


@dataclass(frozen=True)
class CanonicalReads:
    """What ``leaf_canonical`` reads of a rule in the canonical class (docs/semantics.md §4a):
    which stored statuses and frame locals a node of the rule reads, so the others can be erased.

    Attributes:
        member: a node of the rule is in the class only when this holds (``None``: always; the
            ``gated`` rule: its closed gate does not return SKIPPED).
        prev_frame: the rule's frames hold the child's status before the call at index 2.
        reads_prev: the node reads that status (the wake-up test; ``None``: never).
        last_child_prev_unread: the wake-up test is never true after the last child (the
            ``sequence`` rule: ``idx < n`` fails there), so the last child's ``prev`` is unread.
        keeps_finished: the node may tick a finished child again without resetting it
            (PipelineSequence, GoalUpdater; a gate decides by its ``reset_on_done``).
        reads_gate: the declared ``Gate`` says what the node reads (its child's RUNNING, its
            own IDLE, whether it keeps a finished child).
        furthest_index: the memory is a furthest-child index over children that may be
            environment Actions holding SUCCESS (rule 5: PipelineSequence).
    """

    member: NodeFact | None = None
    prev_frame: bool = False
    reads_prev: NodeFact | None = None
    last_child_prev_unread: bool = False
    keeps_finished: bool = False
    reads_gate: bool = False
    furthest_index: bool = False


#: The reads of a rule in the canonical class that reads nothing more than every rule does.
PLAIN_READS = CanonicalReads()


@dataclass(frozen=True)
class FamilyRule:
    """One handler's behaviour (the module docstring says what each part does)."""

    tick: TickFn
    params: ParamsFn | None = None
    extra_children: ExtraChildrenFn | None = None
    restarts: bool = False
    canonical: CanonicalReads | None = None
