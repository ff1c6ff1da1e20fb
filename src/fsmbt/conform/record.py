"""Record real BehaviorTree.CPP 4.8.2 logs of scripted runs (docs/conform.md, 'Recording a run'):
a tree's own XML loaded in behaviortreepy with every leaf type registered as a scripted leaf
(seeded random outcomes: conditions success/failure, actions also running), behaviortreepy's
``FileLogger`` (FileLogger2, ``.btlog``) attached, ticked ``ticks`` times with ``tickOnce``.

4.8.2's FileLogger2 loses transitions when it is destroyed too early: its destructor stops the
writer thread, which drops what it has not taken from its queue yet (all of them when the thread
has not run once, which happens on a loaded machine). So the recorder waits, before it destroys
the logger, until the file holds every completed tick's closing ``root -> IDLE`` record (the
last transition of a tick that returns SUCCESS or FAILURE, ``Tree::tickRoot``'s
``resetStatus``) and has stopped growing for ``QUIET_S`` seconds (what a last RUNNING tick
wrote has no such marker); at most ``WAIT_LIMIT_S`` seconds, then ``RecordingError``.

Needs behaviortreepy (installed by scripts/setup.sh); imported only when called. Costs: the
engine's ticks plus one Python callback per leaf tick, then a wait of about ``QUIET_S``.
"""

from __future__ import annotations

import random
import time
from pathlib import Path

from fsmbt.conform.btlog import MAGIC, RECORD, embedded_nodes
from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind

#: How long the log must stay the same size before the logger may be destroyed (seconds).
QUIET_S = 0.2
#: How long the recorder waits for the logger's writer thread at most (seconds).
WAIT_LIMIT_S = 60.0
_IDLE = 0


class RecordingError(RuntimeError):
    """BehaviorTree.CPP's logger did not write the run to its file in time."""


def _closed_ticks(data: bytes) -> int | None:
    """How many ``root -> IDLE`` records the log's whole records hold; None while the header
    is not on disk yet (the module docstring of fsmbt.conform.btlog has the layout)."""
    head = len(MAGIC) + 5
    if len(data) < head:
        return None
    size = int.from_bytes(data[head - 4 : head], "little", signed=True)
    body = head + size + 8
    if size <= 0 or len(data) < body:
        return None
    _nodes, root = embedded_nodes(data[head : head + size].decode("utf-8"), "the log")
    records = memoryview(data)[body : len(data) - (len(data) - body) % RECORD]
    return sum(
        1
        for at in range(0, len(records), RECORD)
        if records[at + 8] == _IDLE and records[at + 6] | (records[at + 7] << 8) == root
    )


def _wait_until_written(path: Path, closed: int) -> None:
    """Wait until ``path`` holds ``closed`` root -> IDLE records and is quiet (see the module
    docstring)."""
    deadline = time.monotonic() + WAIT_LIMIT_S
    size, since = -1, time.monotonic()
    while True:
        data = path.read_bytes() if path.exists() else b""
        now = time.monotonic()
        if len(data) != size:
            size, since = len(data), now
        seen = _closed_ticks(data)
        if seen is not None and seen >= closed and now - since >= QUIET_S:
            return
        if now > deadline:
            raise RecordingError(
                f"{path}: BehaviorTree.CPP's FileLogger2 wrote {seen or 0} of {closed} "
                f"completed ticks within {WAIT_LIMIT_S:.0f} s"
            )
        time.sleep(0.01)


def record_btlog(doc: BTDocument, xml: str, path: Path, *, seed: int, ticks: int) -> list[str]:
    """Run ``xml`` (the text of ``doc``) in BehaviorTree.CPP and log it to ``path``; returns the
    root status of each tick.

    Raises:
        ImportError: behaviortreepy is not installed.
        RecordingError: the logger did not write the run within ``WAIT_LIMIT_S``.
    """
    import behaviortreepy as btpy  # a compiled extension: only when a run is recorded

    rng = random.Random(seed)
    status = {
        "success": btpy.NodeStatus.SUCCESS,
        "failure": btpy.NodeStatus.FAILURE,
        "running": btpy.NodeStatus.RUNNING,
    }

    def condition(_node: object) -> object:
        return status[rng.choice(("success", "failure"))]

    def action(_node: object) -> object:
        return status[rng.choice(("success", "failure", "running"))]

    def halt(_node: object) -> None:
        return None

    factory = btpy.BehaviorTreeFactory()
    registered: set[str] = set()
    for _tree, node in doc.nodes():
        if node.type in registered or node.is_builtin:
            continue
        if node.kind is NodeKind.CONDITION:
            factory.register_simple_condition(node.type, condition)
        elif node.kind is NodeKind.ACTION:
            factory.register_simple_stateful_action(node.type, action, action, halt)
        else:
            continue
        registered.add(node.type)
    tree = factory.create_tree_from_text(xml)
    logger = btpy.FileLogger(tree, str(path))
    results = [str(tree.tick_once()).rsplit(".", 1)[-1] for _ in range(ticks)]
    # no logger.flush(): in 4.8.2 it writes the file from this thread while the logger's writer
    # thread writes it too (no lock: fixed after 4.8.2), which can duplicate records
    _wait_until_written(path, sum(r in ("SUCCESS", "FAILURE") for r in results))
    del logger  # the writer thread has taken every transition: the destructor loses none
    return results
