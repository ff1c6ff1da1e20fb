"""Reading a node's ports as BehaviorTree.CPP does when it builds the tree, for the families'
``params`` functions (docs/semantics.md, "Node families"). A port that names a blackboard entry
(``{key}``) is refused: its value is not known statically.

Costs: O(length of the port's text).
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.bt import BTNode
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.semantics.status import NodeStatus


def where(node: BTNode) -> dict[str, Any]:
    """The ``location`` and ``element`` keywords of an error about ``node``."""
    return {"location": node.location, "element": f"<{node.type}> '{node.label}'"}


def int_param(node: BTNode, port: str, default: int | None) -> int:
    """An integer port; ``default`` ``None``: the port is required."""
    raw = node.attrs.get(port)
    if raw is None:
        if default is None:
            raise InputError(f"missing port '{port}'", **where(node))
        return default
    text = raw.strip()
    if text.startswith("{") and text.endswith("}"):
        raise UnsupportedError(f"port '{port}' reads the blackboard ({text})", **where(node))
    try:
        return int(text)
    except ValueError:
        raise InputError(f"port '{port}' is not an integer: {raw!r}", **where(node)) from None


def bool_param(node: BTNode, port: str, default: bool) -> bool:
    """A boolean port (``true``/``false``/``1``/``0``)."""
    raw = node.attrs.get(port)
    if raw is None:
        return default
    text = raw.strip().lower()
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    if text.startswith("{"):
        raise UnsupportedError(f"port '{port}' reads the blackboard ({raw})", **where(node))
    raise InputError(f"port '{port}' is not a boolean: {raw!r}", **where(node))


def status_param(node: BTNode, port: str | None, default: str) -> int:
    """A port naming the status a node returns (``Precondition``'s ``else``...)."""
    raw = node.attrs.get(port) if port is not None else None
    text = (raw if raw is not None else default).strip()
    if text.startswith("{"):
        raise UnsupportedError(f"port '{port}' reads the blackboard ({text})", **where(node))
    if text not in ("SUCCESS", "FAILURE", "RUNNING", "SKIPPED"):
        raise InputError(f"port '{port}' is not a status: {raw!r}", **where(node))
    return int(NodeStatus[text])
