"""Canonical leaf-execution states: keep only the memory that can still be read (docs/semantics.md §4a).

Why: a faithful interpreter snapshot (``bt_interpreter.Snapshot``) remembers everything the
engine stores, including what it will reset before it ever reads it again: the SUCCESS/FAILURE
status a finished child keeps until its parent resets it, the RUNNING status of a halted-to-be
action, the RUNNING status of a reactive node whose halt only clears statuses. Two snapshots
that differ only there have the same future, but the checker counts them as two states; on
reactive trees that multiplies the leaf-execution machine (``benchmarks/bench_reactive.py``: a
102-node ReactiveSequence/ReactiveFallback tree has 1 820 faithful states and 71 canonical ones),
and on Nav2's trees (PipelineSequence, RecoveryNode, RoundRobin, RateController) it made the
explored machines two to six times larger than needed (``benchmarks/bench_nav2.py``).

The canonical class (``is_canonical_class``; read from the node registry and the family rules,
no node or rule list here): every control and decorator is ticked by a rule whose family gives
it ``CanonicalReads`` (``FamilyRule.canonical``, ``semantics/families/contract.py``): the
``sequence`` rule (Sequence and Fallback, plain, WithMemory or Async), ``reactive``, Nav2's
``pipeline``, ``recovery`` and ``round_robin``; status maps and KeepRunningUntilFailure, Repeat,
RetryUntilSuccessful, the gated abstractions whose closed gate does not return SKIPPED (the
rule's ``member`` test), GoalUpdater, Groot's Root; plus transparent SubTrees, internal leaves
and environment leaves. No node of the class ever returns SKIPPED (only RunOnce and the
SKIPPED-gates do, and composites only when every child did), so a sequence's skipped counter is
always 0.

Who reads a stored status (every read in ``bt_interpreter``): a leaf action's own tick (SUCCESS
or FAILURE is returned without asking; IDLE and RUNNING both ask the environment), a gated
node's own tick when ``free_when_idle`` (IDLE or not), the parent's frame ``prev`` (the wake-up
test of asynchronous / WithMemory sequences, Repeat and Retry: IDLE or not), a gated parent's
child-RUNNING tests, and every ``haltChild`` (RUNNING or not). Each rule's ``CanonicalReads``
says which of these apply to its nodes; ``_Tables`` reads them per node.

``canonical(snapshot)`` applies five rewrites (the proof that each keeps the future is
docs/semantics.md §4a):

1. a SUCCESS/FAILURE status is dropped when its node's parent resets a finished child before
   ticking it again (every rule of the class except ``pipeline``, GoalUpdater's and the gates
   with ``reset_on_done=False``), or when no reader tells it from IDLE (the node is not an
   environment action nor a ``free_when_idle`` gate, and its parent does not read ``prev``);
   a ``free_when_idle`` gate's SUCCESS/FAILURE reads as RUNNING when nothing below it is kept
   and its parent does not test its RUNNING status (1c);
2. a frame's ``prev`` is set to IDLE unless the frame's node reads it (asynchronous or
   WithMemory sequences, Repeat/Retry that may loop again), or when the child it called is
   the sequence's last child (the wake-up test needs more children to go);
3. a RUNNING status is kept only when it can still be read: the parent reads ``prev`` or tests
   the child's RUNNING status (gates), the node's own rule tells RUNNING from IDLE (a
   ``free_when_idle`` gate), the node keeps memory that its ``halt()`` resets, or a child's
   status is kept (halting this node would clear it). Otherwise the status is only ever read by
   a ``halt()`` whose whole effect is to clear erased statuses. (3b) A free-running gate
   RUNNING over a child kept only for the gate's own RUNNING test ticks that child without
   asking either way: both statuses go;
4. the status of every node on the stack (the path from the root to the requested leaf) is
   dropped: each gets its status again from ``executeTick`` when it returns, and nothing reads
   it before (no rule reads its own status after its first step; a halt only reaches children
   that are not on the stack);
5. a PipelineSequence's furthest index moves down past children that are Actions holding
   SUCCESS: they return SUCCESS until the pipeline resets them, and its memory with them.

Memories are kept as they are (a WithMemory index, a pipeline's furthest child, a recovery's
retry count, a round robin's position: all are read).

Costs: ``canonical`` is O(k + d) for k stored statuses and stack depth d (one reverse pass over
the stored statuses, ids are pre-order so children come after parents); building the tables is
O(N).
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes.registry import Gate
from fsmbt.semantics.bt_interpreter import (
    IDLE,
    RUNNING,
    SUCCESS,
    CompiledNode,
    CompiledTree,
    Snapshot,
)
from fsmbt.semantics.families.contract import CanonicalReads
from fsmbt.semantics.families.registry import rule as family_rule
from fsmbt.semantics.families.registry import rules as family_rules
from fsmbt.semantics.nodes import SUBTREE_TYPE, node_semantics, runtime_tables


def canonical_rules() -> frozenset[str]:
    """The handler names whose rules may put a node in the class (their family gives them
    ``CanonicalReads``; a ``member`` test may still exclude a node). O(rules)."""
    return frozenset(name for name, found in family_rules().items() if found.canonical)


def _reads_of(node: CompiledNode) -> CanonicalReads | None:
    """The ``CanonicalReads`` of ``node``'s rule (``None``: the rule is outside the class)."""
    handler = runtime_tables().handlers.get(node.type)
    found = family_rule(handler) if handler is not None else None
    return found.canonical if found is not None else None


def _gate_of(node: CompiledNode, reads: CanonicalReads | None) -> Gate | None:
    """The declared gate of a node whose rule reads it (``CanonicalReads.reads_gate``)."""
    if reads is None or not reads.reads_gate:
        return None
    spec = node_semantics(node.type)
    return spec.gate if spec is not None else None


def is_canonical_class(tree: CompiledTree) -> bool:
    """Whether every node of ``tree`` is in the canonical class (module docstring). O(N)."""
    for node in tree.nodes:
        if node.kind in (NodeKind.CONTROL, NodeKind.DECORATOR):
            reads = _reads_of(node)
            if reads is None or (reads.member is not None and not reads.member(node)):
                return False
        elif node.kind is NodeKind.SUBTREE:
            if node.type != SUBTREE_TYPE or len(node.children) != 1:
                return False
        elif node.kind not in (NodeKind.ACTION, NodeKind.CONDITION):
            return False
    return True


class _Tables:
    """Per node of one compiled tree, which readers of its status exist (module docstring)."""

    def __init__(self, tree: CompiledTree) -> None:
        tables = runtime_tables()
        nodes = tree.nodes
        reads = [_reads_of(node) or _NO_READS for node in nodes]
        gates = [_gate_of(node, reads[i]) for i, node in enumerate(nodes)]
        #: reads_prev[n]: n's frame holds its child's status before the call and reads it:
        #: asynchronous / WithMemory sequences, and Repeat/Retry when a child's completion can
        #: loop again in the same activation (num_cycles / num_attempts -1 or at least 2).
        self.reads_prev = [
            r.prev_frame and r.reads_prev is not None and r.reads_prev(node)
            for r, node in zip(reads, nodes)
        ]
        #: prev_frame[n]: n's frames hold ``prev`` at index 2 (the sequence and loop rules).
        self.prev_frame = [r.prev_frame for r in reads]
        #: last_child[n]: n is the last child of a parent whose wake-up test (``idx < n``
        #: after the child: the ``sequence`` rule) is never true for it: its ``prev`` is not
        #: read.
        last_child = [
            node.parent is not None
            and reads[node.parent].last_child_prev_unread
            and node.index == len(nodes[node.parent].children) - 1
            for node in nodes
        ]
        self.last_child = last_child
        #: halt_resets[n]: n's halt() forgets its memory.
        self.halt_resets = [node.type in tables.halt_resets_memory for node in nodes]
        #: keeps_finished[n]: n may tick a finished child again without resetting it.
        keeps_finished = [
            reads[i].keeps_finished or (gate is not None and not gate.reset_on_done)
            for i, gate in enumerate(gates)
        ]
        #: reads_child_running[n]: n's rule tests its child's RUNNING status (gates).
        reads_child_running = [
            gate is not None and (gate.free_when_running or gate.halt_on_closed) for gate in gates
        ]
        #: reads_own_idle[n]: n's own tick tells IDLE from the other statuses.
        reads_own_idle = [gate is not None and gate.free_when_idle for gate in gates]
        self.parent = [node.parent if node.parent is not None else -1 for node in nodes]
        self.sf_dead: list[bool] = []
        self.running_read: list[bool] = []
        #: sf_as_running[n]: a stored SUCCESS/FAILURE of n reads as RUNNING (rule 1c).
        self.sf_as_running: list[bool] = []
        #: weak_running[n]: n's RUNNING is read statically only by its gate parent's RUNNING
        #: test (R4); pairs_idle[g]: g is a gate whose RUNNING over such a RUNNING child reads
        #: as IDLE over IDLE (rule 3b: both tick the child without asking the gate).
        self.weak_running: list[bool] = []
        self.pairs_idle: list[bool] = []
        frees_running = [
            reads_own_idle[i]
            and gate is not None
            and gate.free_when_running
            and nodes[i].type not in tables.halt_resets_memory
            for i, gate in enumerate(gates)
        ]
        for i, node in enumerate(nodes):
            p = node.parent
            if p is None:  # the root: its result is reset by the tick's end
                self.sf_dead.append(True)
                self.running_read.append(reads_own_idle[i])
                self.sf_as_running.append(False)
                self.weak_running.append(False)
                self.pairs_idle.append(frees_running[i])
                continue
            parent_reads_prev = self.reads_prev[p] and not last_child[i]
            reads_own_sf = node.is_env_leaf and node.kind is NodeKind.ACTION
            self.sf_dead.append(
                not keeps_finished[p]
                or not (reads_own_sf or reads_own_idle[i] or parent_reads_prev)
            )
            self.running_read.append(
                parent_reads_prev or reads_child_running[p] or reads_own_idle[i]
            )
            self.sf_as_running.append(
                reads_own_idle[i]
                and not reads_child_running[p]
                and node.params[:1] == (RUNNING,)  # its closed gate returns RUNNING
                and node.type not in tables.halt_resets_memory
            )
            self.weak_running.append(
                reads_child_running[p] and not parent_reads_prev and not reads_own_idle[i]
            )
            self.pairs_idle.append(
                frees_running[i] and not parent_reads_prev and not reads_child_running[p]
            )


#: What a node whose rule is outside the class reads beyond every rule (nothing is erased
#: for it: ``Canonicalizer`` runs on trees of the class only).
_NO_READS = CanonicalReads()


class Canonicalizer:
    """The erasures of the module docstring for one compiled tree of the canonical class."""

    def __init__(self, tree: CompiledTree) -> None:
        t = _Tables(tree)
        self.reads_prev = t.reads_prev
        self.prev_frame = t.prev_frame
        self.last_child = t.last_child
        self.halt_resets = t.halt_resets
        self.parent = t.parent
        self.sf_dead = t.sf_dead
        self.running_read = t.running_read
        self.sf_as_running = t.sf_as_running
        self.weak_running = t.weak_running
        self.pairs_idle = t.pairs_idle
        #: pipeline id -> for each child, whether it is an environment Action (whose stored
        #: SUCCESS is returned again without asking: it can never return RUNNING, rule 5).
        self.pipelines: dict[int, tuple[bool, ...]] = {
            node.id: tuple(
                tree.nodes[c].is_env_leaf and tree.nodes[c].kind is NodeKind.ACTION
                for c in node.children
            )
            for node in tree.nodes
            if (reads := _reads_of(node)) is not None and reads.furthest_index
        }
        self.children = [node.children for node in tree.nodes]

    def canonical(self, snap: Snapshot) -> Snapshot:
        """``snap`` with every status and frame local that cannot be read erased.

        Args:
            snap: a snapshot of an interpreter running this tree (at a leaf request or between
                ticks).

        Returns:
            The canonical snapshot; equal for snapshots with the same future.
        """
        statuses, memories, frames, wake = snap
        if self.pipelines and memories:
            memories = self._pipeline_memories(statuses, memories, frames)
        kept: list[tuple[int, int]] = []
        if statuses:
            with_memory = {nid for nid, _ in memories}
            sf_dead, running_read, halt_resets, parent, sf_as_running = (
                self.sf_dead,
                self.running_read,
                self.halt_resets,
                self.parent,
                self.sf_as_running,
            )
            weak_running, pairs_idle = self.weak_running, self.pairs_idle
            # Reverse pre-order: every child is decided before its parent, and a kept child
            # marks its parent (rule 3) through ``needed``.
            needed: set[int] = set()
            weak: set[int] = set()  # gates whose only kept child is a weak RUNNING one
            for nid, status in reversed(statuses):
                if status != RUNNING and sf_as_running[nid] and nid not in needed:
                    status = RUNNING  # rule 1c: no reader tells the two apart
                if status == RUNNING:
                    if nid in weak and pairs_idle[nid]:
                        kept.pop()  # rule 3b: the child's RUNNING goes too (it was the last kept)
                        continue
                    memory = halt_resets[nid] and nid in with_memory
                    keep = nid in needed or running_read[nid] or memory
                    if keep and weak_running[nid] and not memory and nid not in needed:
                        weak.add(parent[nid])
                else:  # SUCCESS / FAILURE (SKIPPED is never stored, IDLE never listed)
                    keep = not sf_dead[nid]
                if keep:
                    kept.append((nid, status))
                    needed.add(parent[nid])
            # Rule 4: the nodes on the stack (the path to the requested leaf) get their status
            # from ``executeTick``'s epilogue when they return, before anything can read it.
            if frames and kept:
                on_stack = {frame[0] for frame in frames}
                kept = [item for item in kept if item[0] not in on_stack]
            kept.reverse()
        # Rule 2: a frame's ``prev`` is erased when its node does not read it, or when the
        # child it called (the next frame's node) is the last child of a sequence.
        prev_frame, reads_prev, last_child = self.prev_frame, self.reads_prev, self.last_child
        new_frames = list(frames)
        for k, frame in enumerate(frames):
            if len(frame) == 3 and prev_frame[frame[0]] and frame[2] != IDLE:
                callee = frames[k + 1][0] if k + 1 < len(frames) else -1
                if not reads_prev[frame[0]] or (callee >= 0 and last_child[callee]):
                    new_frames[k] = (frame[0], frame[1], IDLE)
        return (tuple(kept), memories, tuple(new_frames), wake)

    def _pipeline_memories(
        self,
        statuses: tuple[tuple[int, int], ...],
        memories: tuple[tuple[int, tuple[Any, ...]], ...],
        frames: tuple[tuple[Any, ...], ...],
    ) -> tuple[tuple[int, tuple[Any, ...]], ...]:
        """Rule 5: a pipeline's furthest index ``last`` is only compared with the index of a
        child that returned RUNNING; a child that is an Action holding SUCCESS returns SUCCESS
        until the pipeline resets it (and its memory with it), so ``last`` moves down past
        such children without changing any comparison."""
        changed = False
        done: dict[int, int] | None = None
        new: list[tuple[int, tuple[Any, ...]]] = []
        for nid, memory in memories:
            actions = self.pipelines.get(nid)
            if actions is not None and memory[0]:
                if done is None:
                    done = dict(statuses)
                    on_stack = {frame[0] for frame in frames}
                    for item in on_stack:
                        done.pop(item, None)
                last: int = memory[0]
                children = self.children[nid]
                while last > 0 and actions[last - 1] and done.get(children[last - 1]) == SUCCESS:
                    last -= 1
                if last != memory[0]:
                    changed = True
                    if last == 0:
                        continue  # the default memory is not stored
                    memory = (last,)
            new.append((nid, memory))
        return tuple(new) if changed else memories
