"""Structural statistics of a model: what ``fsmbt info`` shows and the size metrics build on.

FSM (docs/conversion.md, 'FSM -> BT: the loop-execution BT'): the *entry state* is the target of the initial transition (``fsm.initial``);
a *loop state* has in-degree >= 2, where in-degree counts distinct predecessor states and the
start pseudo-state's edge into the entry state (an FSM without a named start pseudo-state still
has that edge: it is how the machine gets into its initial state). These are computed on the
top-level machine, the one a converter walks; hierarchical counts cover every level.

BT: depth counts levels (a lone root has depth 1), breadth is the largest number of nodes on one
level, leaves are Action and Condition nodes (SubTree references are counted apart).
``expanded_depth`` follows SubTree references from the main tree (``None`` when they form a cycle
or name a tree that does not exist).

Every traversal uses an explicit stack: models may be 100 000 levels deep. Complexity: O(N + T)
for N states/nodes and T transitions; entry/loop detection O(T).
"""

from __future__ import annotations

from collections import Counter, deque
from dataclasses import asdict, dataclass, field
from typing import Any

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM


# -- FSM --------------------------------------------------------------------------------------
@dataclass
class FSMStats:
    """Counts and named states of one FSM; every list keeps the model's state order."""

    name: str
    states: int  # top level
    transitions: int  # top level
    events: list[str]  # every level, first appearance order
    initial: str | None
    start: str | None  # the start pseudo-state, when the model names one
    initial_event: str | None
    finals: list[str]  # top level
    entry_state: str | None
    loop_states: list[str]
    unreachable: list[str]  # top level, from the initial state
    hierarchical: bool
    all_states: int  # every level
    all_transitions: int  # every level
    composite_states: int
    parallel_states: int
    nesting_depth: int  # 1 for a flat FSM
    in_degree: dict[str, int] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The figures as plain data (for ``--json``).

        Returns:
            Every field, plus ``kind: "fsm"``.
        """
        return {"kind": "fsm", **asdict(self)}


def in_degrees(fsm: FSM) -> dict[str, int]:
    """Distinct predecessors of each top-level state, plus the start edge of the initial state.

    Two transitions from the same source into the same target (different events) count once:
    the LEBT merges them into one guard either way (docs/conversion.md, 'FSM -> BT').

    Args:
        fsm: A machine (only its top level is counted).

    Returns:
        The in-degree of every top-level state, by name.
    """
    preds: dict[str, set[str]] = {name: set() for name in fsm.states}
    for t in fsm.transitions:
        if t.target in preds:
            preds[t.target].add(t.source)
    degrees = {name: len(sources) for name, sources in preds.items()}
    if fsm.initial in degrees:
        degrees[fsm.initial] += 1  # the start pseudo-state's edge (named or implicit)
    return degrees


def fsm_stats(fsm: FSM) -> FSMStats:
    """Counts and named states of an FSM (what ``fsmbt info`` prints).

    Args:
        fsm: A flat or hierarchical machine.

    Returns:
        Its figures: sizes at the top level and at every level, initial, final, entry, loop
        and unreachable states, nesting depth and in-degrees.
    """
    degrees = in_degrees(fsm)
    all_states = all_transitions = composites = parallels = 0
    depth = 0
    events: dict[str, None] = {}
    if fsm.initial_event is not None:
        events[fsm.initial_event] = None
    stack: list[tuple[FSM, int]] = [(fsm, 1)]
    while stack:
        machine, level = stack.pop()
        depth = max(depth, level)
        all_transitions += len(machine.transitions)
        for t in machine.transitions:
            if t.event is not None:
                events.setdefault(t.event, None)
        for state in machine.states.values():
            all_states += 1
            composites += state.is_composite
            parallels += state.is_parallel
            stack.extend((region, level + 1) for region in reversed(state.regions))
    return FSMStats(
        name=fsm.name,
        states=len(fsm.states),
        transitions=len(fsm.transitions),
        events=list(events),
        initial=fsm.initial,
        start=fsm.start_name,
        initial_event=fsm.initial_event,
        finals=[s.name for s in fsm.states.values() if s.final],
        entry_state=fsm.initial if fsm.initial in fsm.states else None,
        loop_states=[name for name, d in degrees.items() if d >= 2],
        unreachable=_unreachable(fsm),
        hierarchical=fsm.is_hierarchical,
        all_states=all_states,
        all_transitions=all_transitions,
        composite_states=composites,
        parallel_states=parallels,
        nesting_depth=depth,
        in_degree=degrees,
    )


def _unreachable(fsm: FSM) -> list[str]:
    if fsm.initial not in fsm.states:
        return list(fsm.states)
    successors: dict[str, list[str]] = {}
    for t in fsm.transitions:
        successors.setdefault(t.source, []).append(t.target)
    seen = {fsm.initial}
    queue = deque([fsm.initial])
    while queue:
        for target in successors.get(queue.popleft(), []):
            if target not in seen:
                seen.add(target)
                queue.append(target)
    return [name for name in fsm.states if name not in seen]


# -- BT ---------------------------------------------------------------------------------------
@dataclass
class TreeStats:
    """The shape of one tree: node count, depth (levels), breadth (widest level), the most
    children of one node, and leaves."""

    id: str
    nodes: int
    depth: int
    breadth: int
    max_children: int
    leaves: int


@dataclass
class BTStats:
    """Counts of one BT document: nodes by kind and type, leaves, SubTree references, and the
    main tree's shape with and without references followed."""

    main_tree: str | None
    trees: int
    nodes: int  # every tree, SubTree references not expanded
    by_kind: dict[str, int]
    by_type: dict[str, int]
    leaves: int
    actions: int
    conditions: int
    subtree_references: int
    depth: int  # of the main tree, references not expanded
    breadth: int  # of the main tree
    max_children: int  # of any node in any tree
    expanded_depth: int | None  # main tree with references followed
    per_tree: list[TreeStats] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """The figures as plain data (for ``--json``).

        Returns:
            Every field (``per_tree`` as a list of dicts), plus ``kind: "bt"``.
        """
        return {"kind": "bt", **asdict(self)}


def tree_shape(root: BTNode | None, tree_id: str = "tree") -> TreeStats:
    """Nodes, depth (levels), breadth (widest level), widest node and leaves of one tree.

    Args:
        root: The tree's root (``None``: an empty tree).
        tree_id: The ID reported.

    Returns:
        The shape, measured without recursion.
    """
    if root is None:
        return TreeStats(tree_id, 0, 0, 0, 0, 0)
    width: Counter[int] = Counter()
    nodes = leaves = max_children = 0
    stack: list[tuple[BTNode, int]] = [(root, 1)]
    while stack:
        node, level = stack.pop()
        nodes += 1
        width[level] += 1
        leaves += node.is_leaf
        max_children = max(max_children, len(node.children))
        stack.extend((child, level + 1) for child in node.children)
    return TreeStats(tree_id, nodes, max(width), max(width.values()), max_children, leaves)


def bt_stats(doc: BTDocument) -> BTStats:
    """Counts of a BT document (what ``fsmbt info`` prints).

    Args:
        doc: The document.

    Returns:
        Its figures, with one ``TreeStats`` per tree.
    """
    by_kind: Counter[str] = Counter()
    by_type: Counter[str] = Counter()
    for _tree_id, node in doc.nodes():
        by_kind[node.kind.value] += 1
        by_type[node.type] += 1
    per_tree = [tree_shape(tree.root, tree.id) for tree in doc.trees.values()]
    main_id = _main_id(doc)
    main = next((t for t in per_tree if t.id == main_id), TreeStats(str(main_id), 0, 0, 0, 0, 0))
    return BTStats(
        main_tree=main_id,
        trees=len(doc.trees),
        nodes=sum(t.nodes for t in per_tree),
        by_kind=dict(sorted(by_kind.items())),
        by_type=dict(sorted(by_type.items(), key=lambda kv: (-kv[1], kv[0]))),
        leaves=sum(t.leaves for t in per_tree),
        actions=by_kind[NodeKind.ACTION.value],
        conditions=by_kind[NodeKind.CONDITION.value],
        subtree_references=by_kind[NodeKind.SUBTREE.value],
        depth=main.depth,
        breadth=main.breadth,
        max_children=max((t.max_children for t in per_tree), default=0),
        expanded_depth=expanded_depth(doc),
        per_tree=per_tree,
    )


def _main_id(doc: BTDocument) -> str | None:
    try:
        return doc.main.id
    except KeyError:
        return None


def expanded_depth(doc: BTDocument) -> int | None:
    """Depth of the main tree with every SubTree node replaced by the tree it names.

    A SubTree node counts as one level above its tree's root (it is a node BehaviorTree.CPP
    ticks). ``None`` when references are cyclic or dangling. O(N) over all trees: trees are
    measured once each, in reverse topological order of the reference graph.

    Args:
        doc: The document.

    Returns:
        The depth in levels, or ``None`` (no main tree, cyclic or dangling references).
    """
    main_id = _main_id(doc)
    if main_id is None:
        return None
    import networkx as nx  # imported here: it costs ~0.4 s at CLI start-up

    graph: nx.DiGraph[str] = nx.DiGraph()
    graph.add_nodes_from(doc.trees)
    for tree_id, node in doc.nodes():
        ref = node.subtree_id
        if ref is not None:
            if ref not in doc.trees:
                return None
            graph.add_edge(tree_id, ref)
    if not nx.is_directed_acyclic_graph(graph):
        return None
    depth_of: dict[str, int] = {}
    for tree_id in reversed(list(nx.topological_sort(graph))):
        root = doc.trees[tree_id].root
        deepest = 0
        if root is not None:
            stack: list[tuple[BTNode, int]] = [(root, 1)]
            while stack:
                node, level = stack.pop()
                ref = node.subtree_id
                below = depth_of[ref] if ref is not None else 0
                deepest = max(deepest, level + below)
                stack.extend((child, level + 1) for child in node.children)
        depth_of[tree_id] = deepest
    return depth_of[main_id]


def model_stats(model: FSM | BTDocument) -> FSMStats | BTStats:
    """The figures of either kind of model.

    Args:
        model: An ``FSM`` or a ``BTDocument``.

    Returns:
        ``FSMStats`` for an FSM, ``BTStats`` for a BT document.
    """
    return fsm_stats(model) if isinstance(model, FSM) else bt_stats(model)
