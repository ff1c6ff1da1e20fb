"""A recorded execution as fsmbt reads it: the tree the recorder embedded (node ids -> places)
and the status transitions, in order (docs/conform.md, 'Logs').

Every reader (``btlog.py``, ``trace.py``) returns a ``RecordedLog``; the replay
(``replay.py``) never looks at where it came from.
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: BehaviorTree.CPP's ``NodeStatus`` values, as written in its logs.
IDLE, RUNNING, SUCCESS, FAILURE, SKIPPED = 0, 1, 2, 3, 4
STATUS_NAMES = {
    IDLE: "IDLE",
    RUNNING: "RUNNING",
    SUCCESS: "SUCCESS",
    FAILURE: "FAILURE",
    SKIPPED: "SKIPPED",
}
#: A leaf's status as the leaf-execution machine's input (docs/semantics.md).
OUTCOMES = {RUNNING: "running", SUCCESS: "success", FAILURE: "failure"}


@dataclass(frozen=True)
class LoggedNode:
    """One node of the tree a log embeds.

    Attributes:
        uid: the id the log's transitions use.
        label: its instance name (else its type).
        type: its registration ID.
        path: its child-index path from the main tree's root through expanded SubTrees (a
            SubTree's tree root is its child 0): the interpreter's ``CompiledNode.path``.
        leaf: it has no children and is not a SubTree.
    """

    uid: int
    label: str
    type: str
    path: str
    leaf: bool


@dataclass
class RecordedLog:
    """A log: its file, embedded nodes by uid, the root's uid, and the transitions.

    ``times`` are microseconds since ``start_us`` (itself microseconds since the epoch, or 0
    when the format has no clock); ``uids`` and ``statuses`` are parallel arrays (one entry per
    transition, so a 10^6-event log is three flat lists, not a million objects).
    """

    path: str
    format: str
    nodes: dict[int, LoggedNode]
    root: int
    start_us: int = 0
    times: list[int] = field(default_factory=list)
    uids: list[int] = field(default_factory=list)
    statuses: list[int] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.uids)
