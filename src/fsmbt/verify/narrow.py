"""Stages that never go on, for a per-node check whose failures no run reaches
(docs/semantics.md §4d, "Children that never go on"; issue 27).

Why: the per-node check offers each child every status its own local check pairs, so a node
after a stage that can never go on (a ``ReactiveFallback`` whose two children can each fail but
never in the same tick, under a ``Fallback``: it never fails, so the next child is never
ticked) is still checked, and a one-transition change
there fails its local check although no run of the tree ever ticks it: the lift finds no run
and the region was left to its whole product, which stops on large trees with memory. Here,
for each failing node, the stages on its path (``approach.stages``: earlier siblings under a
sequence- or reactive-family parent) are searched alone (``tickable.NeverReturns``: any
interleaving of ticks and halts, a superset of every context), and a stage proven never to
return the statuses its parent goes on with is recorded as never returning them. The check
then runs again with that knowledge (``pernode.check_region``'s ``never``): the stage's parent
is offered only the statuses the stage can return, so its later children are dead
(``tickable.never_ticked``) and are skipped like every dead node.

Sound: a stage's fragment is equivalent to the stage (its own local check, children by
induction), so it leaves by a status's exit only when the stage returns that status, which
the search proved it never does; narrowing what the parent is offered removes only inputs
that never come. Cost: the searches of ``NeverReturns`` (one shared budget per region), then
one more walk of the region per round.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.status import NodeStatus
from fsmbt.verify.tickable import NeverReturns, stage_never_passes


class StagesNeverGoingOn:
    """The stage proofs of one region's merged tree, the searches shared between rounds.

    ``never``: node id -> statuses proven never returned (what ``check_region`` takes);
    ``proofs``: one sentence per proof, for the verdict."""

    def __init__(self, tree: CompiledTree) -> None:
        self.tree = tree
        self.searches = NeverReturns(tree)
        self.never: dict[int, frozenset[int]] = {}
        self.proofs: list[str] = []

    def add_for(self, failing: Iterable[tuple[str, int, Any]]) -> bool:
        """Search the stages of each failing node (``PerNodeOutcome.seen``: description, id in
        the merged tree, local counterexample); whether a new stage was proven never to go on.
        A node already dead by an earlier proof adds nothing."""
        added = False
        for _what, nid, _trace in failing:
            try:
                proof = stage_never_passes(self.tree, nid, self.searches)
            except FsmbtError:
                continue
            if proof is None or proof[0] in self.never:
                continue
            stage, passing = proof
            self.never[stage] = passing
            node, where = self.tree.nodes[stage], self.tree.nodes[nid]
            self.proofs.append(
                f"{where.type} at {where.path or 'the root'}: its earlier {node.type} at "
                f"{node.path or 'the root'} never returns "
                f"{' or '.join(sorted(NodeStatus(s).name for s in passing))}"
            )
            added = True
        return added
