"""Canonical leaf-execution states: keep only the memory that can still be read (docs/semantics.md §4a).

Why: a faithful interpreter snapshot (``bt_interpreter.Snapshot``) remembers everything the
engine stores, including what it will reset before it ever reads it again: the SUCCESS/FAILURE
status a finished child keeps until its parent resets it, the RUNNING status of a halted-to-be
action, the RUNNING status of a reactive node whose halt only clears statuses. Two snapshots
that differ only there have the same future, but the checker counts them as two states; on
reactive trees that multiplies the leaf-execution machine (``benchmarks/bench_reactive.py``: a
102-node ReactiveSequence/ReactiveFallback tree has 1 820 faithful states and 71 canonical ones).

The canonical class (``is_canonical_class``; read from the node registry, no node list here):
every node of the compiled tree is ticked by the ``sequence`` rule (Sequence and Fallback,
plain, WithMemory or Async) or the ``reactive`` rule (ReactiveSequence/ReactiveFallback), is a
status-mapping decorator (``result_map``: Inverter, ForceSuccess, ForceFailure), a transparent
SubTree, an internal leaf or an environment leaf. In this class no node ever returns SKIPPED
(only RunOnce and all-skipped composites do), so a wake-up never survives to a leaf request and
a sequence's skipped counter is always 0.

``canonical(snapshot)`` applies four erasures (the proof that each keeps the future is
docs/semantics.md §4a):

1. every SUCCESS/FAILURE status is dropped: in the class, a parent resets a finished child
   before it ticks that child again, so a finished status is never read;
2. a frame's ``prev`` (the child's status before the call) is set to IDLE unless the frame's
   node is asynchronous or WithMemory - the only rule that reads it (the wake-up test);
3. a RUNNING status is kept only when it can still be read: its node's parent reads ``prev``,
   or the node keeps memory that its ``halt()`` resets (a plain Sequence's running index), or a
   child's RUNNING status is kept (halting this node must reach that child). Otherwise the
   status is only ever read by a ``halt()`` whose whole effect is to clear it;
4. the status of every node on the stack (the path from the root to the requested leaf) is
   dropped: each gets its status again from ``executeTick`` when it returns, and nothing reads
   it before (a halt only reaches children that are not on the stack).

Memories are kept as they are (a WithMemory index, a running child index: both are read).

Costs: ``canonical`` is O(k + d) for k stored statuses and stack depth d (one reverse pass over
the RUNNING nodes, ids are pre-order so children come after parents); building the tables is
O(N).
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import IDLE, RUNNING, CompiledTree, Snapshot
from fsmbt.semantics.nodes import runtime_tables

#: The interpreter's tick rules whose nodes may be in the canonical class (with the status
#: maps, SubTree and leaves): the registry names each kind's rule (``NodeSemantics.handler``).
CANONICAL_RULES: frozenset[str] = frozenset({"sequence", "reactive"})


def is_canonical_class(tree: CompiledTree) -> bool:
    """Whether every node of ``tree`` is in the canonical class (module docstring). O(N)."""
    tables = runtime_tables()
    for node in tree.nodes:
        if node.kind is NodeKind.CONTROL:
            if tables.handlers.get(node.type) not in CANONICAL_RULES:
                return False
        elif node.kind is NodeKind.DECORATOR:
            if node.type not in tables.result_maps:
                return False
        elif node.kind is NodeKind.SUBTREE:
            if node.type != "SubTree" or len(node.children) != 1:
                return False
        elif node.kind not in (NodeKind.ACTION, NodeKind.CONDITION):
            return False
    return True


class Canonicalizer:
    """The erasures of the module docstring for one compiled tree of the canonical class."""

    def __init__(self, tree: CompiledTree) -> None:
        tables = runtime_tables()
        flags = tables.sequence_flags
        nodes = tree.nodes
        #: reads_prev[n]: n's tick rule reads its child's status before the call (wake-up test).
        self.reads_prev = [
            node.type in flags and (flags[node.type][1] or flags[node.type][2]) for node in nodes
        ]
        #: sequence_frame[n]: n's frames are (id, pc, prev) of the ``sequence`` rule.
        self.sequence_frame = [node.type in flags for node in nodes]
        #: halt_resets[n]: n's halt() forgets its memory.
        self.halt_resets = [node.type in tables.halt_resets_memory for node in nodes]
        self.parent_reads_prev = [
            node.parent is not None and self.reads_prev[node.parent] for node in nodes
        ]
        self.parent = [node.parent if node.parent is not None else -1 for node in nodes]

    def canonical(self, snap: Snapshot) -> Snapshot:
        """``snap`` with every status and frame local that cannot be read erased.

        Args:
            snap: a snapshot of an interpreter running this tree (at a leaf request or between
                ticks).

        Returns:
            The canonical snapshot; equal for snapshots with the same future.
        """
        statuses, memories, frames, wake = snap
        running = [nid for nid, status in statuses if status == RUNNING]
        kept: set[int] = set()
        if running:
            with_memory = {nid for nid, _ in memories}
            parent_reads_prev, halt_resets, parent = (
                self.parent_reads_prev,
                self.halt_resets,
                self.parent,
            )
            # Reverse pre-order: every child is decided before its parent, and a kept child
            # marks its parent (rule 3) through ``needed``.
            needed: set[int] = set()
            for nid in reversed(running):
                if (
                    nid in needed
                    or parent_reads_prev[nid]
                    or (halt_resets[nid] and nid in with_memory)
                ):
                    kept.add(nid)
                    needed.add(parent[nid])
        # Rule 4: the nodes on the stack (the path to the requested leaf) get their status from
        # ``executeTick``'s epilogue when they return, before anything can read it.
        for frame in frames:
            kept.discard(frame[0])
        new_statuses = tuple((nid, RUNNING) for nid in running if nid in kept)
        sequence_frame, reads_prev = self.sequence_frame, self.reads_prev
        new_frames = tuple(
            (frame[0], frame[1], IDLE)
            if len(frame) == 3 and sequence_frame[frame[0]] and not reads_prev[frame[0]]
            else frame
            for frame in frames
        )
        return (new_statuses, memories, new_frames, wake)
