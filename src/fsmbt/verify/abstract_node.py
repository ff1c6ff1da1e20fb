"""One node over abstract children, run by fsmbt's interpreter one tick at a time: the shape
every local argument about a tree node shares (docs/semantics.md §4d).

Why a module of its own: the per-node check (``verify/pernode.py``), the lower bound on a
counterexample (``verify/lower_bound.py``), the tickable-node analysis
(``verify/tickable.py``), the lift's shortest realizations (``verify/lift.py``) and NuSMV's
local encoding (``verify/nusmv/encode_local.py``) all read a node ``N`` as ``N`` itself (its
type, ports and semantics) over abstract leaves ``⟪i⟫`` whose outcomes an environment
chooses. Node behaviour is the interpreter's, never the converter's.
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.semantics.bt_interpreter import BTInterpreter, CompiledNode, LeafRequest
from fsmbt.semantics.compiled import RUNNING, Work

#: (interpreter snapshot, child position or ``None`` between ticks)
State = tuple[Any, int | None]
#: (input: ``"tick"``, ``"halt"`` or a child's status, its cost, next state, event:
#: ``("tick", i)``, ``("exit", status)`` or ``("none", None)`` after a halt)
Edge = tuple[Any, int, State, tuple[str, Any]]


def abstract_tree(
    node: CompiledNode, kids_running: list[bool], names: list[str] | None = None
) -> BTDocument:
    """The tree side's shape of a local problem: N (its type, ports and semantics) over
    abstract leaves, child i an action when it may return RUNNING (else a condition), named
    ``names[i]`` (default ``⟪i⟫``). Only a shape: fsmbt's interpreter runs it
    (``AbstractRun``, ``pernode``), NuSMV's own tick rules in ``nusmv.encode_local``."""
    source = node.source
    labels = names if names is not None else [f"⟪{i}⟫" for i in range(len(kids_running))]
    leaves = [
        BTNode(label, NodeKind.ACTION if running else NodeKind.CONDITION, name=label)
        for label, running in zip(labels, kids_running, strict=True)
    ]
    copy = BTNode(
        source.type,
        source.kind,
        attrs=dict(source.attrs),
        children=leaves,
        semantics=source.semantics,
    )
    return BTDocument.single(copy)


class AbstractRun:
    """A node over abstract children run by fsmbt's interpreter, one tick at a time
    (``exactly_once``: a RUNNING is returned to the parent), ``halt`` between ticks (the
    interpreter's ``haltChild``: ``halt()`` when RUNNING, the status reset otherwise). Child
    ``i`` may return the statuses of ``kids[i]`` (status -> the cost a search gives that
    event; 0 where only reachability counts). Cost: one interpreter step per edge."""

    def __init__(self, node: CompiledNode, kids: list[dict[int, int]]) -> None:
        self.interp = BTInterpreter(
            abstract_tree(node, [RUNNING in k for k in kids]), exactly_once=True
        )
        self.index = {n.id: int(n.label[1:-1]) for n in self.interp.tree.nodes if n.is_env_leaf}
        self.kids = kids

    def start(self) -> State:
        """The node at rest, between ticks."""
        return (self.interp.initial(), None)

    def _run(self, snap: Any, outcome: int | None) -> tuple[State, tuple[str, Any]]:
        snap, event = self.interp.advance(snap, outcome)
        if isinstance(event, LeafRequest):
            i = self.index[event.node.id]
            return (snap, i), ("tick", i)
        # the wake-up flag is the parent's business: a RUNNING is returned either way
        return ((snap[0], snap[1], snap[2], False), None), ("exit", event.status)

    def edges(self, state: State) -> list[Edge]:
        """Every input offered in ``state``: ``tick`` and ``halt`` between ticks (in that
        order), else each status child ``position`` may return (sorted)."""
        snap, position = state
        if position is None:
            tick = self._run(self.interp.begin_tick(snap), None)
            w = Work(snap)
            self.interp.reset_child(w, 0, None)
            return [("tick", 0, *tick), ("halt", 0, (w.snapshot(), None), ("none", None))]
        return [
            (status, cost, *self._run(snap, status))
            for status, cost in sorted(self.kids[position].items())
        ]
