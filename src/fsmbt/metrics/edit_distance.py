"""Distances between two models: tree edit distance of BTs (zss, Zhang-Shasha) and graph edit
distance of FSMs (networkx, bounded by a timeout).

BT: unit costs (insert, delete, relabel = 1); a node's label is ``type`` plus its ``name`` when it
has one, so renaming a leaf or changing a Sequence into a Fallback costs 1. Zhang-Shasha runs
in O(n1 n2 min(d1, l1) min(d2, l2)) time for n nodes, depth d and l leaves.
FSM: the flattened machines as directed graphs; nodes are states labelled with their action
and final flag plus one start node; an edge per (source, target) labelled with the sorted set
of its events (the initial arrow carries the initial event). Unit costs. Exact graph edit
distance is NP-hard: ``networkx.optimize_edit_paths`` gives better and better upper bounds
until it proves the optimum, reaches the label lower bound (``label_lower_bound``) or the
timeout stops it; the result says which. The distance of the machines *as written* (every
level, not flattened) is ``fsmbt.metrics.structure_distance``.
"""

from __future__ import annotations

import time
from collections import Counter
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import networkx as nx

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM

START_NODE = "__start__"


@dataclass
class Distance:
    value: float
    exact: bool  # False: an upper bound (the search was cut by the timeout)
    method: str
    seconds: float
    lower_bound: float | None = None  # no edit path is cheaper (None: not computed)

    def to_dict(self) -> dict[str, object]:
        found: dict[str, object] = {
            "value": self.value,
            "exact": self.exact,
            "method": self.method,
            "seconds": round(self.seconds, 6),
            "kind": "exact" if self.exact else "upper bound",
        }
        if self.lower_bound is not None:
            found["lower_bound"] = self.lower_bound
        return found


def _label(node: BTNode) -> str:
    return f"{node.type}:{node.name}" if node.name else node.type


def tree_edit_distance(a: BTDocument | BTNode, b: BTDocument | BTNode) -> Distance:
    """Zhang-Shasha distance between the main trees (unit costs)."""
    ra = a.main.root if isinstance(a, BTDocument) else a
    rb = b.main.root if isinstance(b, BTDocument) else b
    began = time.perf_counter()
    if ra is None or rb is None:
        other = rb if ra is None else ra
        value = float(sum(1 for _ in other.walk())) if other is not None else 0.0
    else:
        import zss  # heavy (numpy); only `fsmbt metrics A B` needs it

        value = float(zss.simple_distance(ra, rb, lambda n: n.children, _label))
    return Distance(value, True, "zss (Zhang-Shasha)", time.perf_counter() - began)


def fsm_graph(fsm: FSM) -> nx.DiGraph:
    """The flattened FSM as a labelled digraph (see the module docstring)."""
    flat = flatten(fsm)
    import networkx as nx

    graph: nx.DiGraph[str] = nx.DiGraph()
    graph.add_node(START_NODE, label=("start",))
    for state in flat.states.values():
        graph.add_node(state.name, label=("state", state.action, state.final))
    events: dict[tuple[str, str], set[str]] = {}
    if flat.initial is not None:
        events[(START_NODE, flat.initial)] = {flat.initial_event or ""}
    for t in flat.transitions:
        events.setdefault((t.source, t.target), set()).add(t.event or "")
    for (source, target), names in events.items():
        graph.add_edge(source, target, label=tuple(sorted(names)))
    return graph


def label_lower_bound(a: nx.DiGraph, b: nx.DiGraph) -> int:
    """A lower bound of the unit-cost graph edit distance from the label multisets.

    For nodes (and likewise edges) with ``I`` labels in common (multiset intersection), any
    edit path costs at least ``max(|A|, |B|) - I``: at most ``I`` substitutions are free and
    every other element of the larger side is substituted or inserted/deleted at cost >= 1.

    Args:
        a: a graph whose nodes and edges carry a ``label``.
        b: another such graph.

    Returns:
        The bound (an integer).
    """

    def part(first: list[object], second: list[object]) -> int:
        x, y = Counter(first), Counter(second)
        common = sum((x & y).values())
        return max(len(first), len(second)) - common

    nodes = part(
        [d["label"] for _, d in a.nodes(data=True)], [d["label"] for _, d in b.nodes(data=True)]
    )
    edges = part(
        [d["label"] for _, _, d in a.edges(data=True)],
        [d["label"] for _, _, d in b.edges(data=True)],
    )
    return nodes + edges


def graph_edit_distance(a: FSM, b: FSM, *, timeout: float = 5.0) -> Distance:
    """Graph edit distance of two flattened FSMs, exact when the search ends within
    ``timeout`` or reaches ``label_lower_bound``; ``lower_bound`` is always given."""
    import networkx as nx

    ga, gb = fsm_graph(a), fsm_graph(b)
    lower = label_lower_bound(ga, gb)
    began = time.perf_counter()
    best: float | None = None
    same = lambda x, y: x["label"] == y["label"]  # noqa: E731
    for _nodes, _edges, cost in nx.optimize_edit_paths(
        ga, gb, node_match=same, edge_match=same, strictly_decreasing=True, timeout=timeout
    ):
        best = cost
    elapsed = time.perf_counter() - began
    exact = elapsed < timeout
    if best is None:  # nothing found in time: deleting a and inserting b is always possible
        best = float(
            ga.number_of_nodes()
            + ga.number_of_edges()
            + gb.number_of_nodes()
            + gb.number_of_edges()
        )
        exact = False
    exact = exact or best == lower
    return Distance(
        float(best),
        exact,
        "networkx optimize_edit_paths",
        elapsed,
        lower_bound=float(best if exact else lower),
    )
