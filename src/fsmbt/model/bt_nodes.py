"""The node types of BehaviorTree.CPP v4 that fsmbt knows, and the names older inputs use.

A thin view of the node registry (``fsmbt.model.nodes``, docs/semantics.md "Node registry"):
nothing here is declared, everything is read from the registry's entries.

Everything is mapped to BehaviorTree.CPP v4 meaning (docs/semantics.md, 'Names'): the reactive
"Sequence" of Colledanchise & Ögren is ``ReactiveSequence`` here, their "Sequence*" is the plain
``Sequence``; BehaviorTree.CPP v3's ``SequenceStar`` is v4's ``SequenceWithMemory``.
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import FALLBACK_TYPES, SEQUENCE_TYPES, aliases, all_nodes, node_semantics
from fsmbt.model.nodes import canonical_type as canonical_type
from fsmbt.model.nodes.registry import NodeSemantics

#: A built-in node type (the registry entry; ``.type``, ``.kind``, ``.children``,
#: ``.time_based`` as before).
NodeSpec = NodeSemantics

#: The built-in node types by name (a snapshot of the registry at import).
BUILTIN_NODES: dict[str, NodeSpec] = {node.name: node for node in all_nodes()}

#: BehaviorTree.CPP v3 (and misspelt) names and their v4 equivalents.
V3_ALIASES: dict[str, str] = aliases()


def builtin_spec(type_name: str) -> NodeSpec | None:
    """The registry entry of a type name (aliases accepted), ``None`` for custom types."""
    return node_semantics(type_name)


__all__ = [
    "BUILTIN_NODES",
    "FALLBACK_TYPES",
    "SEQUENCE_TYPES",
    "V3_ALIASES",
    "NodeKind",
    "NodeSpec",
    "builtin_spec",
    "canonical_type",
]
