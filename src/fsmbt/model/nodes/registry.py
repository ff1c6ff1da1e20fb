"""The registry of BT node semantics: one ``NodeSemantics`` entry per built-in node kind.

Every module that needs to know what a node kind is or does - the XML reader, ``validate``, the
interpreter and its fast paths, depth compression, the converters and baselines, the NuSMV
encoder, the LLM structural check - reads it from here (through ``fsmbt.model.bt_nodes`` or
``fsmbt.semantics.nodes``). The entries themselves are declared once, by family, the way
BehaviorTree.CPP lays out ``src/controls`` and ``src/decorators``: ``controls.py``,
``decorators.py``, ``leaves.py``. docs/semantics.md ("Node registry") lists them.

Why the table lives in ``fsmbt.model`` and not in ``fsmbt.semantics``: the layers import
downward only (model <- formats, model <- semantics <- convert <- verify), and the model layer
itself (``bt.py``'s ``is_builtin``, ``validate``) and the readers (``formats/btcpp.py``: which
tag is a control, which a decorator) need the syntactic half of each entry. An entry is pure
data - names, counts, flags, reasons, the name of the interpreter's tick rule - so it sits at
the bottom layer; ``fsmbt.semantics.nodes`` is the semantic face (statuses as ``NodeStatus``,
the derived node sets the interpreter dispatches on) and re-exports everything here.

Adding a node kind: one ``NodeSemantics`` in the family module (or ``register()`` at run time
for a tool's own kinds), plus tests. The derived sets at the bottom of this module are computed
from the built-in entries once, at import; code that must see kinds registered later calls the
lookup functions (the interpreter and ``validate`` do).

Costs: lookups are dict reads, O(1); the derived sets are built once, O(K) for K kinds.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from enum import Enum

from fsmbt.model.kinds import NodeKind


class Family(str, Enum):
    """What a node does, the grouping of docs/semantics.md and BehaviorTree.CPP's sources."""

    SEQUENCE = "sequence"  # ticks children in order, stops at the first failure
    FALLBACK = "fallback"  # ticks children in order, stops at the first success
    PARALLEL = "parallel"  # ticks every child each tick, thresholds decide
    CONDITIONAL = "conditional"  # IfThenElse / WhileDoElse: child 0 picks a branch
    SWITCH = "switch"  # a blackboard value picks the child
    MANUAL = "manual"  # a person picks the child
    STATUS_MAP = "status_map"  # one child, its result rewritten (Inverter, Force*, ...)
    LOOP = "loop"  # one child, ticked again while a result repeats (Repeat, Retry)
    ONCE = "once"  # RunOnce
    GATE = "gate"  # blackboard pre-conditions / entry updates
    BLACKBOARD_LOOP = "blackboard_loop"  # LoopInt & co: a blackboard queue
    TIMER = "timer"  # Delay, Timeout, Sleep
    INTERNAL_LEAF = "internal_leaf"  # AlwaysSuccess & co: a fixed result, no environment
    BLACKBOARD_LEAF = "blackboard_leaf"  # ScriptCondition, WasEntryUpdated
    SUBTREE = "subtree"  # a reference to another tree
    PIPELINE = "pipeline"  # Nav2 PipelineSequence: re-ticks earlier children every tick
    RECOVERY = "recovery"  # Nav2 RecoveryNode: a main child and a recovery child, retried
    ROUND_ROBIN = "round_robin"  # Nav2 RoundRobin: resumes at the child after the last one
    CONTROLLER = "controller"  # Nav2 rate/distance/speed/goal controllers: a gated child
    ITERATOR = "iterator"  # MoveIt Pro ForEach*: one child per element of a blackboard vector
    WRAPPER = "wrapper"  # a transparent one-child wrapper (Groot 1 Root, GoalUpdater)


@dataclass(frozen=True)
class Gate:
    """An abstraction's environment input: a condition the environment answers on each tick
    where the node consults it (docs/semantics.md, "Abstractions").

    The gate is ticked as an extra condition child labelled ``<node label>.<word>``; its
    SUCCESS opens the gate (the child is ticked, the timer fired, the vector has another
    element...), its FAILURE closes it.

    Attributes:
        word: the gate's label suffix (``gate``, ``timer``, ``more``, ``match``, ``if``).
        free_when_idle: the first tick after the node was IDLE ticks the child without asking.
        free_when_running: a RUNNING child is ticked without asking.
        closed: the status the node returns when the gate is closed (a ``NodeStatus`` name).
        reset_on_done: the child is reset when it completes (else it keeps its status).
        halt_on_closed: a closed gate halts a RUNNING child (else the child stays RUNNING).
    """

    word: str
    free_when_idle: bool = False
    free_when_running: bool = True
    closed: str = "RUNNING"
    reset_on_done: bool = True
    halt_on_closed: bool = True


@dataclass(frozen=True)
class NodeSemantics:
    """One built-in node kind: its shape, its run-time rules, and how each engine treats it.

    Attributes:
        name: the BehaviorTree.CPP v4 type name (the XML tag).
        kind: control, decorator, action, condition or subtree.
        family: see ``Family``.
        children: exact child count in the file; ``None`` = ``min_children`` or more.
        min_children: the fewest children when ``children`` is ``None`` (1; ManualSelector 0).
        child_counts: the allowed counts when only some are (``IfThenElse``: ``(2, 3)``).
        tick: what one tick does (a summary of the BehaviorTree.CPP source; docs/semantics.md
            has the full rule).
        halt: what ``halt()`` does and which memory it keeps.
        memory: the names of the memory the node keeps across ticks, in the interpreter's order.
        default_memory: that memory at rest (``None``: no memory slot); the interpreter stores
            only values that differ from it, so equal states hash equal.
        halt_resets_memory: ``halt()`` forgets ``memory`` (else it survives a halt).
        reactive: re-ticks earlier children on every tick (``Reactive*``).
        with_memory: skips children that already succeeded (failed) until the node finishes.
        asynchronous: returns RUNNING after each child instead of going on in the same tick.
        wakes_up: emits the tree's wake-up signal that ``tickOnce`` answers by re-ticking.
        mergeable: depth compression merges a child of the same kind into this node
            (``Sequence(a, Sequence(b, c)) = Sequence(a, b, c)``).
        handler: the interpreter's tick rule for this kind; ``None``: the interpreter refuses it.
        internal_result: for internal leaves, the ``NodeStatus`` name they always return.
        result_map: for status-mapping decorators, what the child's ``SUCCESS`` and ``FAILURE``
            become (``None``: not a pure status map).
        time_based: needs a clock (Delay, Timeout, Sleep).
        blackboard_based: its control flow reads the blackboard.
        rejection: why the interpreter refuses it (``None``: supported, or refused as an
            unknown kind).
        nusmv: the NuSMV encoding rule (``None``: not encoded; ``nusmv_refusal`` says why).
        nusmv_refusal: why the NuSMV encoding refuses it.
        ports: the ports the rules read.
        aliases: older (v3) or misspelt names read as this kind.
        source: the BehaviorTree.CPP source the rules follow.
        library: who defines the kind (BehaviorTree.CPP, Nav2, MoveIt Pro, Groot).
        requires: the option that enables the kind (``nav2`` / ``moveit_pro``: ``--nodes``;
            ``time`` / ``blackboard``: ``--abstract``); ``None``: always available.
        abstraction: the sentence the verdict names when the kind is modelled as an
            abstraction (``None``: modelled exactly).
        gate: the abstraction's environment input (``Gate``), ``None`` for exact kinds.
        closed_port: a port that overrides ``gate.closed`` (``Precondition``'s ``else``).
        abstract_port: the kind is an abstraction only when this port reads the blackboard
            (``{key}``); with a literal value its rules are exact and need no option (the Loop
            family's ``queue``: docs/semantics.md, "LoopInt, LoopBool, LoopDouble, LoopString").
    """

    name: str
    kind: NodeKind
    family: Family
    children: int | None
    tick: str
    halt: str = "sets its status to IDLE"
    child_counts: tuple[int, ...] | None = None
    min_children: int = 1
    memory: tuple[str, ...] = ()
    default_memory: tuple[object, ...] | None = None
    halt_resets_memory: bool = False
    reactive: bool = False
    with_memory: bool = False
    asynchronous: bool = False
    wakes_up: bool = False
    mergeable: bool = False
    handler: str | None = None
    internal_result: str | None = None
    result_map: tuple[str, str] | None = None
    time_based: bool = False
    blackboard_based: bool = False
    rejection: str | None = None
    nusmv: str | None = None
    nusmv_refusal: str | None = None
    ports: tuple[str, ...] = ()
    aliases: tuple[str, ...] = ()
    source: str = ""
    library: str = "BehaviorTree.CPP"
    requires: str | None = None
    abstraction: str | None = None
    gate: Gate | None = None
    closed_port: str | None = None
    abstract_port: str | None = None

    @property
    def type(self) -> str:
        """The type name (the ``NodeSpec.type`` of earlier releases)."""
        return self.name

    @property
    def is_fallback(self) -> bool:
        """Stops at the first success (the fallback family)."""
        return self.family is Family.FALLBACK

    @property
    def is_plain(self) -> bool:
        """A plain ``Sequence``/``Fallback``: not reactive, no memory, not asynchronous."""
        return (
            self.family in (Family.SEQUENCE, Family.FALLBACK)
            and not self.reactive
            and not self.with_memory
            and not self.asynchronous
        )

    def abstracted_for(self, attrs: Mapping[str, str]) -> bool:
        """Whether a node of this kind with these attributes is modelled as an abstraction.

        Args:
            attrs: the node's XML attributes (its ports).

        Returns:
            ``True`` for a kind with an ``abstraction``, unless its ``abstract_port`` holds a
            literal value (then the node's rules are exact).
        """
        if self.abstraction is None:
            return False
        if self.abstract_port is None:
            return True
        return is_blackboard_reference(attrs.get(self.abstract_port, ""))

    def allows_children(self, count: int) -> bool:
        """Whether a node of this kind may have ``count`` children in a file."""
        if self.child_counts is not None:
            return count in self.child_counts
        if self.children is None:
            return count >= self.min_children
        return count == self.children


def is_blackboard_reference(text: str) -> bool:
    """A port value that names a blackboard entry (``{key}``), as BehaviorTree.CPP's
    ``isBlackboardPointer`` reads it: surrounding spaces ignored, at least one character
    between the braces."""
    text = text.strip(" ")
    return len(text) >= 3 and text.startswith("{") and text.endswith("}")


_NODES: dict[str, NodeSemantics] = {}
_ALIASES: dict[str, str] = {}
_VERSION = [0]  # bumped by register/unregister: lets derived tables know when to rebuild


def version() -> int:
    """A counter that changes whenever a kind is registered or removed."""
    return _VERSION[0]


def register(node: NodeSemantics) -> NodeSemantics:
    """Add a node kind to the registry.

    Args:
        node: the entry; its ``name`` and ``aliases`` must be new.

    Returns:
        ``node`` (so a family module can write ``X = register(NodeSemantics(...))``).

    Raises:
        ValueError: the name or an alias is already registered.
    """
    for name in (node.name, *node.aliases):
        if name in _NODES or name in _ALIASES:
            raise ValueError(f"node kind {name!r} is already registered")
    _NODES[node.name] = node
    for alias in node.aliases:
        _ALIASES[alias] = node.name
    _VERSION[0] += 1
    return node


def unregister(name: str) -> None:
    """Remove a kind added by ``register`` (and its aliases). Unknown names are ignored."""
    node = _NODES.pop(name, None)
    if node is not None:
        for alias in node.aliases:
            _ALIASES.pop(alias, None)
        _VERSION[0] += 1


@contextmanager
def registered(*nodes: NodeSemantics) -> Iterator[None]:
    """Register ``nodes`` for the duration of a ``with`` block (tests, plug-ins).

    Args:
        nodes: new entries.
    """
    for node in nodes:
        register(node)
    try:
        yield
    finally:
        for node in nodes:
            unregister(node.name)


def canonical_type(type_name: str) -> str:
    """The v4 name of a node type (v3 aliases mapped, everything else unchanged)."""
    return _ALIASES.get(type_name, type_name)


def node_semantics(type_name: str) -> NodeSemantics | None:
    """The entry of a type name (aliases accepted), or ``None`` for a custom / unknown type."""
    return _NODES.get(_ALIASES.get(type_name, type_name))


def all_nodes() -> tuple[NodeSemantics, ...]:
    """Every registered entry, in declaration order."""
    return tuple(_NODES.values())


def aliases() -> dict[str, str]:
    """Every alias and the v4 name it stands for."""
    return dict(_ALIASES)


def kinds_where(
    predicate: Callable[[NodeSemantics], bool], nodes: Iterable[NodeSemantics] | None = None
) -> frozenset[str]:
    """The names of the registered kinds (or of ``nodes``) that satisfy ``predicate``."""
    return frozenset(n.name for n in (all_nodes() if nodes is None else nodes) if predicate(n))


#: The options that enable kinds: ``--nodes`` profiles and ``--abstract`` families.
PROFILES = ("nav2", "moveit_pro")
ABSTRACTIONS = ("time", "blackboard")


def enabling_option(requirement: str) -> str:
    """The command-line option that enables a ``NodeSemantics.requires`` value."""
    if requirement in ABSTRACTIONS:
        return f"--abstract {requirement}"
    return f"--nodes {requirement}"


__all__ = [
    "ABSTRACTIONS",
    "Family",
    "Gate",
    "PROFILES",
    "enabling_option",
    "is_blackboard_reference",
    "NodeSemantics",
    "aliases",
    "all_nodes",
    "canonical_type",
    "kinds_where",
    "node_semantics",
    "register",
    "registered",
    "unregister",
    "version",
]
