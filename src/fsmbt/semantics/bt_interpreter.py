"""An interpreter of behavior trees that follows BehaviorTree.CPP v4 (4.8) tick rules exactly.

Why a resumable, explicit-stack design: the leaf-execution machine (``leaf_machine``) must pause
*inside* a tick, at the moment a leaf is ticked, and snapshot everything as a hashable value so
the checker can explore states. So every node's ``tick()`` is written as a small state machine:
a *frame* ``(node id, pc, locals...)`` on an explicit stack; ticking a child pushes a frame, a
child's return pops it and resumes the parent at ``pc``. No Python recursion is used anywhere
(trees may be 100 000 deep): compiling, ticking and halting all use explicit stacks.

Which node kinds exist, which family tick rule runs each (``fsmbt.semantics.families``: one
module per node family, bound into one dispatch dict here, docs/semantics.md §9a), their
memory at rest, which ``halt()`` forgets it and which kinds are refused and why come from the node registry
(``fsmbt.semantics.nodes.runtime_tables()``, docs/semantics.md "Node registry"); statuses are
``fsmbt.semantics.status.NodeStatus`` values (plain-int aliases below, for the hot loops).

What is modelled, node by node, is exactly the v4 code (see docs/semantics.md for the rules):
node statuses (``IDLE``/``RUNNING``/``SUCCESS``/``FAILURE``; ``SKIPPED`` is returned but never
stored, as ``TreeNode::executeTick`` does), each node's memory (running index, skipped count,
counters, Parallel's completed set...), ``halt()`` per node type, ``resetChildren()``, and the
tree's wake-up signal used by ``Tree::tickOnce`` (SequenceWithMemory, Repeat,
RetryUntilSuccessful and the Async controls emit it; ``tickOnce`` re-ticks the root at once while
it is RUNNING and a wake-up is pending; ``tickExactlyOnce`` does not).

Leaves: a Condition consults the environment on every tick; an Action is a
``StatefulActionNode`` (it may return RUNNING): it consults the environment when its status is
IDLE (``onStart``) or RUNNING (``onRunning``) and returns its old status, *without* consulting the
environment, when ticked while still SUCCESS/FAILURE. ``AlwaysSuccess``, ``AlwaysFailure``,
``Script``, ``SetBlackboard`` and ``UnsetBlackboard`` are internal: deterministic, never
observed. Blackboard- and time-dependent nodes are rejected with ``UnsupportedError``.

Complexity: compiling is O(N) for N nodes after SubTree expansion; one leaf-to-leaf advance is
O(nodes touched); a snapshot is O(k log k + d) for k nodes with non-default status/memory and
stack depth d.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import dataclass
from types import MethodType
from typing import Any, Final

from fsmbt import limits
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.compiled import FAILURE as FAILURE
from fsmbt.semantics.compiled import GATE_TYPE as GATE_TYPE
from fsmbt.semantics.compiled import IDLE as IDLE
from fsmbt.semantics.compiled import RUNNING as RUNNING
from fsmbt.semantics.compiled import SKIPPED as SKIPPED
from fsmbt.semantics.compiled import SUCCESS as SUCCESS
from fsmbt.semantics.compiled import BTRuntimeError as BTRuntimeError
from fsmbt.semantics.compiled import CompiledNode as CompiledNode
from fsmbt.semantics.compiled import Frame as Frame
from fsmbt.semantics.compiled import HaltHook as HaltHook
from fsmbt.semantics.compiled import Snapshot as Snapshot
from fsmbt.semantics.compiled import TickAction as TickAction
from fsmbt.semantics.compiled import Work as Work
from fsmbt.semantics.families.manual import MANUAL_STATUSES as MANUAL_STATUSES
from fsmbt.semantics.families.manual import manual_choices as manual_choices
from fsmbt.semantics.families.parallel import parallel_threshold as parallel_threshold
from fsmbt.semantics.families.ports import status_param, where
from fsmbt.semantics.families.registry import rule as family_rule
from fsmbt.semantics.families.registry import rules as family_rules
from fsmbt.semantics.nodes import (
    SUBTREE_TYPE,
    canonical_type,
    enabling_option,
    node_semantics,
    runtime_tables,
)
from fsmbt.semantics.status import LeafOutcome, NodeStatus

# -- statuses: plain-int aliases of NodeStatus for the hot loops (``fsmbt.semantics.compiled``)
STATUS_NAMES: tuple[str, ...] = tuple(status.name for status in NodeStatus)
#: Leaf outcomes as the environment / the leaf machine's inputs name them (plain ``str``).
OUTCOME_SUCCESS: Final[str] = LeafOutcome.SUCCESS.value
OUTCOME_FAILURE: Final[str] = LeafOutcome.FAILURE.value
OUTCOME_RUNNING: Final[str] = LeafOutcome.RUNNING.value
OUTCOME_TO_STATUS: dict[str, int] = {o.value: o.status.value for o in LeafOutcome}
STATUS_TO_OUTCOME: dict[int, str] = {v: k for k, v in OUTCOME_TO_STATUS.items()}


# -- supported node types: the node registry (fsmbt.semantics.nodes) ----------------------------
# Which kinds are ticked and by which rule, their default memory, which are refused and why:
# ``runtime_tables()``, read when a tree is compiled and when an interpreter is built.
#: Pre-condition attributes change control flow from the blackboard: rejected.
PRECONDITION_ATTRS = ("_skipIf", "_failureIf", "_successIf", "_while")


class BTLivelock(BTRuntimeError):
    """``tickOnce`` would re-tick the root forever without ticking an environment leaf (e.g.
    ``Repeat num_cycles=-1`` over ``AlwaysSuccess``): the real engine hangs."""


def _gate_leaf(node: BTNode, ctype: str) -> BTNode | None:
    """The condition leaf that asks the environment for an abstraction's input
    (``<label>.<word>``), when ``node`` is an enabled abstraction with a gate."""
    if node.semantics is None:
        return None
    spec = node_semantics(ctype)
    if spec is None or spec.gate is None or not spec.abstracted_for(node.attrs):
        return None  # (a Loop over a literal queue is exact: no gate)
    return BTNode(
        GATE_TYPE, NodeKind.CONDITION, f"{node.label}.{spec.gate.word}", location=node.location
    )


class CompiledTree:
    """A ``BTDocument``'s main tree with SubTrees expanded, validated against v4 rules."""

    def __init__(self, doc: BTDocument) -> None:
        self.doc = doc
        self.nodes: list[CompiledNode] = []
        self._paths: dict[int, str] = {}
        self._compile()

    # Compilation is iterative: a work stack of (BTNode, parent id, path, subtree chain).
    def _compile(self) -> None:
        tree = self.doc.main
        if tree.root is None:
            raise InputError(
                "the main behavior tree is empty",
                location=tree.location,
                element=f"BehaviorTree '{tree.id}'",
            )
        tables = runtime_tables()
        extra_children = {
            kind: found.extra_children
            for kind, handler in tables.handlers.items()
            if (found := family_rule(handler)) is not None and found.extra_children is not None
        }
        children_of: dict[int, list[int]] = {}
        raw: list[tuple[BTNode, str, int | None, int, tuple[Any, ...], int | None, NodeKind]] = []
        stack: list[tuple[BTNode, int | None, int, tuple[str, ...]]] = [
            (tree.root, None, 0, (tree.id,))
        ]
        # nodes once SubTrees are expanded (a SubTree used twice per level doubles the tree)
        max_nodes = limits.current().max_nodes
        while stack:
            node, parent, position, chain = stack.pop()
            nid = len(raw)
            if nid >= max_nodes:
                raise InputError(
                    limits.exceeded(
                        "the tree's nodes once SubTrees are expanded",
                        "max_nodes",
                        max_nodes,
                    ),
                    element=tree.id,
                )
            if parent is not None:
                children_of[parent].append(nid)
            children_of[nid] = []
            ctype, kind, params, internal, kids = self._check(node, chain)
            raw.append((node, ctype, parent, position, params, internal, kind))
            gate = _gate_leaf(node, ctype)
            if gate is not None:
                kids = [*kids, gate]  # the gate is the last child (docs/semantics.md §10)
            extra = extra_children.get(ctype)
            if extra is not None:  # e.g. ManualSelector's picks: conditions after the children
                kids = [*kids, *extra(node, params)]
            if ctype == SUBTREE_TYPE:
                target = node.attrs["ID"]
                kids = [self.doc.trees[target].root]  # type: ignore[list-item]
                chain = chain + (target,)
            for index in range(len(kids) - 1, -1, -1):
                stack.append((kids[index], nid, index, chain))
        # pre-order ids: stack pushes reversed, so children ids were assigned in order
        for nid, (node, ctype, parent, position, params, internal, kind) in enumerate(raw):
            self.nodes.append(
                CompiledNode(
                    id=nid,
                    type=ctype,
                    kind=kind,
                    children=tuple(children_of[nid]),
                    label=node.label,
                    parent=parent,
                    index=position,
                    source=node,
                    params=params,
                    internal_status=internal,
                    tree=self,
                )
            )

    def path_of(self, nid: int) -> str:
        """See ``CompiledNode.path``; cached per node."""
        cached = self._paths.get(nid)
        if cached is None:
            parts: list[str] = []
            x: int | None = nid
            while x is not None and x != 0:
                node = self.nodes[x]
                parts.append(str(node.index))
                x = node.parent
            cached = "/".join(reversed(parts))
            self._paths[nid] = cached
        return cached

    @classmethod
    def checker(cls, doc: BTDocument) -> CompiledTree:
        """A tree of ``doc`` left uncompiled, to check its nodes one at a time with
        ``check_node`` (``semantics/blockers.py`` lists every blocker, not only the first)."""
        tree = cls.__new__(cls)
        tree.doc = doc
        return tree

    def check_node(
        self, node: BTNode, chain: tuple[str, ...]
    ) -> tuple[str, NodeKind, tuple[Any, ...], int | None, list[BTNode]]:
        """Check one node against the v4 rules (as compiling does) and read it.

        Returns:
            Its canonical type, kind, parameters, internal id (or ``None``) and children.

        Raises:
            InputError: the node is malformed; ``UnsupportedError`` for what cannot be
                modelled exactly.
        """
        return self._check(node, chain)

    def _check(
        self, node: BTNode, chain: tuple[str, ...]
    ) -> tuple[str, NodeKind, tuple[Any, ...], int | None, list[BTNode]]:
        tables = runtime_tables()
        ctype = node.semantics or canonical_type(node.type)
        kind = node.kind
        for attr in PRECONDITION_ATTRS:
            if attr in node.attrs:
                raise UnsupportedError(
                    f"pre-condition '{attr}' depends on the blackboard", **where(node)
                )
        spec = node_semantics(ctype)
        # a kind that is an abstraction only for a {blackboard} port (the Loop family's
        # queue) is exact, and needs no option, when that port is a literal
        exact_here = (
            spec is not None
            and spec.abstract_port is not None
            and not spec.abstracted_for(node.attrs)
        )
        if (
            spec is not None
            and spec.requires is not None
            and node.semantics is None
            and not exact_here
        ):
            why = spec.rejection or (
                f"a {spec.library} node whose control flow reads data fsmbt "
                "does not model (a clock, the robot pose, a goal or a "
                "blackboard vector)"
            )
            raise UnsupportedError(
                f"{ctype}: {why}; enable it with {enabling_option(spec.requires)} (an "
                f"abstraction: {spec.abstraction})",
                **where(node),
            )
        reason = tables.rejected.get(ctype)
        if reason is not None and node.semantics is None and not exact_here:
            raise UnsupportedError(f"{ctype}: {reason}", **where(node))
        kids = list(node.children)
        params: tuple[Any, ...] = ()
        internal: int | None = None
        if node.semantics is not None and spec is not None:
            kind = spec.kind
            if spec.handler == "env_condition":
                kind = NodeKind.CONDITION
            elif spec.gate is not None and kind in (NodeKind.ACTION, NodeKind.CONDITION):
                if kids:
                    raise InputError("a leaf node has children", **where(node))
                return ctype, NodeKind.DECORATOR, params, internal, kids  # Sleep: gate only
        if kind is NodeKind.SUBTREE or ctype == SUBTREE_TYPE:
            kind = NodeKind.SUBTREE
            ctype = SUBTREE_TYPE
            target = node.attrs.get("ID")
            if not target or target not in self.doc.trees:
                raise InputError(
                    f"SubTree refers to unknown tree {target!r} (a tree of another file: name "
                    "that file or its folder with --trees PATH)",
                    **where(node),
                )
            if target in chain:
                raise UnsupportedError(
                    f"SubTree '{target}' includes itself (recursion)", **where(node)
                )
            if self.doc.trees[target].root is None:
                raise InputError(f"SubTree '{target}' is empty", **where(node))
            return ctype, kind, params, internal, []
        if kind in (NodeKind.ACTION, NodeKind.CONDITION):
            if kids:
                raise InputError("a leaf node has children", **where(node))
            if ctype in tables.internal_leaves:
                internal = tables.internal_leaves[ctype]
            elif spec is not None and spec.handler == "env_condition" and node.semantics:
                pass  # an abstraction: a condition the environment answers
            elif spec is not None:
                raise UnsupportedError(f"built-in leaf {ctype} is not supported", **where(node))
            return ctype, kind, params, internal, kids
        if kind is NodeKind.DECORATOR:
            if ctype not in tables.decorators:
                raise UnsupportedError(
                    f"decorator type '{node.type}' is not supported (custom or unknown semantics)",
                    **where(node),
                )
            if len(kids) != 1:
                raise InputError(
                    f"decorator {ctype} needs exactly one child, has {len(kids)}", **where(node)
                )
            params = self._family_params(node, ctype, exact_here)
            if not params and spec is not None and spec.gate is not None:
                params = (status_param(node, spec.closed_port, spec.gate.closed),)
            return ctype, kind, params, internal, kids
        if kind is NodeKind.CONTROL:
            if ctype not in tables.controls:
                raise UnsupportedError(
                    f"control type '{node.type}' is not supported (custom or unknown semantics)",
                    **where(node),
                )
            spec = node_semantics(ctype)
            if not kids and (spec is None or not spec.allows_children(0)):
                raise InputError(f"control node {ctype} has no children", **where(node))
            n = len(kids)
            counts = spec.child_counts if spec is not None else None
            if counts is not None and n not in counts:
                allowed = " or ".join(str(c) for c in counts)
                raise InputError(f"{ctype} needs {allowed} children, has {n}", **where(node))
            params = self._family_params(node, ctype, exact_here)
            return ctype, kind, params, internal, kids
        raise UnsupportedError(f"node kind {kind} is not supported", **where(node))

    @staticmethod
    def _family_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
        """The node's ports read and checked by its family (``FamilyRule.params``; ``()`` for
        a family without ports; docs/semantics.md "Node families")."""
        handler = runtime_tables().handlers[ctype]
        found = family_rule(handler)
        if found is None:
            raise UnsupportedError(
                f"{ctype}: its tick rule {handler!r} is not registered "
                "(fsmbt.semantics.families.registry.register_rule)",
                **where(node),
            )
        if found.params is None:
            return ()
        return found.params(node, ctype, exact)

    @property
    def root(self) -> CompiledNode:
        return self.nodes[0]


# -- run-time configuration ------------------------------------------------------------------
@dataclass(frozen=True)
class LeafRequest:
    """The interpreter is about to tick an environment leaf; ``prev`` is its status (IDLE =
    first tick / ``onStart``, RUNNING = ``onRunning``)."""

    node: CompiledNode
    prev: int


@dataclass(frozen=True)
class TickDone:
    """A ``tickOnce`` (or ``tickExactlyOnce``) call returned ``status``."""

    status: int


#: A node kind's tick rule bound to an interpreter (a family's ``FamilyRule.tick``).
TickRule = Callable[[Work, CompiledNode, Frame, "int | None", "HaltHook | None"], TickAction]

EMPTY_SNAPSHOT: Snapshot = ((), (), (), False)


def snapshot_statuses(snapshot: Snapshot) -> tuple[tuple[int, int], ...]:
    """The ``(node id, status)`` pairs of the nodes whose status is not IDLE, in id order.

    Why a function and not a named tuple: snapshots are made once per explored state, and a
    plain tuple is the cheapest hashable value; readers outside this module use this accessor
    instead of indexing the tuple.
    """
    return snapshot[0]


class BTInterpreter:
    """Executes a compiled tree step by step. Stateless itself: every call takes and returns a
    ``Snapshot``, so callers (the leaf machine, the LEBT runtime, a plain runner) share it."""

    def __init__(self, tree: BTDocument | CompiledTree, *, exactly_once: bool = False) -> None:
        self.tree = tree if isinstance(tree, CompiledTree) else CompiledTree(tree)
        self.nodes = self.tree.nodes
        self.exactly_once = exactly_once
        # Dispatch data from the node registry (docs/semantics.md "Node registry").
        tables = runtime_tables()
        # Each kind's tick rule is its family's function bound to this interpreter
        # (``fsmbt.semantics.families``): one dict read and one bound-method call per node tick.
        rules = family_rules()
        self._tick: dict[str, TickRule] = {
            kind: MethodType(rules[handler].tick, self)
            for kind, handler in tables.handlers.items()
            if handler in rules
        }
        self._default_mem = tables.default_memory
        self._halt_resets = tables.halt_resets_memory
        self.seq_flags = tables.sequence_flags
        self.reactive_fallbacks = tables.reactive_fallbacks
        self.result_maps = tables.result_maps

    # -- public driving API --------------------------------------------------------------
    def initial(self) -> Snapshot:
        return EMPTY_SNAPSHOT

    def begin_tick(self, snap: Snapshot) -> Snapshot:
        """Start one ``tickOnce``: push the root's frame (the snapshot must be between ticks)."""
        if snap[2]:
            raise ValueError("a tick is already in progress")
        return (snap[0], snap[1], ((0, 0),), snap[3])

    def advance(
        self, snap: Snapshot, outcome: int | None = None, halt_hook: HaltHook | None = None
    ) -> tuple[Snapshot, LeafRequest | TickDone]:
        """Run until the next environment leaf must be ticked or the ``tickOnce`` returns.

        ``outcome`` answers the ``LeafRequest`` the snapshot stopped at (``None`` right after
        ``begin_tick``). ``halt_hook`` is called for every RUNNING action that gets halted.
        """
        w = Work(snap)
        result: int | None = None
        seen_reticks: set[Snapshot] = set()
        if outcome is not None:
            nid = w.frames[-1][0]
            node = self.nodes[nid]
            if node.is_condition and outcome == RUNNING:
                raise BTRuntimeError("a condition returned RUNNING", element=node.label)
            if outcome not in (SUCCESS, FAILURE, RUNNING):
                raise ValueError(f"invalid leaf outcome {outcome!r}")
            w.frames.pop()
            result = self._returned(w, nid, outcome)
        elif not w.frames:
            raise ValueError("no tick in progress: call begin_tick first")
        while True:
            if not w.frames:
                assert result is not None
                # Tree::tickRoot: re-tick at once while RUNNING and a wake-up is pending.
                if result == RUNNING and w.wake and not self.exactly_once:
                    w.wake = False
                    key = w.snapshot()
                    if key in seen_reticks:
                        raise BTLivelock(
                            "the tree re-ticks its root forever without ticking a leaf",
                            element=self.nodes[0].label,
                        )
                    seen_reticks.add(key)
                    w.frames.append((0, 0))
                    result = None
                    continue
                if result in (SUCCESS, FAILURE):
                    w.st.pop(0, None)  # rootNode()->resetStatus()
                return w.snapshot(), TickDone(result)
            frame = w.frames[-1]
            node = self.nodes[frame[0]]
            if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
                if node.internal_status is not None:
                    w.frames.pop()
                    result = self._returned(w, node.id, node.internal_status)
                    continue
                prev = w.st.get(node.id, IDLE)
                if node.kind is NodeKind.ACTION and prev in (SUCCESS, FAILURE):
                    # StatefulActionNode::tick returns its old status without a callback
                    w.frames.pop()
                    result = self._returned(w, node.id, prev)
                    continue
                return w.snapshot(), LeafRequest(node, prev)
            action = self._tick[node.type](w, node, frame, result, halt_hook)
            if action[0] == "call":
                _, child, new_frame = action
                w.frames[-1] = new_frame
                w.frames.append((child, 0))
                result = None
            else:
                w.frames.pop()
                result = self._returned(w, node.id, action[1])

    def leaf_request(self, snap: Snapshot) -> LeafRequest | None:
        """The leaf a paused snapshot waits on, or ``None`` between ticks."""
        if not snap[2]:
            return None
        nid = snap[2][-1][0]
        return LeafRequest(self.nodes[nid], dict(snap[0]).get(nid, IDLE))

    def halt_tree(self, snap: Snapshot, halt_hook: HaltHook | None = None) -> Snapshot:
        """``Tree::haltTree``: halt the root (between ticks)."""
        w = Work(snap)
        self._halt(w, 0, halt_hook)
        return w.snapshot()

    # -- helpers shared by node types -------------------------------------------------------
    def _returned(self, w: Work, nid: int, status: int) -> int:
        """``executeTick``'s epilogue: store the status unless SKIPPED."""
        if status == IDLE:
            raise BTRuntimeError("a node returned IDLE", element=self.nodes[nid].label)
        if status != SKIPPED:
            w.st[nid] = status
        return status

    def mem(self, w: Work, node: CompiledNode) -> tuple[Any, ...]:
        return w.mem.get(node.id, self._default_mem[node.type])

    def set_mem(self, w: Work, node: CompiledNode, value: tuple[Any, ...]) -> None:
        if value == self._default_mem[node.type]:
            w.mem.pop(node.id, None)
        else:
            w.mem[node.id] = value

    def reset_child(self, w: Work, child: int, hook: HaltHook | None) -> None:
        """``ControlNode::haltChild`` / ``DecoratorNode::resetChild``."""
        if w.st.get(child, IDLE) == RUNNING:
            self._halt(w, child, hook)
        w.st.pop(child, None)

    def reset_children(
        self, w: Work, node: CompiledNode, hook: HaltHook | None, first: int = 0
    ) -> None:
        for child in node.children[first:]:
            self.reset_child(w, child, hook)

    def _halt(self, w: Work, nid: int, hook: HaltHook | None) -> None:
        """``haltNode()``: per-type ``halt()``, halting RUNNING descendants (explicit stack,
        pre-order, as the recursive C++ does)."""
        stack = [nid]
        while stack:
            x = self.nodes[stack.pop()]
            t = x.type
            if t in self._halt_resets:
                w.mem.pop(x.id, None)  # these halt() reset their memory
            # the others (SequenceWithMemory, RunOnce...) keep theirs: NodeSemantics.halt
            if (
                x.kind is NodeKind.ACTION
                and x.internal_status is None
                and hook is not None
                and w.st.get(x.id, IDLE) == RUNNING
            ):
                hook(x)
            for child in reversed(x.children):
                if w.st.get(child, IDLE) == RUNNING:
                    stack.append(child)
                else:
                    w.st.pop(child, None)
            w.st.pop(x.id, None)
            # running children reset their own status when popped (after their halt)


# -- a plain runner: the interpreter driven by an environment callback -------------------------
Environment = Callable[[BTNode, str], str]


@dataclass
class TickRecord:
    """One ``tick_once``: the leaves ticked (labels and paths, in order) and the root result."""

    leaves: list[tuple[str, str, str]]  # (label, path, outcome)
    result: str


class BTRunner:
    """Run a document tick by tick; each leaf asks ``env(node, path)`` for its outcome
    (``"success"``/``"failure"``/``"running"``). Mirrors behaviortreepy's ``Tree``."""

    def __init__(
        self,
        doc: BTDocument | CompiledTree,
        env: Environment,
        *,
        exactly_once: bool = False,
        halt_hook: HaltHook | None = None,
        max_leaf_ticks_per_tick: int = 1_000_000,
    ) -> None:
        self.interp = BTInterpreter(doc, exactly_once=exactly_once)
        self.env = env
        self.halt_hook = halt_hook
        self.snapshot: Snapshot = self.interp.initial()
        self.max_leaf_ticks = max_leaf_ticks_per_tick

    def tick_once(self) -> TickRecord:
        snap = self.interp.begin_tick(self.snapshot)
        snap, event = self.interp.advance(snap, None, self.halt_hook)
        leaves: list[tuple[str, str, str]] = []
        while isinstance(event, LeafRequest):
            if len(leaves) >= self.max_leaf_ticks:
                raise BTRuntimeError("a tick does not end (too many leaf ticks)")
            node = event.node
            outcome = self.env(node.source, node.path)
            status = OUTCOME_TO_STATUS.get(outcome)
            if status is None:
                raise ValueError(f"environment returned {outcome!r} for {node.label}")
            leaves.append((node.label, node.path, outcome))
            snap, event = self.interp.advance(snap, status, self.halt_hook)
        self.snapshot = snap
        return TickRecord(leaves, STATUS_NAMES[event.status])

    def halt(self) -> None:
        self.snapshot = self.interp.halt_tree(self.snapshot, self.halt_hook)


def snapshot_key(snap: Snapshot) -> Hashable:
    """Snapshots are already hashable; this names the intent at call sites."""
    return snap
