"""A BT region as one small sub-machine per node, built from each node's own tick rule, never
by exploring (docs/conversion.md, "Per-node conversion"; docs/semantics.md §4d; issue 27).

Why: the compact form (``bt_compact``) and the unrolled form explore the region's
leaf-execution machine first, whose states are the *product* of the memories of its nodes (a
running index per plain control under a reactive one, a WithMemory index, retry counts ...):
a mixed tree of a few hundred nodes already has more configurations than any limit. Here the
memory of each node is its own SCXML variable and each node's rule is written once, so the
machine is linear in the region: its W3C meaning (configurations x valuations) is the product,
but it is never built by the converter.

The machine (one flat SCXML state list; every state tagged ``fsmbt:node`` (the SCXML writer's fsmbt
namespace, Clark notation in ``attrs``) = the node's path as
``CompiledNode.path`` names it, ``""`` for the region's root):

- a *leaf* is one state whose action is the leaf's label (as the other forms); its events
  ``success``/``failure`` (and ``running`` for an action) lead to where its parent's rule says;
- every other node has an *entry* (the state its tick starts in: a transient state with no
  action whose eventless guarded transitions pick the child to tick from the node's memory, or,
  when the node always starts at its first child, that child's entry) and receives three
  *returns* from its parent: where its SUCCESS, FAILURE and RUNNING lead, each a target state
  plus the assignments to run on the way (``Cont``). A return that depends on data (a wake-up
  test, a retry count) is a transient state of the node with guarded eventless transitions;
- a RUNNING that reaches the region's root ends the tick: the next tick enters the root again
  at its own entry state (the root always has one, so that the next tick is told apart from
  a child's entry: ``fsmbt.verify.pernode`` reads it as the root's RUNNING exit)
  (the region heads its part of the tree: its plain ancestors resume straight into it;
  docs/semantics.md §4c). A tick ending RUNNING and a wake-up's re-tick are not observable
  (§4), so they are the same eventless step back to the root's entry;
- halting a child (a reactive node halting the children after the one that returned) assigns
  the declared memory at rest to every variable of that child's subtree whose kind forgets it
  on halt (``halt_resets_memory``; a SequenceWithMemory keeps its index, as BehaviorTree.CPP
  4.8.2 does), and clears the "child was RUNNING" flags. A subtree that was not running already
  holds those values, so resetting it unconditionally is the interpreter's ``haltChild``.

Per rule (the handler names and flags of ``fsmbt.semantics.nodes.runtime_tables``; the
reference is each family's tick function in ``fsmbt.semantics.families``):

- ``sequence`` (Sequence, Fallback, SequenceWithMemory, Async*): ``idx`` (running child), and
  ``cr`` (the child at ``idx`` was RUNNING before this tick: the wake-up test reads it). Entry:
  ``[idx == i] -> child i``. Child i's go-on: ``idx = i + 1`` then the next child, or - for an
  asynchronous / with-memory kind whose child completed in this tick (``cr == 0``) - RUNNING
  (the wake-up); the last child's go-on resets ``idx``. The stop result resets ``idx`` (kept by
  a kind with memory). RUNNING sets ``cr``;
- ``reactive``: no memory; entry = child 0; a stop result or RUNNING halts the later children
  (a chain of transient states, one per child with memory, so that the size stays linear);
- ``simple_decorator``: rewires the child's results (``result_map``; none: SUCCESS becomes
  RUNNING, KeepRunningUntilFailure);
- ``repeat`` / ``retry``: ``count`` and ``cr``; the repeated result goes on while
  ``count + 1 < limit``: again at once after a child that was RUNNING, else RUNNING (wake-up).

Each family's rule lives in its own module of ``fsmbt.convert.pernode`` (``sequence``,
``reactive``, ``status_map``, ``loops``, ``parallel``: the rules above, in each module's header),
written through one ``Writer`` and dispatched on the declaration's handler name
(``pernode.registry.RULES``). Anything else in the region (SubTree, RunOnce, a gate, a built-in
leaf, a pre-condition, ``num_cycles="0"``, a Parallel threshold of 0) is refused with the
reason: the caller keeps today's explored form. Costs: O(N) states, O(N · d) assignments for d the nesting depth of reactive nodes (each
reactive node resets its children's subtrees once per chain), no exploration.

Proof obligation: the region's W3C meaning equals its leaf-execution machine (§4). The checker
discharges it on every conversion whose whole product it can build (every small tree of the
tests, ``tests/convert/test_conv_bt_pernode.py``), and ``fsmbt.verify.pernode`` per node.
"""

from __future__ import annotations

from collections.abc import Callable

from fsmbt.convert.pernode.kernel import NODE_ATTR, ROLE_ATTR, Cont, PerNodeRegion
from fsmbt.convert.pernode.registry import SUPPORTED_HANDLERS
from fsmbt.convert.pernode.sizing import (
    PERNODE_MIN_LOG2,
    PERNODE_SURE_NODES,
    PERNODE_TRY_STATES,
    memory_log2,
    pernode_estimate,
    refusal,
    region_size,
)
from fsmbt.convert.pernode.writer import Writer
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import CompiledTree


def pernode_region(
    node: BTNode,
    *,
    name: str,
    new_variable: Callable[[str], str],
    unique: Callable[[FSM, str], str],
) -> PerNodeRegion | str:
    """``node``'s subtree written per node (the module docstring), or why it cannot be.

    Args:
        node: the region's root (its ancestors plain: they resume straight into it).
        name: the sub-machine's name.
        new_variable: a unique variable name from a base (shared by one conversion).
        unique: a unique state name in a machine (the converter's rule).
    """
    try:
        tree = CompiledTree(BTDocument.single(node))
    except FsmbtError as exc:
        return str(exc)
    why = refusal(tree)
    if why is not None:
        return why
    return Writer(tree, name, new_variable, unique).build()


__all__ = [
    "NODE_ATTR",
    "ROLE_ATTR",
    "PERNODE_MIN_LOG2",
    "PERNODE_SURE_NODES",
    "PERNODE_TRY_STATES",
    "SUPPORTED_HANDLERS",
    "Cont",
    "PerNodeRegion",
    "memory_log2",
    "pernode_estimate",
    "pernode_region",
    "refusal",
    "region_size",
]
