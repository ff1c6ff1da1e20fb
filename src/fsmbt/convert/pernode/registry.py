"""The per-node rules by handler name (``fsmbt.semantics.nodes.runtime_tables().handlers``):
one table the writer dispatches on (``fsmbt.convert.pernode``). A handler not here is refused
by name, and the converter keeps the explored form for that region."""

from __future__ import annotations

from fsmbt.convert.pernode import loops, parallel, reactive, sequence, status_map
from fsmbt.convert.pernode.kernel import NodeRule

RULES: dict[str, NodeRule] = {
    handler: family.RULE
    for family in (sequence, reactive, status_map, loops, parallel)
    for handler in family.RULE.handlers
}
#: The tick rules written per node.
SUPPORTED_HANDLERS = frozenset(RULES)
