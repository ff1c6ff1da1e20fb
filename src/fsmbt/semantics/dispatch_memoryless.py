"""Which dispatch trees have macro steps that are a function of the blackboard alone
(docs/semantics.md §12, "NuSMV"; docs/nusmv.md, "The dispatch form").

BehaviorTree.CPP 4.8.2's rules for the nodes both dispatch forms are made of keep no memory
that changes what a tick does:

- ``Switch2``..``Switch6`` ticks the first child whose case equals the entry's value, else the
  default; its ``running_child_`` only decides which child it halts when the match changes;
- ``KeepRunningUntilFailure`` maps its child's SUCCESS to RUNNING and FAILURE to FAILURE,
  resetting the child either way;
- ``ReactiveFallback`` re-ticks from its first child every tick; a RUNNING child halts the
  others, SUCCESS resets them all;
- ``SubTree`` is transparent (and resets its child when it completes);
- ``AlwaysSuccess``/``AlwaysFailure`` answer without a callback;
- ``DispatchEntry`` (a leaf with no halt behaviour) runs its action and returns SUCCESS; every
  parent above resets it after a SUCCESS, so it is IDLE whenever it is ticked (never a stale
  ``StatefulActionNode`` answer).

Halting these nodes changes only their statuses, which no rule above reads. So one tick's path,
outputs, blackboard writes and root status depend only on the blackboard entries and the event:
a tree of these kinds is a Mealy machine over the entries' values. And since a
``DispatchEntry``'s SUCCESS makes each of those parents return at once (SUCCESS or RUNNING),
a tick runs at most one ``DispatchEntry``, after every read of the tick: its ``_onSuccess``
writes never change what the same tick reads. ``fsmbt.verify.nusmv.encode_dispatch`` encodes
exactly such trees; ``fsmbt.convert.engines`` keeps the dispatch form for NuSMV when this holds.

A node of any other kind is refused with the reason: ``Sequence``/``Fallback`` and the other
memory controls keep the running child's index across ticks; ``Script`` writes the blackboard
outside a ``DispatchEntry``; a status map (``Inverter``, ``Force*``) or a ``ReactiveSequence``
would let the tick go on after a ``DispatchEntry`` wrote the index. Cost: O(nodes).
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import REACTIVE_CONTROLS, RESULT_MAP_DECORATORS
from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.dispatch_runtime import ENTRY
from fsmbt.semantics.outcome_blackboard import SCRIPT, SWITCH, OutcomeTree

KEEP_RUNNING = "KeepRunningUntilFailure"
REACTIVE_FALLBACK = "ReactiveFallback"
#: The control and decorator kinds whose tick is a function of the blackboard (see above).
MEMORYLESS = frozenset({SWITCH, KEEP_RUNNING, REACTIVE_FALLBACK})


def memory_refusal(tree: OutcomeTree) -> tuple[CompiledNode, str] | None:
    """The first node (pre-order) outside the kinds above and why, or ``None`` when every
    node is one of them."""
    for node in tree.nodes:
        if node.kind is NodeKind.SUBTREE or node.type in MEMORYLESS:
            continue
        if node.internal_status is not None or node.type == ENTRY:
            continue
        return node, _why(node)
    return None


def _why(node: CompiledNode) -> str:
    if node.type == SCRIPT or node.source.type == "Script":
        return "it writes the blackboard outside a DispatchEntry's _onSuccess"
    if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
        return f"a dispatch tree's only leaves are {ENTRY}, AlwaysSuccess and AlwaysFailure"
    # status maps and reactive controls, as the node registry declares them (§9a)
    if node.type in RESULT_MAP_DECORATORS or node.type in REACTIVE_CONTROLS:
        return (
            "a tick could go on after a DispatchEntry wrote the index (only "
            f"{KEEP_RUNNING} over it is encoded)"
        )
    return (
        "it may keep memory between ticks (a running child's index, a counter, a timer) "
        "that the encoding of Switch, KeepRunningUntilFailure, ReactiveFallback and SubTree "
        "does not model"
    )
