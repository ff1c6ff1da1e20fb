"""Hierarchical FSM -> BT with one ``<BehaviorTree>`` per composite state (the paper's future work).

The behaviour is the flattened FSM's (docs/semantics.md, 'Models': every check works on the flattening), so the
guards and state leaves speak flat names (``Door/Open/ajar``) and the macro-step protocol of
docs/semantics.md, 'The LEBT protocol', is unchanged; only the *shape* of the tree follows the hierarchy:

- a *cluster* is a composite state with the flat states inside it; each cluster gets its own
  tree (id = its path, ``Door/Open``), referenced from its parent level by a ``<SubTree>`` node;
  trees are built lowest level first;
- on one level (the top machine or a cluster) the *nodes* are its atomic flat states and its
  sub-clusters. The LEBT rules apply to the graph of these nodes, with one rule added: every
  sub-cluster is a root of its level. Roots: nodes entered from outside the level (the start
  pseudo-state included), nodes with >= 2 distinct predecessor nodes, and sub-clusters; every
  other atomic state hangs below its only predecessor node (a state, or a cluster - then below
  the cluster's ``SubTree``, entered when an event leaves the cluster towards it);
- selector(n) = ``Fallback(guard(n), body(n))``; ``guard(n)`` holds every flat (source, event)
  pair whose target lies in ``n`` (for a cluster: all of them, internal ones included); the
  body is the state leaf, or the cluster's ``SubTree``, alone or followed by the selectors hung
  below it. A cluster's tree is the ``Sequence`` of its level's root selectors.

Why it is equivalent (the checker proves it on every conversion in the tests): a guard matches
only pairs whose target lies below it, so the first tick of a macro step takes the transition
whenever its target hangs below the running state's path or lies further on in a root
sequence; otherwise the root returns SUCCESS with the event pending and the second tick
descends from the root through exactly the clusters containing the target (each is a root of
its level and its guard holds the pair) to the target, a root of its own level.

Parallel states: their regions' combinations are atomic members of the parallel state's cluster
(one ``SubTree`` over the product, no tree per region) - said in a warning. Completion
transitions are resolved by flattening (transient configurations do not exist in the flat
machine). Names containing ``/``, ``[`` or ``|`` cannot be told apart from flat paths: such a
machine is converted flat (``lebt``) with a warning that says so.

Depth bound (docs/semantics.md §5, "Depth-bounded LEBT"): within each level's tree, a node
whose selector would nest deeper than ``structure.MAX_SELECTOR_LEVELS`` becomes a root of its
level (as a node entered from outside is), so no ``<BehaviorTree>`` nests more than 200 XML
levels; a hierarchy deeper than ``MAX_SUBTREE_LEVELS`` is converted flat, with a warning.

Complexity: O(F + T + L) after flattening (F flat states, T flat transitions, L total length of
the flat names), explicit stacks only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from fsmbt.convert.lebt import ROOT_NAME, LebtLeafWriter, fsm_to_lebt, lebt_node_models
from fsmbt.convert.perf import without_gc_pauses
from fsmbt.convert.result import ConversionResult
from fsmbt.convert.structure import MAX_SELECTOR_LEVELS, analyse
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.flatten import PATH_SEPARATOR, flatten, needs_flattening
from fsmbt.model.fsm import FSM

HIERARCHY_MODES = ("subtrees", "flatten")
#: Most levels of ``SubTree`` nesting written (the main tree = 1): BehaviorTree.CPP's loader
#: recurses through every SubTree's XML, so a deeper hierarchy is converted flat (with a
#: warning) rather than written as a SubTree chain that grows with the machine
#: (docs/semantics.md §5, "Depth-bounded LEBT").
MAX_SUBTREE_LEVELS = 32
_AMBIGUOUS = ("/", "[", "|")
_OUTSIDE = "\x00outside"  # the predecessor standing for "from outside this level"


@dataclass
class _Cluster:
    """One composite (or parallel) state: its path, parent, members on its own level."""

    path: str
    parent: str | None  # None = the top level
    parallel: bool = False
    members: list[str] = field(default_factory=list)  # node keys, flat order
    depth: int = 0


def _state_key(flat_name: str) -> str:
    return "s:" + flat_name


def _cluster_key(path: str) -> str:
    return "c:" + path


def _ambiguous_names(fsm: FSM) -> list[str]:
    return [
        path for path, _machine, state in fsm.walk() if any(ch in state.name for ch in _AMBIGUOUS)
    ]


def _classify(fsm: FSM, flat: FSM) -> tuple[dict[str, _Cluster], dict[str, str | None]]:
    """Clusters by path and, for every flat state, the cluster it is an atomic member of."""
    clusters: dict[str, _Cluster] = {}
    owner: dict[str, str | None] = {}
    for flat_name in flat.states:
        machine, prefix, parent = fsm, "", None
        rest = flat_name
        while True:
            head, sep, tail = rest.partition(PATH_SEPARATOR)
            state = machine.states.get(head)
            if state is None or not sep or state.is_atomic:
                break  # an atomic state at this level (or a name flatten made up: keep it here)
            path = prefix + head
            if path not in clusters:
                parent_cluster: _Cluster | None = (
                    clusters.get(parent) if parent is not None else None
                )
                clusters[path] = _Cluster(
                    path,
                    parent,
                    state.is_parallel,
                    depth=0 if parent_cluster is None else parent_cluster.depth + 1,
                )
                (
                    parent_cluster.members
                    if parent_cluster is not None
                    else clusters.setdefault("", _Cluster("", None)).members
                ).append(_cluster_key(path))
            parent = path
            if state.is_parallel:
                break  # the regions' combinations are atomic members of the parallel cluster
            machine, prefix, rest = state.regions[0], path + PATH_SEPARATOR, tail
        owner[flat_name] = parent
        (
            clusters[parent].members
            if parent is not None
            else clusters.setdefault("", _Cluster("", None)).members
        ).append(_state_key(flat_name))
    return clusters, owner


def _node_at(
    flat_name: str, level: str | None, owner: dict[str, str | None], clusters: dict[str, _Cluster]
) -> str | None:
    """The node of ``level`` containing ``flat_name`` (None = not inside ``level``)."""
    path = owner[flat_name]
    if path == level:
        return _state_key(flat_name)
    while path is not None:
        parent = clusters[path].parent
        if parent == level:
            return _cluster_key(path)
        path = parent
    return None


@without_gc_pauses
def fsm_to_subtree_bt(fsm: FSM, *, style: str = "paper", **options: object) -> ConversionResult:
    """Convert a hierarchical FSM into an LEBT with one ``SubTree`` per composite state."""
    if not needs_flattening(fsm) or not fsm.is_hierarchical:
        return fsm_to_lebt(fsm, style=style, **options)
    ambiguous = _ambiguous_names(fsm)
    if ambiguous:
        result = fsm_to_lebt(fsm, style=style, **options)
        result.warnings.append(
            f"state name(s) {', '.join(ambiguous[:5])} contain '/', '[' or '|' and cannot be "
            "told apart from flattened paths: converted flat, without SubTrees"
        )
        return result
    if style != "paper":
        return fsm_to_lebt(fsm, style=style, **options)  # raises the style error
    flat = flatten(fsm)
    structure = analyse(flat)
    clusters, owner = _classify(fsm, flat)
    deepest = 1 + max((c.depth + 1 for p, c in clusters.items() if p), default=0)
    if deepest > MAX_SUBTREE_LEVELS:
        result = fsm_to_lebt(flat, style=style, **options)
        result.warnings.append(
            f"the hierarchy nests {deepest} levels of composite states, more than the "
            f"{MAX_SUBTREE_LEVELS} SubTree levels written: converted flat, without SubTrees"
        )
        return result
    top = clusters.setdefault("", _Cluster("", None))
    levels = [path for path in clusters if path != ""]
    warnings = [
        f"hierarchical FSM flattened to {len(flat.states)} states; composite states "
        f"kept as {len(levels)} SubTree(s)"
    ]
    parallel = [c.path for c in clusters.values() if c.parallel]
    if parallel:
        warnings.append(
            f"parallel state(s) {', '.join(parallel[:5])}: their regions are one "
            "SubTree over the product of the regions (no tree per region)"
        )

    writer = LebtLeafWriter(flat, structure)
    # per level: predecessor nodes of each node, and where each flat pair's target lies
    guard_pairs: dict[str, list[tuple[str, str]]] = {}
    preds: dict[str, dict[str, None]] = {}
    for target, pairs in structure.guard_pairs.items():
        for source, event in pairs:
            # every level from the target's own up to the top: the node there holding target
            level, node = owner[target], _state_key(target)
            while True:
                guard_pairs.setdefault(node, []).append((source, event))
                inside = _node_at(source, level, owner, clusters) if source in owner else None
                preds.setdefault(node, {}).setdefault(inside or _OUTSIDE, None)
                if level is None:
                    break
                node, level = _cluster_key(level), clusters[level].parent
    trees: dict[str, BTNode] = {}
    tree_ids: dict[str, str] = {}
    used_ids = {"MainTree"}
    for path in levels:
        tree_id = path
        n = 2
        while tree_id in used_ids:
            tree_id = f"{path}#{n}"
            n += 1
        used_ids.add(tree_id)
        tree_ids[path] = tree_id

    def leaf_or_subtree(key: str) -> BTNode:
        if key.startswith("s:"):
            return writer.state_leaf(key[2:])
        path = key[2:]
        return BTNode(
            type="SubTree", kind=NodeKind.SUBTREE, name=path, attrs={"ID": tree_ids[path]}
        )

    def guard(key: str) -> BTNode:
        label = key[2:]
        pairs = ";".join(f"{writer.esc(s)}/{writer.esc(e)}" for s, e in guard_pairs[key])
        return BTNode(
            type="LebtGuard",
            kind=NodeKind.CONDITION,
            name=f"Enter_{label}",
            attrs={"target": label, "pairs": pairs},
        )

    def build_level(cluster: _Cluster) -> BTNode:
        members = cluster.members
        roots = [
            k
            for k in members
            if k.startswith("c:")
            or _OUTSIDE in preds.get(k, {_OUTSIDE: None})
            or len(preds.get(k, ())) >= 2
        ]
        root_set = set(roots)
        below: dict[str, list[str]] = {}
        for key in members:
            if key not in root_set:
                (only,) = preds[key]
                below.setdefault(only, []).append(key)
        roots.extend(_bound_levels(roots, below))

        def selector(key: str) -> tuple[BTNode, BTNode | None]:
            label = key[2:]
            body_head = leaf_or_subtree(key)
            children = below.get(key, [])
            if not children:
                return BTNode(
                    type="Fallback",
                    kind=NodeKind.CONTROL,
                    name=f"{label}_selector",
                    children=[guard(key), body_head],
                ), None
            shape = "chain" if len(children) == 1 else "branch"
            body = BTNode(
                type="Sequence",
                kind=NodeKind.CONTROL,
                name=f"{label}_{shape}",
                children=[body_head],
            )
            return BTNode(
                type="Fallback",
                kind=NodeKind.CONTROL,
                name=f"{label}_selector",
                children=[guard(key), body],
            ), body

        name = ROOT_NAME if cluster.path == "" else f"{cluster.path}_LEBT"
        level_root = BTNode(type="Sequence", kind=NodeKind.CONTROL, name=name)
        pending: list[tuple[str, BTNode]] = []
        for key in roots:
            sel, body = selector(key)
            level_root.children.append(sel)
            if body is not None:
                pending.append((key, body))
        while pending:
            key, body = pending.pop()
            for child in below[key]:
                sel, child_body = selector(child)
                body.children.append(sel)
                if child_body is not None:
                    pending.append((child, child_body))
        return level_root

    # lowest level first, so every SubTree's tree exists before the level that references it
    for path in sorted(levels, key=lambda p: -clusters[p].depth):
        trees[path] = build_level(clusters[path])
    main = build_level(top)
    doc = BTDocument(main_tree="MainTree")
    doc.trees["MainTree"] = BehaviorTree("MainTree", main)
    for path in levels:
        doc.trees[tree_ids[path]] = BehaviorTree(tree_ids[path], trees[path])
    doc.node_models.update(lebt_node_models())
    stats = {
        "states": len(flat.states),
        "transitions": sum(len(v) for v in structure.exits.values()),
        "entry": structure.entry,
        "subtrees": len(levels),
        "parallel_subtrees": len(parallel),
        "levels": 1 + max((c.depth + 1 for p, c in clusters.items() if p), default=0),
        "flattened": True,
        "hierarchy": "subtrees",
        "nodes": sum(1 for _tree, _node in doc.nodes()),
    }
    return ConversionResult(doc, "rules", "fsm->bt", stats, warnings)


def _bound_levels(roots: list[str], below: dict[str, list[str]]) -> list[str]:
    """The nodes to promote to roots of their level so that no selector nests deeper than
    ``MAX_SELECTOR_LEVELS`` (``structure.bound_depth``'s rule; taken out of ``below`` here),
    in the order a walk from the roots meets them. O(nodes of the level), no recursion."""
    promoted: list[str] = []
    queue = [(key, 1) for key in roots]
    for key, level in queue:  # the list grows while it is read
        children = below.get(key)
        if not children:
            continue
        if level + 1 > MAX_SELECTOR_LEVELS:
            promoted.extend(children)
            queue.extend((child, 1) for child in children)
            del below[key]
        else:
            queue.extend((child, level + 1) for child in children)
    return promoted


def fsm_to_bt(
    fsm: FSM, *, style: str = "paper", hierarchy: str = "subtrees", **options: object
) -> ConversionResult:
    """The rules engine's FSM -> BT: SubTrees per composite state, or one flat LEBT."""
    if hierarchy not in HIERARCHY_MODES:
        raise UnsupportedError(
            f"hierarchy mode '{hierarchy}' (offered: {', '.join(HIERARCHY_MODES)})"
        )
    if hierarchy == "flatten":
        return fsm_to_lebt(fsm, style=style, **options)
    return fsm_to_subtree_bt(fsm, style=style, **options)
