"""What a tick rule works on: a compiled node, the statuses, the mutable working state and the
shape of a rule's answer (docs/semantics.md, "Node families").

Why a module of its own: the interpreter (``bt_interpreter``) dispatches to the node families'
tick rules (``fsmbt.semantics.families``) and the families need these types; keeping them here,
below both, means neither imports the other's module (no import cycle). ``bt_interpreter``
re-exports every name, so existing callers keep importing them from there.

Costs: none at run time beyond the classes themselves; ``Work`` copies a snapshot's dicts once
per ``advance`` call.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Final, Protocol

from fsmbt.model.bt import BTNode
from fsmbt.model.errors import InputError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.status import NodeStatus

# -- statuses (fsmbt.semantics.status; docs/semantics.md "Statuses") ---------------------------
# Plain-int aliases of NodeStatus for the hot loops: snapshots hold them, and an int hashes
# three times faster than an IntEnum member (equal values, equal hashes).
IDLE: Final[int] = NodeStatus.IDLE.value
RUNNING: Final[int] = NodeStatus.RUNNING.value
SUCCESS: Final[int] = NodeStatus.SUCCESS.value
FAILURE: Final[int] = NodeStatus.FAILURE.value
SKIPPED: Final[int] = NodeStatus.SKIPPED.value

#: The type of the synthetic condition leaves the interpreter adds (an abstraction's gate, a
#: ManualSelector's picks): never a registered kind, so always an environment leaf.
GATE_TYPE = "_fsmbt_gate"


class BTRuntimeError(InputError):
    """The tree does something BehaviorTree.CPP would throw on (e.g. a child returns IDLE)."""


class NodePaths(Protocol):
    """What a compiled node asks its tree for (``CompiledTree.path_of``)."""

    def path_of(self, nid: int) -> str: ...


@dataclass(frozen=True)
class CompiledNode:
    """One node after SubTree expansion; ``id`` is its pre-order index."""

    id: int
    type: str
    kind: NodeKind
    children: tuple[int, ...]
    label: str
    parent: int | None
    index: int  # position among the parent's children
    source: BTNode = field(compare=False, repr=False)
    params: tuple[Any, ...] = ()
    internal_status: int | None = None  # for internal built-in leaves
    tree: NodePaths | None = field(default=None, compare=False, repr=False)

    @property
    def path(self) -> str:
        """Child indices from the root joined by ``/`` (``""`` for the root); a SubTree node
        has its tree's root as child 0. Computed on demand: O(depth)."""
        assert self.tree is not None
        return self.tree.path_of(self.id)

    @property
    def is_env_leaf(self) -> bool:
        """A leaf whose outcome the environment decides (observable in traces)."""
        return self.kind in (NodeKind.ACTION, NodeKind.CONDITION) and self.internal_status is None

    @property
    def is_condition(self) -> bool:
        return self.kind is NodeKind.CONDITION


# -- run-time configuration ------------------------------------------------------------------
#: A snapshot: (statuses, memories, frames, wake-up pending). Hashable; equal snapshots behave
#: the same for every future input.
Snapshot = tuple[
    tuple[tuple[int, int], ...],
    tuple[tuple[int, tuple[Any, ...]], ...],
    tuple[tuple[Any, ...], ...],
    bool,
]


class Work:
    """The mutable working copy of a snapshot: statuses ``st`` (IDLE ones absent), memories
    ``mem`` (default ones absent), the frame stack and the pending wake-up."""

    __slots__ = ("st", "mem", "frames", "wake")

    def __init__(self, snap: Snapshot) -> None:
        self.st: dict[int, int] = dict(snap[0])
        self.mem: dict[int, tuple[Any, ...]] = dict(snap[1])
        self.frames: list[tuple[Any, ...]] = list(snap[2])
        self.wake: bool = snap[3]

    def snapshot(self) -> Snapshot:
        return (
            tuple(sorted(self.st.items())),
            tuple(sorted(self.mem.items())),
            tuple(self.frames),
            self.wake,
        )


HaltHook = Callable[[CompiledNode], None]
#: A frame on the interpreter's stack: (node id, pc, locals...).
Frame = tuple[Any, ...]
#: What a tick rule does next: ("call", child id, new frame) or ("ret", status).
TickAction = tuple[Any, ...]
