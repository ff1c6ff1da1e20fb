"""Record real BehaviorTree.CPP 4.8.2 logs of scripted runs (docs/conform.md, 'Recording a run'):
a tree's own XML loaded in behaviortreepy with every leaf type registered as a scripted leaf
(seeded random outcomes: conditions success/failure, actions also running), behaviortreepy's
``FileLogger`` (FileLogger2, ``.btlog``) attached, ticked ``ticks`` times with ``tickOnce``.

Needs behaviortreepy (installed by scripts/setup.sh); imported only when called. Costs: the
engine's ticks plus one Python callback per leaf tick.
"""

from __future__ import annotations

import random
from pathlib import Path

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind


def record_btlog(doc: BTDocument, xml: str, path: Path, *, seed: int, ticks: int) -> list[str]:
    """Run ``xml`` (the text of ``doc``) in BehaviorTree.CPP and log it to ``path``; returns the
    root status of each tick.

    Raises:
        ImportError: behaviortreepy is not installed.
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
    del logger  # the destructor joins the writer thread: every transition is on disk
    return results
