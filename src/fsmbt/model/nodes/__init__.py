"""The node registry: every built-in BehaviorTree.CPP v4 node kind, declared once by family.

``registry.py`` holds the ``NodeSemantics`` entry type and the lookups; ``controls.py``,
``decorators.py`` and ``leaves.py`` declare the built-ins (importing this package registers
them). The named sets below are derived from the built-in entries, once, at import: each node
set the code base uses is defined here and nowhere else. docs/semantics.md ("Node registry")
says which module reads which set.
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import controls, decorators, leaves, projects
from fsmbt.model.nodes.registry import (
    ABSTRACTIONS,
    PROFILES,
    Family,
    Gate,
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

_BUILTINS = all_nodes()

#: Control kinds the interpreter ticks.
INTERPRETED_CONTROLS = kinds_where(lambda n: n.kind is NodeKind.CONTROL and n.handler is not None)
#: Decorator kinds the interpreter ticks.
INTERPRETED_DECORATORS = kinds_where(
    lambda n: n.kind is NodeKind.DECORATOR and n.handler is not None
)
#: The plain (non-reactive, memoryless, synchronous) Sequence and Fallback: the paper's
#: controls, the unit controls of BT -> HFSM, the fast leaf table's class.
PLAIN_CONTROLS = kinds_where(lambda n: n.is_plain)
#: Reactive controls (re-tick earlier children every tick).
REACTIVE_CONTROLS = kinds_where(lambda n: n.reactive)
#: Controls depth compression merges with a child of the same kind.
MERGEABLE_CONTROLS = kinds_where(lambda n: n.mergeable)
#: Decorators that only rewrite their child's SUCCESS/FAILURE (Inverter, ForceSuccess, ...).
RESULT_MAP_DECORATORS = kinds_where(lambda n: n.result_map is not None)
#: Every kind of the sequence family / the fallback family.
SEQUENCE_TYPES = kinds_where(lambda n: n.family is Family.SEQUENCE)
FALLBACK_TYPES = kinds_where(lambda n: n.family is Family.FALLBACK)
#: Kinds that need a clock / read the blackboard for control flow.
TIME_BASED = kinds_where(lambda n: n.time_based)
BLACKBOARD_BASED = kinds_where(lambda n: n.blackboard_based)
#: Kinds the NuSMV encoder encodes.
NUSMV_ENCODED = kinds_where(lambda n: n.nusmv is not None)
#: The SubTree reference's canonical type name (its declaration, ``leaves.SUBTREE``): a compiled
#: tree gives every expanded reference this type and the referenced root as its one child.
SUBTREE_TYPE: str = leaves.SUBTREE.name

__all__ = [
    "ABSTRACTIONS",
    "BLACKBOARD_BASED",
    "PROFILES",
    "Gate",
    "enabling_option",
    "projects",
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
    "aliases",
    "all_nodes",
    "canonical_type",
    "controls",
    "decorators",
    "kinds_where",
    "leaves",
    "node_semantics",
    "register",
    "registered",
    "unregister",
]
