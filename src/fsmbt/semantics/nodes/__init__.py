"""The semantic face of the node registry: the tables the interpreter and the engines run on.

The entries (one per built-in kind, by family: ``fsmbt.model.nodes.controls``, ``.decorators``,
``.leaves``) are declared in the model layer, because the readers and ``validate`` need them and
the model must not import ``fsmbt.semantics`` (docs/architecture.md, layers). This package
re-exports them and adds what only the semantics layer speaks: results as ``NodeStatus``, and
``RuntimeTables`` - the dispatch data of ``fsmbt.semantics.bt_interpreter`` (which tick rule,
which default memory, which kinds forget their memory on halt, which are refused and why),
rebuilt whenever a kind is registered, so a kind added with ``register()`` is ticked by the next
interpreter built.

Costs: ``runtime_tables()`` is O(K) for K kinds the first time after a registration, then a
cached read.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import (
    ABSTRACTIONS,
    BLACKBOARD_BASED,
    FALLBACK_TYPES,
    INTERPRETED_CONTROLS,
    INTERPRETED_DECORATORS,
    MERGEABLE_CONTROLS,
    NUSMV_ENCODED,
    PLAIN_CONTROLS,
    PROFILES,
    REACTIVE_CONTROLS,
    RESULT_MAP_DECORATORS,
    SEQUENCE_TYPES,
    SUBTREE_TYPE,
    TIME_BASED,
    Family,
    NodeSemantics,
    aliases,
    all_nodes,
    canonical_type,
    enabling_option,
    kinds_where,
    node_semantics,
    register,
    registered,
    unregister,
)
from fsmbt.model.nodes.registry import version
from fsmbt.semantics.status import NodeStatus


@dataclass(frozen=True)
class RuntimeTables:
    """What the interpreter dispatches on, derived from the registry (see the module docstring).

    Attributes:
        handlers: kind -> name of its tick rule (a ``FamilyRule`` in
            ``fsmbt.semantics.families.registry``).
        controls: control kinds with a tick rule.
        decorators: decorator kinds with a tick rule.
        internal_leaves: internal leaf kind -> the status it always returns.
        rejected: kind -> why the interpreter refuses it.
        default_memory: kind -> its memory at rest.
        halt_resets_memory: kinds whose ``halt()`` forgets their memory.
        sequence_flags: sequence/fallback kinds ticked by the ``sequence`` rule -> (is a
            fallback, asynchronous, with memory).
        reactive_fallbacks: reactive kinds of the fallback family.
        result_maps: status-mapping decorator -> the statuses its child's SUCCESS/FAILURE
            become.
    """

    handlers: dict[str, str]
    controls: frozenset[str]
    decorators: frozenset[str]
    internal_leaves: dict[str, int]
    rejected: dict[str, str]
    default_memory: dict[str, tuple[object, ...]]
    halt_resets_memory: frozenset[str]
    sequence_flags: dict[str, tuple[bool, bool, bool]]
    reactive_fallbacks: frozenset[str]
    result_maps: dict[str, tuple[int, int]]


def internal_status(node: NodeSemantics) -> NodeStatus | None:
    """The status an internal leaf always returns, ``None`` for every other kind."""
    return None if node.internal_result is None else NodeStatus[node.internal_result]


def _build(nodes: tuple[NodeSemantics, ...]) -> RuntimeTables:
    # a condition kind's handler (``env_condition``) names no tick rule: it is ticked as an
    # environment leaf
    handlers = {
        n.name: n.handler
        for n in nodes
        if n.handler is not None and n.kind is not NodeKind.CONDITION
    }
    internal = {
        n.name: int(NodeStatus[n.internal_result]) for n in nodes if n.internal_result is not None
    }
    return RuntimeTables(
        handlers=handlers,
        controls=kinds_where(lambda n: n.kind is NodeKind.CONTROL and n.handler is not None, nodes),
        decorators=kinds_where(
            lambda n: n.kind is NodeKind.DECORATOR and n.handler is not None, nodes
        ),
        internal_leaves=internal,
        rejected={n.name: n.rejection for n in nodes if n.rejection is not None},
        default_memory={n.name: n.default_memory for n in nodes if n.default_memory is not None},
        halt_resets_memory=kinds_where(lambda n: n.halt_resets_memory, nodes),
        sequence_flags={
            n.name: (n.is_fallback, n.asynchronous, n.with_memory)
            for n in nodes
            if n.handler == "sequence"
        },
        reactive_fallbacks=kinds_where(lambda n: n.reactive and n.is_fallback, nodes),
        result_maps={
            n.name: (int(NodeStatus[n.result_map[0]]), int(NodeStatus[n.result_map[1]]))
            for n in nodes
            if n.result_map is not None
        },
    )


T = TypeVar("T")


def abstractions_used(doc: object) -> list[str]:
    """The abstraction sentences of every node of a BT document modelled as an abstraction
    (``BTNode.semantics`` naming a kind with an ``abstraction``), once each, in tree order:
    what a verdict over ``doc`` holds under (docs/semantics.md §10).

    Args:
        doc: a ``BTDocument`` (anything else has none).

    Returns:
        The sentences, e.g. ``["RateController may skip its child on any tick (...)"]``.
    """
    from fsmbt.model.bt import BTDocument

    if not isinstance(doc, BTDocument):
        return []
    found: dict[str, None] = {}
    for _tree, node in doc.nodes():
        if node.semantics is None:
            continue
        spec = node_semantics(node.semantics)
        if spec is not None and spec.abstracted_for(node.attrs):
            # (a Loop over a literal queue is exact: not an abstraction)
            assert spec.abstraction is not None
            sentence = spec.abstraction
            if node.semantics != node.type:
                sentence = f"{node.type} (as {sentence})"
            found.setdefault(sentence, None)
    return list(found)


def rewired(decorator: str, success: T, failure: T) -> tuple[T, T]:
    """Where a status-mapping decorator's child's SUCCESS and FAILURE lead, given where the
    decorator's own SUCCESS and FAILURE lead (its ``result_map``); the converters wire
    Inverter, ForceSuccess and ForceFailure with it.

    Args:
        decorator: a type in ``RESULT_MAP_DECORATORS``.
        success: the target of the decorator's SUCCESS.
        failure: the target of the decorator's FAILURE.

    Returns:
        The targets of the child's SUCCESS and FAILURE.

    Raises:
        ValueError: ``decorator`` is not a status-mapping decorator.
    """
    spec = node_semantics(decorator)
    if spec is None or spec.result_map is None:
        raise ValueError(f"{decorator!r} is not a status-mapping decorator")
    on_success, on_failure = spec.result_map
    succeeded = NodeStatus.SUCCESS.name
    return (
        success if on_success == succeeded else failure,
        success if on_failure == succeeded else failure,
    )


_CACHE: list[tuple[int, RuntimeTables]] = []


def runtime_tables() -> RuntimeTables:
    """The interpreter's tables for the kinds registered now (cached until the next change)."""
    current = version()
    if not _CACHE or _CACHE[0][0] != current:
        _CACHE[:] = [(current, _build(all_nodes()))]
    return _CACHE[0][1]


__all__ = [
    "ABSTRACTIONS",
    "BLACKBOARD_BASED",
    "PROFILES",
    "FALLBACK_TYPES",
    "INTERPRETED_CONTROLS",
    "INTERPRETED_DECORATORS",
    "MERGEABLE_CONTROLS",
    "NUSMV_ENCODED",
    "PLAIN_CONTROLS",
    "SUBTREE_TYPE",
    "REACTIVE_CONTROLS",
    "RESULT_MAP_DECORATORS",
    "SEQUENCE_TYPES",
    "TIME_BASED",
    "Family",
    "NodeSemantics",
    "RuntimeTables",
    "abstractions_used",
    "aliases",
    "all_nodes",
    "canonical_type",
    "enabling_option",
    "internal_status",
    "kinds_where",
    "node_semantics",
    "register",
    "registered",
    "rewired",
    "runtime_tables",
    "unregister",
]
