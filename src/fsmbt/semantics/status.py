"""The one status vocabulary of fsmbt: node status, leaf outcome, machine status.

Why one module: the interpreter, the fast paths, the LEBT runtimes, the converters, the
baselines and the NuSMV encoder all speak about the same three things, and each used to spell
them its own way (integers, lower-case strings, upper-case literals). Every module now imports
them from here; docs/semantics.md ("Statuses") states what each value means.

- ``NodeStatus``: what a BehaviorTree.CPP v4 node returns or holds (``IDLE``, ``RUNNING``,
  ``SUCCESS``, ``FAILURE``, ``SKIPPED``). An ``IntEnum`` so that the interpreter's hashable
  snapshots stay small tuples of integers (``NodeStatus.SUCCESS == 2``); ``SKIPPED`` is returned
  but never stored, as ``TreeNode::executeTick`` does.
- ``LeafOutcome``: what the environment answers when a leaf is ticked; these are the input
  symbols of a leaf-execution machine (``"success"``, ``"failure"``, ``"running"``).
- ``MachineStatus``: whether an explored machine is still running or has ended (``"running"``,
  ``"final"``) - the status the checker compares.
- ``RootResult``: the two results a root can end a tick with, as leaf-execution outputs and as
  the names of a converted HFSM's exit states (``"SUCCESS"``, ``"FAILURE"``).

The ``str`` enums compare equal to their values, so reports and files keep the same text.
"""

from __future__ import annotations

from enum import Enum, IntEnum


class NodeStatus(IntEnum):
    """A node's status, numbered as BehaviorTree.CPP's ``NodeStatus`` is ordered."""

    IDLE = 0
    RUNNING = 1
    SUCCESS = 2
    FAILURE = 3
    SKIPPED = 4

    @property
    def is_completed(self) -> bool:
        """``SUCCESS`` or ``FAILURE`` (BehaviorTree.CPP's ``isStatusCompleted``)."""
        return self in (NodeStatus.SUCCESS, NodeStatus.FAILURE)


class LeafOutcome(str, Enum):
    """The environment's answer when a leaf is ticked (a leaf-execution input symbol)."""

    SUCCESS = "success"
    FAILURE = "failure"
    RUNNING = "running"

    def __str__(self) -> str:
        return self.value

    @property
    def status(self) -> NodeStatus:
        """The node status the leaf returns with this outcome."""
        return _OUTCOME_TO_STATUS[self]

    @classmethod
    def of(cls, status: NodeStatus) -> LeafOutcome:
        """The outcome that makes a leaf return ``status`` (``RUNNING``/``SUCCESS``/``FAILURE``)."""
        return _STATUS_TO_OUTCOME[status]


class MachineStatus(str, Enum):
    """Whether an explored machine goes on or has ended (what the checker compares)."""

    RUNNING = "running"
    FINAL = "final"

    def __str__(self) -> str:
        return self.value


class RootResult(str, Enum):
    """A root's result at the end of a tick, as an output symbol and an exit-state name."""

    SUCCESS = "SUCCESS"
    FAILURE = "FAILURE"

    def __str__(self) -> str:
        return self.value

    @property
    def status(self) -> NodeStatus:
        """The node status this result stands for."""
        return NodeStatus.SUCCESS if self is RootResult.SUCCESS else NodeStatus.FAILURE


_OUTCOME_TO_STATUS = {
    LeafOutcome.SUCCESS: NodeStatus.SUCCESS,
    LeafOutcome.FAILURE: NodeStatus.FAILURE,
    LeafOutcome.RUNNING: NodeStatus.RUNNING,
}
_STATUS_TO_OUTCOME = {status: outcome for outcome, status in _OUTCOME_TO_STATUS.items()}

__all__ = ["LeafOutcome", "MachineStatus", "NodeStatus", "RootResult"]
