"""An interpreter of behavior trees that follows BehaviorTree.CPP v4 (4.8) tick rules exactly.

Why a resumable, explicit-stack design: the leaf-execution machine (``leaf_machine``) must pause
*inside* a tick, at the moment a leaf is ticked, and snapshot everything as a hashable value so
the checker can explore states. So every node's ``tick()`` is written as a small state machine:
a *frame* ``(node id, pc, locals...)`` on an explicit stack; ticking a child pushes a frame, a
child's return pops it and resumes the parent at ``pc``. No Python recursion is used anywhere
(trees may be 100 000 deep): compiling, ticking and halting all use explicit stacks.

Which node kinds exist, which tick rule (``_t_<handler>``) runs each, their memory at rest,
which ``halt()`` forgets it and which kinds are refused and why come from the node registry
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

import re
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from typing import Any, Final

from fsmbt.limits import Limits
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.nodes import canonical_type, enabling_option, node_semantics, runtime_tables
from fsmbt.semantics.status import LeafOutcome, NodeStatus

# -- statuses (fsmbt.semantics.status; docs/semantics.md "Statuses") ---------------------------
# Plain-int aliases of NodeStatus for the hot loops: snapshots hold them, and an int hashes
# three times faster than an IntEnum member (equal values, equal hashes).
IDLE: Final[int] = NodeStatus.IDLE.value
RUNNING: Final[int] = NodeStatus.RUNNING.value
SUCCESS: Final[int] = NodeStatus.SUCCESS.value
FAILURE: Final[int] = NodeStatus.FAILURE.value
SKIPPED: Final[int] = NodeStatus.SKIPPED.value
STATUS_NAMES: tuple[str, ...] = tuple(status.name for status in NodeStatus)
#: Leaf outcomes as the environment / the leaf machine's inputs name them (plain ``str``).
OUTCOME_SUCCESS: Final[str] = LeafOutcome.SUCCESS.value
OUTCOME_FAILURE: Final[str] = LeafOutcome.FAILURE.value
OUTCOME_RUNNING: Final[str] = LeafOutcome.RUNNING.value
OUTCOME_TO_STATUS: dict[str, int] = {o.value: o.status.value for o in LeafOutcome}
STATUS_TO_OUTCOME: dict[int, str] = {v: k for k, v in OUTCOME_TO_STATUS.items()}

#: Upper bound on nodes after SubTree expansion (a SubTree used twice per level doubles); the
#: default lives in ``fsmbt.limits`` (``max_nodes``).
MAX_COMPILED_NODES = Limits.max_nodes

# -- supported node types: the node registry (fsmbt.semantics.nodes) ----------------------------
# Which kinds are ticked and by which rule, their default memory, which are refused and why:
# ``runtime_tables()``, read when a tree is compiled and when an interpreter is built.
#: Pre-condition attributes change control flow from the blackboard: rejected.
PRECONDITION_ATTRS = ("_skipIf", "_failureIf", "_successIf", "_while")


class BTRuntimeError(InputError):
    """The tree does something BehaviorTree.CPP would throw on (e.g. a child returns IDLE)."""


class BTLivelock(BTRuntimeError):
    """``tickOnce`` would re-tick the root forever without ticking an environment leaf (e.g.
    ``Repeat num_cycles=-1`` over ``AlwaysSuccess``): the real engine hangs."""


@dataclass(frozen=True)
class CompiledNode:
    """One node after SubTree expansion; ``id`` is its pre-order index."""

    id: int
    type: str
    kind: NodeKind
    children: tuple[int, ...]
    label: str
    parent: int | None
    index: int  # position among the parent's children
    source: BTNode = field(compare=False, repr=False)
    params: tuple[Any, ...] = ()
    internal_status: int | None = None  # for internal built-in leaves
    tree: CompiledTree | None = field(default=None, compare=False, repr=False)

    @property
    def path(self) -> str:
        """Child indices from the root joined by ``/`` (``""`` for the root); a SubTree node
        has its tree's root as child 0. Computed on demand: O(depth)."""
        assert self.tree is not None
        return self.tree.path_of(self.id)

    @property
    def is_env_leaf(self) -> bool:
        """A leaf whose outcome the environment decides (observable in traces)."""
        return self.kind in (NodeKind.ACTION, NodeKind.CONDITION) and self.internal_status is None

    @property
    def is_condition(self) -> bool:
        return self.kind is NodeKind.CONDITION


def _where(node: BTNode) -> dict[str, Any]:
    return {"location": node.location, "element": f"<{node.type}> '{node.label}'"}


def _int_param(node: BTNode, port: str, default: int | None) -> int:
    raw = node.attrs.get(port)
    if raw is None:
        if default is None:
            raise InputError(f"missing port '{port}'", **_where(node))
        return default
    text = raw.strip()
    if text.startswith("{") and text.endswith("}"):
        raise UnsupportedError(f"port '{port}' reads the blackboard ({text})", **_where(node))
    try:
        return int(text)
    except ValueError:
        raise InputError(f"port '{port}' is not an integer: {raw!r}", **_where(node)) from None


def _bool_param(node: BTNode, port: str, default: bool) -> bool:
    raw = node.attrs.get(port)
    if raw is None:
        return default
    text = raw.strip().lower()
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    if text.startswith("{"):
        raise UnsupportedError(f"port '{port}' reads the blackboard ({raw})", **_where(node))
    raise InputError(f"port '{port}' is not a boolean: {raw!r}", **_where(node))


def _status_param(node: BTNode, port: str | None, default: str) -> int:
    """A port naming the status a node returns (``Precondition``'s ``else``...)."""
    raw = node.attrs.get(port) if port is not None else None
    text = (raw if raw is not None else default).strip()
    if text.startswith("{"):
        raise UnsupportedError(f"port '{port}' reads the blackboard ({text})", **_where(node))
    if text not in ("SUCCESS", "FAILURE", "RUNNING", "SKIPPED"):
        raise InputError(f"port '{port}' is not a status: {raw!r}", **_where(node))
    return int(NodeStatus[text])


#: How BehaviorTree.CPP 4.8 reads one element of a literal Loop queue (convertFromString<T>):
#: int: std::from_chars (a leading '-' and digits; the rest is ignored; int32 bounds), double:
#: std::stod (leading spaces, then a number, inf or nan), bool: the six spellings it accepts.
_INT_ELEMENT = re.compile(r"-?\d+")
_DOUBLE_ELEMENT = re.compile(r"\s*[+-]?(\d|\.\d|inf|nan)", re.IGNORECASE)
_BOOL_ELEMENTS = frozenset({"0", "1", "true", "TRUE", "True", "false", "FALSE", "False"})


def _queue_elements(text: str) -> list[str]:
    """BehaviorTree.CPP's ``splitString(queue, ';')``: "" has no element, a trailing ';'
    adds none, ";;" in the middle adds an empty one."""
    parts: list[str] = []
    pos = 0
    while pos < len(text):
        end = text.find(";", pos)
        end = len(text) if end < 0 else end
        parts.append(text[pos:end])
        pos = end + 1
    return parts


def _element_ok(ctype: str, element: str) -> bool:
    if ctype == "LoopInt":
        match = _INT_ELEMENT.match(element)
        return match is not None and -(2**31) <= int(match.group()) < 2**31
    if ctype == "LoopDouble":
        return _DOUBLE_ELEMENT.match(element) is not None
    if ctype == "LoopBool":
        return element in _BOOL_ELEMENTS
    return True  # LoopString: any text


def _loop_params(node: BTNode, ctype: str, literal: bool) -> tuple[int, int]:
    """``(if_empty status, queue length)`` of a Loop node; length ``-1``: a {blackboard}
    queue (an abstraction, its gate says whether an element is left)."""
    if_empty = _status_param(node, "if_empty", "SUCCESS")
    raw = node.attrs.get("queue")
    if raw is None:
        raise InputError(f"{ctype}: missing port 'queue'", **_where(node))
    if not literal:
        return (if_empty, -1)
    if canonical_type(node.type) != ctype:
        raise UnsupportedError(
            f"{node.type} (read as {ctype}) has a literal queue {raw!r}: how many elements it "
            "holds depends on the element type's own convertFromString; give the queue as a "
            f"{{blackboard}} entry (an abstraction) or use {ctype} itself",
            **_where(node),
        )
    elements = _queue_elements(raw)
    for element in elements:
        if not _element_ok(ctype, element):
            raise InputError(
                f"{ctype}: queue element {element!r} of {raw!r} is not a valid "
                f"{ctype[4:].lower()} (BehaviorTree.CPP refuses to build the tree)",
                **_where(node),
            )
    return (if_empty, len(elements))


#: The type of the synthetic gate leaves (never a registered kind, so always an env leaf).
GATE_TYPE = "_fsmbt_gate"


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


#: The person's picks of a ManualSelector besides its children (manual_node.cpp: S, F, R keys).
MANUAL_STATUSES: tuple[int, ...] = (SUCCESS, FAILURE, RUNNING)


def manual_choices(n_children: int, repeat_last: bool) -> int:
    """How many picks a ManualSelector offers: its children and the three statuses; with
    ``repeat_last_selection`` the children only (a status picked there makes BehaviorTree.CPP
    4.8.2 index past its children on the next tick; docs/semantics.md); without children the
    three statuses."""
    if n_children == 0:
        return len(MANUAL_STATUSES)
    return n_children if repeat_last else n_children + len(MANUAL_STATUSES)


def _choice_leaves(node: BTNode, n_children: int, repeat_last: bool) -> list[BTNode]:
    """The conditions that ask the person for a ManualSelector's pick, one per pick but the
    last (docs/semantics.md, "ManualSelector"): ``pick_<i>`` (child i, 1-based as the terminal
    UI numbers them), ``pick_SUCCESS``, ``pick_FAILURE``; the first that answers SUCCESS is the
    pick, none means the last pick (RUNNING, or the last child with repeat_last_selection)."""
    words = [f"pick_{i + 1}" for i in range(n_children)]
    if n_children == 0 or not repeat_last:
        words += [f"pick_{NodeStatus(s).name}" for s in MANUAL_STATUSES]
    return [
        BTNode(GATE_TYPE, NodeKind.CONDITION, f"{node.label}.{word}", location=node.location)
        for word in words[: manual_choices(n_children, repeat_last) - 1]
    ]


def parallel_threshold(value: int, count: int) -> int:
    """BehaviorTree.CPP's reading of a Parallel threshold: negative means "all but"."""
    return max(count + value + 1, 0) if value < 0 else value


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
        children_of: dict[int, list[int]] = {}
        raw: list[tuple[BTNode, str, int | None, int, tuple[Any, ...], int | None, NodeKind]] = []
        stack: list[tuple[BTNode, int | None, int, tuple[str, ...]]] = [
            (tree.root, None, 0, (tree.id,))
        ]
        while stack:
            node, parent, position, chain = stack.pop()
            nid = len(raw)
            if nid >= MAX_COMPILED_NODES:
                raise InputError(
                    f"the tree has more than {MAX_COMPILED_NODES} nodes once SubTrees are expanded",
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
            if ctype == "ManualSelector":  # the person's pick: conditions after the children
                kids = [*kids, *_choice_leaves(node, *params)]
            if ctype == "SubTree":
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
                    f"pre-condition '{attr}' depends on the blackboard", **_where(node)
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
                **_where(node),
            )
        reason = tables.rejected.get(ctype)
        if reason is not None and node.semantics is None and not exact_here:
            raise UnsupportedError(f"{ctype}: {reason}", **_where(node))
        kids = list(node.children)
        params: tuple[Any, ...] = ()
        internal: int | None = None
        if node.semantics is not None and spec is not None:
            kind = spec.kind
            if spec.handler == "env_condition":
                kind = NodeKind.CONDITION
            elif spec.gate is not None and kind in (NodeKind.ACTION, NodeKind.CONDITION):
                if kids:
                    raise InputError("a leaf node has children", **_where(node))
                return ctype, NodeKind.DECORATOR, params, internal, kids  # Sleep: gate only
        if kind is NodeKind.SUBTREE or ctype == "SubTree":
            kind = NodeKind.SUBTREE
            ctype = "SubTree"
            target = node.attrs.get("ID")
            if not target or target not in self.doc.trees:
                raise InputError(
                    f"SubTree refers to unknown tree {target!r} (a tree of another file: name "
                    "that file or its folder with --trees PATH)",
                    **_where(node),
                )
            if target in chain:
                raise UnsupportedError(
                    f"SubTree '{target}' includes itself (recursion)", **_where(node)
                )
            if self.doc.trees[target].root is None:
                raise InputError(f"SubTree '{target}' is empty", **_where(node))
            return ctype, kind, params, internal, []
        if kind in (NodeKind.ACTION, NodeKind.CONDITION):
            if kids:
                raise InputError("a leaf node has children", **_where(node))
            if ctype in tables.internal_leaves:
                internal = tables.internal_leaves[ctype]
            elif spec is not None and spec.handler == "env_condition" and node.semantics:
                pass  # an abstraction: a condition the environment answers
            elif spec is not None:
                raise UnsupportedError(f"built-in leaf {ctype} is not supported", **_where(node))
            return ctype, kind, params, internal, kids
        if kind is NodeKind.DECORATOR:
            if ctype not in tables.decorators:
                raise UnsupportedError(
                    f"decorator type '{node.type}' is not supported (custom or unknown semantics)",
                    **_where(node),
                )
            if len(kids) != 1:
                raise InputError(
                    f"decorator {ctype} needs exactly one child, has {len(kids)}", **_where(node)
                )
            if ctype == "Repeat":
                params = (_int_param(node, "num_cycles", None),)
            elif ctype == "RetryUntilSuccessful":
                params = (_int_param(node, "num_attempts", None),)
            elif ctype == "RunOnce":
                params = (_bool_param(node, "then_skip", True),)
            elif ctype == "RepeatUnlessFailureEachTick":
                params = (_int_param(node, "num_cycles", -1),)
            elif spec is not None and spec.handler == "loop_queue":
                params = _loop_params(node, ctype, exact_here)
            elif spec is not None and spec.gate is not None:
                params = (_status_param(node, spec.closed_port, spec.gate.closed),)
            return ctype, kind, params, internal, kids
        if kind is NodeKind.CONTROL:
            if ctype not in tables.controls:
                raise UnsupportedError(
                    f"control type '{node.type}' is not supported (custom or unknown semantics)",
                    **_where(node),
                )
            spec = node_semantics(ctype)
            if not kids and (spec is None or not spec.allows_children(0)):
                raise InputError(f"control node {ctype} has no children", **_where(node))
            n = len(kids)
            counts = spec.child_counts if spec is not None else None
            if counts is not None and n not in counts:
                allowed = " or ".join(str(c) for c in counts)
                raise InputError(f"{ctype} needs {allowed} children, has {n}", **_where(node))
            if ctype == "Parallel":
                succ = _int_param(node, "success_count", -1)
                fail = _int_param(node, "failure_count", 1)
                if n < parallel_threshold(succ, n) or n < parallel_threshold(fail, n):
                    raise InputError(
                        "Parallel threshold exceeds the number of children", **_where(node)
                    )
                params = (succ, fail)
            elif ctype == "RecoveryNode":
                params = (_int_param(node, "number_of_retries", 1),)
            elif ctype == "RoundRobin":
                params = (_bool_param(node, "wrap_around", False),)
            elif ctype == "ManualSelector":
                params = (n, _bool_param(node, "repeat_last_selection", False))
            elif ctype == "ParallelAll":
                fail = _int_param(node, "max_failures", 1)
                if n < parallel_threshold(fail, n):
                    raise InputError(
                        "ParallelAll max_failures exceeds the number of children", **_where(node)
                    )
                params = (parallel_threshold(fail, n),)
            return ctype, kind, params, internal, kids
        raise UnsupportedError(f"node kind {kind} is not supported", **_where(node))

    @property
    def root(self) -> CompiledNode:
        return self.nodes[0]


# -- run-time configuration ------------------------------------------------------------------
#: A snapshot: (statuses, memories, frames, wake-up pending). Hashable; equal snapshots behave
#: the same for every future input.
Snapshot = tuple[
    tuple[tuple[int, int], ...],
    tuple[tuple[int, tuple[Any, ...]], ...],
    tuple[tuple[Any, ...], ...],
    bool,
]


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


HaltHook = Callable[[CompiledNode], None]
#: A frame on the interpreter's stack: (node id, pc, locals...).
Frame = tuple[Any, ...]
#: What a tick rule does next: ("call", child id, new frame) or ("ret", status).
TickAction = tuple[Any, ...]
#: A node kind's tick rule (``BTInterpreter._t_<handler>``).
TickRule = Callable[["_Work", CompiledNode, Frame, "int | None", "HaltHook | None"], TickAction]


class _Work:
    """The mutable working copy of a snapshot."""

    __slots__ = ("st", "mem", "frames", "wake")

    def __init__(self, snap: Snapshot) -> None:
        self.st: dict[int, int] = dict(snap[0])
        self.mem: dict[int, tuple[Any, ...]] = dict(snap[1])
        self.frames: list[tuple[Any, ...]] = list(snap[2])
        self.wake: bool = snap[3]

    def snapshot(self) -> Snapshot:
        return (
            tuple(sorted(self.st.items())),
            tuple(sorted(self.mem.items())),
            tuple(self.frames),
            self.wake,
        )


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
        self._tick: dict[str, TickRule] = {
            kind: getattr(self, f"_t_{handler}") for kind, handler in tables.handlers.items()
        }
        self._default_mem = tables.default_memory
        self._halt_resets = tables.halt_resets_memory
        self._seq_flags = tables.sequence_flags
        self._reactive_fallbacks = tables.reactive_fallbacks
        self._result_maps = tables.result_maps

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
        w = _Work(snap)
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
        w = _Work(snap)
        self._halt(w, 0, halt_hook)
        return w.snapshot()

    # -- helpers shared by node types -------------------------------------------------------
    def _returned(self, w: _Work, nid: int, status: int) -> int:
        """``executeTick``'s epilogue: store the status unless SKIPPED."""
        if status == IDLE:
            raise BTRuntimeError("a node returned IDLE", element=self.nodes[nid].label)
        if status != SKIPPED:
            w.st[nid] = status
        return status

    def _mem(self, w: _Work, node: CompiledNode) -> tuple[Any, ...]:
        return w.mem.get(node.id, self._default_mem[node.type])

    def _set_mem(self, w: _Work, node: CompiledNode, value: tuple[Any, ...]) -> None:
        if value == self._default_mem[node.type]:
            w.mem.pop(node.id, None)
        else:
            w.mem[node.id] = value

    def _reset_child(self, w: _Work, child: int, hook: HaltHook | None) -> None:
        """``ControlNode::haltChild`` / ``DecoratorNode::resetChild``."""
        if w.st.get(child, IDLE) == RUNNING:
            self._halt(w, child, hook)
        w.st.pop(child, None)

    def _reset_children(
        self, w: _Work, node: CompiledNode, hook: HaltHook | None, first: int = 0
    ) -> None:
        for child in node.children[first:]:
            self._reset_child(w, child, hook)

    def _halt(self, w: _Work, nid: int, hook: HaltHook | None) -> None:
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

    # -- node types: each returns ("call", child, new_frame) or ("ret", status) ---------------
    def _t_sequence(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Sequence / Fallback / Async* / SequenceWithMemory (sequence_node.cpp & co)."""
        is_fallback, asynch, with_memory = self._seq_flags[node.type]
        stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
        idx, skipped = self._mem(w, node)
        n = len(node.children)
        if frame[1] == 0:
            if w.st.get(node.id, IDLE) == IDLE:  # !isStatusActive(status())
                skipped = 0
            w.st[node.id] = RUNNING
        else:
            prev = frame[2]
            if result == RUNNING:
                self._set_mem(w, node, (idx, skipped))
                return ("ret", RUNNING)
            if result == stop:
                if with_memory:
                    self._reset_children(w, node, hook, first=idx)
                else:
                    self._reset_children(w, node, hook)
                    idx = 0
                self._set_mem(w, node, (idx, skipped))
                return ("ret", stop)
            if result == go_on:
                idx += 1
                if (asynch or with_memory) and prev == IDLE and idx < n:
                    w.wake = True
                    self._set_mem(w, node, (idx, skipped))
                    return ("ret", RUNNING)
            elif result == SKIPPED:
                idx += 1
                skipped += 1
            else:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
        if idx < n:
            child = node.children[idx]
            self._set_mem(w, node, (idx, skipped))
            return ("call", child, (node.id, 1, w.st.get(child, IDLE)))
        all_skipped = skipped == n
        self._reset_children(w, node, hook)
        self._set_mem(w, node, (0, 0))
        return ("ret", SKIPPED if all_skipped else go_on)

    def _t_reactive(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """ReactiveSequence / ReactiveFallback (reactive_sequence.cpp, reactive_fallback.cpp)."""
        is_fallback = node.type in self._reactive_fallbacks
        stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            index, all_skipped = 0, True
        else:
            index, all_skipped = frame[2], frame[3]
            all_skipped = all_skipped and result == SKIPPED
            if result == RUNNING:
                for i, child in enumerate(node.children):
                    if i != index:
                        self._reset_child(w, child, hook)
                return ("ret", RUNNING)
            if result == stop:
                self._reset_children(w, node, hook)
                return ("ret", stop)
            if result == SKIPPED:
                self._reset_child(w, node.children[index], hook)
            elif result != go_on:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
            index += 1
        if index < len(node.children):
            return ("call", node.children[index], (node.id, 1, index, all_skipped))
        self._reset_children(w, node, hook)
        return ("ret", SKIPPED if all_skipped else go_on)

    def _t_parallel(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Parallel with success_count / failure_count (parallel_node.cpp)."""
        n = len(node.children)
        succ_param, fail_param = node.params
        need_s, need_f = parallel_threshold(succ_param, n), parallel_threshold(fail_param, n)
        completed, sc, fc = self._mem(w, node)
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            i, skipped = 0, 0
            checked = False
        else:
            i, skipped = frame[2], frame[3]
            if result == SKIPPED:
                skipped += 1
            elif result == SUCCESS:
                completed, sc = completed | {i}, sc + 1
            elif result == FAILURE:
                completed, fc = completed | {i}, fc + 1
            elif result != RUNNING:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
            checked = True  # the child at i was ticked: run the checks for i below
        while i < n:
            if not checked and i not in completed:
                self._set_mem(w, node, (completed, sc, fc))
                return ("call", node.children[i], (node.id, 1, i, skipped))
            checked = False
            if sc >= need_s or (succ_param < 0 and sc + skipped >= need_s):
                self._set_mem(w, node, (frozenset(), 0, 0))
                self._reset_children(w, node, hook)
                return ("ret", SUCCESS)
            if (n - fc) < need_s or fc == need_f:
                self._set_mem(w, node, (frozenset(), 0, 0))
                self._reset_children(w, node, hook)
                return ("ret", FAILURE)
            i += 1
        self._set_mem(w, node, (completed, sc, fc))
        return ("ret", SKIPPED if skipped == n else RUNNING)

    def _t_parallel_all(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """ParallelAll with max_failures (parallel_all_node.cpp)."""
        n = len(node.children)
        (need_f,) = node.params
        completed, fc = self._mem(w, node)
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            i, skipped = 0, 0
        else:
            i, skipped = frame[2], frame[3]
            if result == SUCCESS:
                completed = completed | {i}
            elif result == FAILURE:
                completed, fc = completed | {i}, fc + 1
            elif result == SKIPPED:
                skipped += 1
            elif result != RUNNING:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
            i += 1
        while i < n and i in completed:
            i += 1
        if i < n:
            self._set_mem(w, node, (completed, fc))
            return ("call", node.children[i], (node.id, 1, i, skipped))
        if skipped == n:
            self._set_mem(w, node, (completed, fc))
            return ("ret", SKIPPED)
        if skipped + len(completed) >= n:
            self._reset_children(w, node, hook)  # haltChildren()
            status = FAILURE if fc >= need_f else SUCCESS
            self._set_mem(w, node, (frozenset(), 0))
            return ("ret", status)
        self._set_mem(w, node, (completed, fc))
        return ("ret", RUNNING)

    def _t_if_then_else(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """IfThenElse (if_then_else_node.cpp): the condition is not re-evaluated while a branch
        runs."""
        (child_idx,) = self._mem(w, node)
        n = len(node.children)
        pc = frame[1]
        if pc == 0:
            w.st[node.id] = RUNNING
            if child_idx == 0:
                return ("call", node.children[0], (node.id, 1))
        elif pc == 1:
            if result == RUNNING:
                return ("ret", RUNNING)
            if result == SUCCESS:
                child_idx = 1
            elif result == FAILURE:
                if n == 3:
                    child_idx = 2
                else:
                    return ("ret", FAILURE)
            else:
                raise BTRuntimeError(
                    "IfThenElse: the condition was skipped (BehaviorTree.CPP throws a logic_error)",
                    element=node.label,
                )
            self._set_mem(w, node, (child_idx,))
        else:  # pc == 2: the branch returned
            if result == RUNNING:
                return ("ret", RUNNING)
            self._reset_children(w, node, hook)
            self._set_mem(w, node, (0,))
            return ("ret", result)
        return ("call", node.children[child_idx], (node.id, 2))

    def _t_while_do_else(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """WhileDoElse (while_do_else_node.cpp): the condition is re-evaluated every tick."""
        n = len(node.children)
        pc = frame[1]
        if pc == 0:
            w.st[node.id] = RUNNING
            return ("call", node.children[0], (node.id, 1))
        if pc == 1:
            if result == RUNNING:
                return ("ret", RUNNING)
            if result == SUCCESS:
                if n == 3:
                    self._reset_child(w, node.children[2], hook)
                return ("call", node.children[1], (node.id, 2))
            if result == FAILURE:
                if n == 3:
                    self._reset_child(w, node.children[1], hook)
                    return ("call", node.children[2], (node.id, 2))
                status = FAILURE
            else:
                raise BTRuntimeError(
                    "WhileDoElse: the condition was skipped (the node would return IDLE)",
                    element=node.label,
                )
        else:
            assert result is not None  # pc == 2: the branch returned
            status = result
        if status == RUNNING:
            return ("ret", RUNNING)
        self._reset_children(w, node, hook)
        return ("ret", status)

    def _t_simple_decorator(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Inverter, ForceSuccess, ForceFailure, KeepRunningUntilFailure."""
        child = node.children[0]
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            return ("call", child, (node.id, 1))
        mapped = self._result_maps.get(node.type)
        if mapped is None:  # KeepRunningUntilFailure
            if result == FAILURE:
                self._reset_child(w, child, hook)
                return ("ret", FAILURE)
            if result == SUCCESS:
                self._reset_child(w, child, hook)
                return ("ret", RUNNING)
            return ("ret", RUNNING)  # RUNNING, or `return status()` (RUNNING) when skipped
        if result in (RUNNING, SKIPPED):
            return ("ret", result)
        self._reset_child(w, child, hook)
        return ("ret", mapped[0] if result == SUCCESS else mapped[1])

    def _t_repeat(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Repeat num_cycles (repeat_node.cpp); -1 repeats forever."""
        return self._loop_decorator(w, node, frame, result, hook, again_on=SUCCESS)

    def _t_retry(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """RetryUntilSuccessful num_attempts (retry_node.cpp); -1 retries forever."""
        return self._loop_decorator(w, node, frame, result, hook, again_on=FAILURE)

    def _loop_decorator(
        self,
        w: _Work,
        node: CompiledNode,
        frame: Frame,
        result: int | None,
        hook: HaltHook | None,
        *,
        again_on: int,
    ) -> TickAction:
        """Repeat and RetryUntilSuccessful are mirror images in BehaviorTree.CPP: the child is
        ticked again while it returns ``again_on``, at most ``node.params[0]`` times (-1: no
        bound); the other result ends the loop at once. A loop that goes on in the same tick
        after a synchronous child asks for a wake-up and returns RUNNING, as v4 does."""
        (limit,) = node.params
        (count,) = self._mem(w, node)
        child = node.children[0]
        stop_on = FAILURE if again_on == SUCCESS else SUCCESS
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            do_loop = count < limit or limit == -1
        else:
            prev = frame[2]
            if result == again_on:
                # with -1 the count is never read: keep it 0 so states stay finite
                count = count + 1 if limit != -1 else 0
                do_loop = count < limit or limit == -1
                self._reset_child(w, child, hook)
                if prev == IDLE and do_loop:
                    w.wake = True
                    self._set_mem(w, node, (count,))
                    return ("ret", RUNNING)
            elif result == stop_on:
                self._set_mem(w, node, (0,))
                self._reset_child(w, child, hook)
                return ("ret", stop_on)
            elif result == RUNNING:
                return ("ret", RUNNING)
            elif result == SKIPPED:
                self._reset_child(w, child, hook)
                return ("ret", SKIPPED)
            else:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
        if do_loop:
            self._set_mem(w, node, (count,))
            return ("call", child, (node.id, 1, w.st.get(child, IDLE)))
        self._set_mem(w, node, (0,))
        return ("ret", again_on)

    def _t_run_once(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """RunOnce then_skip (run_once_node.h): memory survives halts."""
        (then_skip,) = node.params
        ticked, returned = self._mem(w, node)
        if frame[1] == 0:
            if ticked:
                return ("ret", SKIPPED if then_skip else returned)
            w.st[node.id] = RUNNING
            return ("call", node.children[0], (node.id, 1))
        if result in (SUCCESS, FAILURE):
            self._set_mem(w, node, (True, result))
            self._reset_child(w, node.children[0], hook)
        return ("ret", result)

    def _t_subtree(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """SubTree (subtree_node.cpp): a transparent decorator; port remapping is irrelevant."""
        if frame[1] == 0:
            if w.st.get(node.id, IDLE) == IDLE:
                w.st[node.id] = RUNNING
            return ("call", node.children[0], (node.id, 1))
        if result in (SUCCESS, FAILURE):
            self._reset_child(w, node.children[0], hook)
        return ("ret", result)

    # -- project kinds and abstractions (docs/semantics.md §10) ---------------------------------
    def _t_manual_selector(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """ManualSelector (manual_node.cpp): the person's pick is asked through the choice
        conditions after the children (``_choice_leaves``), the first SUCCESS wins; a picked
        child's status is returned; nothing else is halted or reset."""
        n, repeat_last = node.params
        choices = node.children[n:]
        pc = frame[1]
        if pc == 0:
            (previous,) = self._mem(w, node)
            if n and repeat_last and previous >= 0:
                return ("call", node.children[previous], (node.id, 2))
            if n:
                w.st[node.id] = RUNNING  # setStatus(RUNNING) before selectChild()
            if not choices:  # one child under repeat_last_selection: the only pick
                pick = 0
            else:
                return ("call", choices[0], (node.id, 1, 0))
        elif pc == 1:
            asked = frame[2]
            w.st.pop(choices[asked], None)  # a choice keeps no status: asked afresh each time
            if result == SUCCESS:
                pick = asked
            elif asked + 1 < len(choices):
                return ("call", choices[asked + 1], (node.id, 1, asked + 1))
            else:
                pick = len(choices)  # none said yes: the last pick
        else:  # pc == 2: the picked child returned
            assert result is not None
            return ("ret", result)
        if pick < n:
            if repeat_last:
                self._set_mem(w, node, (pick,))
            return ("call", node.children[pick], (node.id, 2))
        return ("ret", MANUAL_STATUSES[pick - n])

    def _t_pipeline(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Nav2 PipelineSequence (pipeline_sequence.cpp)."""
        (last,) = self._mem(w, node)
        n = len(node.children)
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            i, skipped = 0, 0
        else:
            i, skipped = frame[2], frame[3]
            if result == FAILURE:
                self._reset_children(w, node, hook)
                self._set_mem(w, node, (0,))
                return ("ret", FAILURE)
            if result == SKIPPED:
                skipped += 1
            elif result == RUNNING:
                if i >= last:
                    self._set_mem(w, node, (i,))
                    return ("ret", RUNNING)
            elif result != SUCCESS:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
            i += 1
        if i < n:
            return ("call", node.children[i], (node.id, 1, i, skipped))
        self._reset_children(w, node, hook)
        self._set_mem(w, node, (0,))
        return ("ret", SKIPPED if skipped == n else SUCCESS)

    def _t_recovery(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Nav2 RecoveryNode (recovery_node.cpp): main child 0, recovery child 1."""
        (retries,) = node.params
        idx, tries = self._mem(w, node)
        main, recovery = node.children
        if frame[1] == 0:
            w.st[node.id] = RUNNING
        elif idx == 0:
            if result == RUNNING:
                return ("ret", RUNNING)
            if result in (SUCCESS, SKIPPED):
                self._reset_children(w, node, hook)  # haltChild(1), then halt()
                self._set_mem(w, node, (0, 0))
                return ("ret", result)
            if result != FAILURE:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
            if tries >= retries:
                self._reset_children(w, node, hook)
                self._set_mem(w, node, (0, 0))
                return ("ret", FAILURE)
            self._reset_child(w, main, hook)
            idx = 1
        else:
            if result == RUNNING:
                return ("ret", RUNNING)
            if result == SKIPPED:  # no recovery possible; not a retry
                self._reset_child(w, recovery, hook)
                self._set_mem(w, node, (0, tries))
                return ("ret", FAILURE)
            if result == FAILURE:
                self._reset_children(w, node, hook)
                self._set_mem(w, node, (0, 0))
                return ("ret", FAILURE)
            if result != SUCCESS:
                raise BTRuntimeError("a child returned IDLE", element=node.label)
            self._reset_child(w, recovery, hook)
            idx, tries = 0, tries + 1
        if tries <= retries:
            self._set_mem(w, node, (idx, tries))
            return ("call", node.children[idx], (node.id, 1))
        self._reset_children(w, node, hook)
        self._set_mem(w, node, (0, 0))
        return ("ret", FAILURE)

    def _t_round_robin(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Nav2 RoundRobin (round_robin_node.cpp), with its ``wrap_around`` port."""
        (wrap,) = node.params
        n = len(node.children)
        idx, failed = self._mem(w, node)
        ended = False
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            skipped = 0
        else:
            skipped = frame[2]
            if result not in (SUCCESS, FAILURE, RUNNING, SKIPPED):
                raise BTRuntimeError("a child returned IDLE", element=node.label)
            if result != RUNNING:
                idx += 1
                if idx == n:
                    if wrap:
                        idx = 0
                    else:  # the end of the list: counted, then the loop stops
                        skipped += result == SKIPPED
                        failed += result == FAILURE
                        ended = True
            if not ended:
                if result == SUCCESS:
                    self._reset_children(w, node, hook)
                    self._set_mem(w, node, (idx, 0))
                    return ("ret", SUCCESS)
                if result == RUNNING:
                    self._set_mem(w, node, (idx, failed))
                    return ("ret", RUNNING)
                if result == FAILURE:
                    failed += 1
                else:
                    skipped += 1
        if not ended and failed + skipped < n:
            self._set_mem(w, node, (idx, failed))
            return ("call", node.children[idx], (node.id, 1, skipped))
        self._reset_children(w, node, hook)
        self._set_mem(w, node, (0, 0))
        return ("ret", SKIPPED if skipped == n else FAILURE)

    def _t_repeat_each_tick(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """MoveIt Pro RepeatUnlessFailureEachTick: one cycle per tick, no wake-up."""
        (limit,) = node.params
        (count,) = self._mem(w, node)
        child = node.children[0]
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            return ("call", child, (node.id, 1))
        if result == RUNNING:
            return ("ret", RUNNING)
        self._reset_child(w, child, hook)
        if result == SUCCESS:
            if limit != -1:  # with -1 the count is never read: keep it 0 (finite states)
                count += 1
                if count >= limit:
                    self._set_mem(w, node, (0,))
                    return ("ret", SUCCESS)
            self._set_mem(w, node, (count,))
            return ("ret", RUNNING)
        if result == FAILURE:
            self._set_mem(w, node, (0,))
            return ("ret", FAILURE)
        return ("ret", SKIPPED)

    def _t_single_trigger(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Nav2 SingleTrigger: the child runs to completion once per activation."""
        child = node.children[0]
        if frame[1] == 0:
            (triggered,) = self._mem(w, node)
            if w.st.get(node.id, IDLE) == IDLE:
                triggered = False
                self._set_mem(w, node, (False,))
            w.st[node.id] = RUNNING
            if triggered:
                return ("ret", FAILURE)
            return ("call", child, (node.id, 1))
        if result in (SUCCESS, FAILURE):
            self._set_mem(w, node, (True,))
        return ("ret", result)

    def _t_pass_through(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """A transparent wrapper (Groot 1 ``Root``): the child's status, child reset when done."""
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            return ("call", node.children[0], (node.id, 1))
        if result in (SUCCESS, FAILURE):
            self._reset_child(w, node.children[0], hook)
        return ("ret", result)

    def _t_pass_through_keep(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Nav2 GoalUpdater: ``return child_node_->executeTick()`` (the child is not reset)."""
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            return ("call", node.children[0], (node.id, 1))
        return ("ret", result)

    def _gate_of(self, node: CompiledNode) -> Any:
        spec = node_semantics(node.type)
        assert spec is not None and spec.gate is not None
        return spec.gate

    def _t_gated(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """An abstraction whose gate (the last child, a condition the environment answers)
        decides whether the child is ticked: Nav2's controllers, Delay, Precondition,
        BlackboardCheck* (docs/semantics.md §10)."""
        gate_rule = self._gate_of(node)
        child, gate = node.children[0], node.children[-1]
        (closed,) = node.params
        pc = frame[1]
        if pc == 0:
            prev = w.st.get(node.id, IDLE)
            w.st[node.id] = RUNNING
            child_status = w.st.get(child, IDLE)
            if (gate_rule.free_when_idle and prev == IDLE) or (
                gate_rule.free_when_running and child_status == RUNNING
            ):
                return ("call", child, (node.id, 2))
            return ("call", gate, (node.id, 1))
        if pc == 1:
            w.st.pop(gate, None)  # a gate keeps no status: it is asked afresh each time
            if result == SUCCESS:
                return ("call", child, (node.id, 2))
            if gate_rule.halt_on_closed and w.st.get(child, IDLE) == RUNNING:
                self._reset_child(w, child, hook)
            return ("ret", closed)
        if gate_rule.reset_on_done and result in (SUCCESS, FAILURE):
            self._reset_child(w, child, hook)
        return ("ret", result)

    def _t_timeout(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Timeout as an abstraction: the timer (the gate) may fire on any tick after the
        first; fired, the child is halted and the node returns FAILURE."""
        child, gate = node.children[0], node.children[-1]
        pc = frame[1]
        if pc == 0:
            started = w.st.get(node.id, IDLE) == RUNNING
            w.st[node.id] = RUNNING
            if not started:
                return ("call", child, (node.id, 2))
            return ("call", gate, (node.id, 1))
        if pc == 1:
            w.st.pop(gate, None)
            if result == SUCCESS:  # fired
                self._reset_child(w, child, hook)
                return ("ret", FAILURE)
            return ("call", child, (node.id, 2))
        if result in (SUCCESS, FAILURE):
            self._reset_child(w, child, hook)
        return ("ret", result)

    def _t_sleep(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """Sleep as an abstraction: RUNNING until the timer (the gate) says the time is up."""
        gate = node.children[-1]
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            return ("call", gate, (node.id, 1))
        w.st.pop(gate, None)
        return ("ret", SUCCESS if result == SUCCESS else RUNNING)

    def _t_for_each(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """MoveIt Pro ForEach / ForEachUntilSuccess as an abstraction: the gate says whether
        the vector has another element; one element per tick."""
        (no_more,) = node.params
        stop = FAILURE if no_more == SUCCESS else SUCCESS
        child, gate = node.children[0], node.children[-1]
        pc = frame[1]
        if pc == 0:
            w.st[node.id] = RUNNING
            if w.st.get(child, IDLE) == RUNNING:
                return ("call", child, (node.id, 2))
            return ("call", gate, (node.id, 1))
        if pc == 1:
            w.st.pop(gate, None)
            if result == SUCCESS:
                return ("call", child, (node.id, 2))
            return ("ret", no_more)
        if result == RUNNING:
            return ("ret", RUNNING)
        self._reset_child(w, child, hook)
        return ("ret", stop if result == stop else RUNNING)

    def _t_loop_queue(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """LoopInt / LoopBool / LoopDouble / LoopString (loop_node.h, docs/semantics.md).

        ``params = (if_empty, length)``. A literal queue of ``length`` elements is reloaded when
        the node is ticked while IDLE; its memory is how many elements are left and whether the
        child returned RUNNING on its last tick (``child_running_``). ``length = -1``
        (a {blackboard} queue, an abstraction): the gate, the last child, says whether the
        queue still has an element. An element is popped only while the child is not RUNNING;
        no element left returns ``if_empty`` without setting RUNNING (a SKIPPED result leaves
        the stored status as it was, as ``executeTick`` does)."""
        if_empty, length = node.params
        child = node.children[0]
        pc = frame[1]
        left, child_running = self._mem(w, node)
        if pc == 0:
            if w.st.get(node.id, IDLE) == IDLE:
                left, child_running = length, False  # the static queue is copied afresh
            if length < 0:
                if child_running:
                    w.st[node.id] = RUNNING
                    return ("call", child, (node.id, 2))
                return ("call", node.children[-1], (node.id, 1))
            if not child_running:
                if left == 0:
                    self._set_mem(w, node, (0, False))
                    return ("ret", if_empty)
                left -= 1  # pop_front, written to the 'value' port
            self._set_mem(w, node, (left, child_running))
            w.st[node.id] = RUNNING
            return ("call", child, (node.id, 2))
        if pc == 1:  # the gate answered: does the blackboard queue have an element?
            w.st.pop(node.children[-1], None)
            if result == SUCCESS:
                w.st[node.id] = RUNNING
                return ("call", child, (node.id, 2))
            self._set_mem(w, node, (0, False))
            return ("ret", if_empty)
        # child_running_ is the node's own flag, not the child's stored status: a child that
        # returned SKIPPED keeps its old (possibly RUNNING) status but clears the flag
        self._set_mem(w, node, (max(left, 0), result == RUNNING))
        if result in (SUCCESS, FAILURE):
            self._reset_child(w, child, hook)
        return ("ret", FAILURE if result == FAILURE else RUNNING)

    def _t_real_parallel(
        self, w: _Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        """julienbayle/stardust RealParallel (docs/semantics.md, "Project nodes"): every child
        is ticked on every tick, in order, and never reset by the node (only its halt resets
        them); any RUNNING child: RUNNING, else any FAILURE: FAILURE, else SUCCESS. A SKIPPED
        child makes the project's node throw."""
        if frame[1] == 0:
            w.st[node.id] = RUNNING
            return ("call", node.children[0], (node.id, 1, 0, False, False))
        i, running, failed = frame[2], frame[3], frame[4]
        if result == RUNNING:
            running = True
        elif result == FAILURE:
            failed = True
        elif result != SUCCESS:
            raise BTRuntimeError(
                "RealParallel: a child returned SKIPPED (the node throws on any status but "
                "SUCCESS, FAILURE and RUNNING)",
                element=node.label,
            )
        i += 1
        if i < len(node.children):
            return ("call", node.children[i], (node.id, 1, i, running, failed))
        return ("ret", RUNNING if running else FAILURE if failed else SUCCESS)


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
