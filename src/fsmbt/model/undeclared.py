"""Leaves whose kind no declaration gives, counted per node type (docs/semantics.md, 'Models').

A BehaviorTree.CPP file may use leaf types it never declares (Nav2's trees rely on
``nav2_tree_nodes.xml``); fsmbt then assumes an Action (the safe choice: it may return RUNNING).
A real tree repeats the same types many times, so every front end reports them as one line per
type with a count - never one line per node. Cost: O(N) over the document's nodes.
"""

from __future__ import annotations

from collections import Counter

from fsmbt.model.bt import BTDocument


def undeclared_leaf_types(doc: BTDocument) -> Counter[str]:
    """How many nodes of each undeclared leaf type the document has (all trees).

    Args:
        doc: the BT document.

    Returns:
        Node type -> number of nodes, most frequent first when iterated with ``most_common``.
    """
    found: Counter[str] = Counter()
    for _tree_id, node in doc.nodes():
        if not node.kind_declared and not node.children:
            found[node.type] += 1
    return found


def summary(counts: Counter[str], *, shown: int = 12) -> str:
    """One line for all undeclared leaf types: ``3 undeclared leaf types (7 nodes) assumed to
    be Actions that may return RUNNING: Spin x3, Wait x2, BackUp``.

    Args:
        counts: from ``undeclared_leaf_types``.
        shown: most types named (the rest are counted).

    Returns:
        The line, or ``""`` when there is none.
    """
    if not counts:
        return ""
    nodes = sum(counts.values())
    types = len(counts)
    named = [f"{t} x{n}" if n > 1 else t for t, n in counts.most_common(shown)]
    if types > shown:
        named.append(f"... (+{types - shown} more types)")
    kind = "type" if types == 1 else "types"
    node_word = "node" if nodes == 1 else "nodes"
    return (
        f"{types} undeclared leaf {kind} ({nodes} {node_word}) assumed to be Actions that "
        f"may return RUNNING: {', '.join(named)}"
    )
