"""What a BT node is (control, decorator, action, condition, subtree): ``NodeKind``.

Its own module so that the node registry (``fsmbt.model.nodes``) and the tree model
(``fsmbt.model.bt``) can both use it without importing each other; ``fsmbt.model.bt_nodes``
re-exports it under its old name.
"""

from __future__ import annotations

from enum import Enum


class NodeKind(str, Enum):
    """What a node is, which decides how many children it has and what it may return."""

    CONTROL = "Control"
    DECORATOR = "Decorator"
    ACTION = "Action"
    CONDITION = "Condition"
    SUBTREE = "SubTree"


__all__ = ["NodeKind"]
