"""FSM -> BT in the structured style: the tree a person would write for an outcome-driven machine
(docs/conversion.md, "The structured style"; the outcome rules: docs/semantics.md §11).

Steps: read the machine as outcome-driven (``semantics.outcome_view``: every violation is a
located ``OutcomeError``, exit 2); structure each region (``regions``), or give it the flag form
(``flags``) when no structured form exists; the top-level machine is the main
``<BehaviorTree>`` itself, each container one ``<BehaviorTree>`` used by one ``SubTree`` node;
every leaf type is declared in ``<TreeNodesModel>``; a Concurrence the outcome view reads in
rounds is a ``Parallel`` / ``ParallelAll`` over its children's leaves and SubTrees (``_parallel``;
a container child's loops return RUNNING when they go round, ``RegionStructurer(
yielding_loops=True)``; the rule: docs/semantics.md §11, "Concurrences: Parallel or product",
"Container children"). The result's ``stats`` count what was found
and ``stats["summary"]`` says it in one line ("structured: 3 sequences, 1 fallback, ...").

Cost: the regions' structuring (``regions``) plus O(nodes).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Mapping

from fsmbt.convert.result import ConversionResult
from fsmbt.convert.structured import builder
from fsmbt.convert.structured.flags import flag_form
from fsmbt.convert.structured.regions import RegionStructurer, Unstructured
from fsmbt.convert.structured.schedule import exit_terms, read_structured_view
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode, NodeModel
from fsmbt.model.fsm import FSM
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.semantics.outcome_view import OutcomeView, Region, Unit

STYLE = "structured"


def fsm_to_structured(
    fsm: FSM, *, outcomes: str | Mapping[str, str] | None = None, **_options: object
) -> ConversionResult:
    """Convert an outcome-driven machine into its structured tree.

    Args:
        fsm: the machine (flat or hierarchical).
        outcomes: the per-machine outcome rules (``"arrived=success,lost=failure"``).

    Raises:
        OutcomeError: the machine is not outcome-driven, or the option maps an outcome to
        both results (the message names the state or the option).
    """
    rules = OutcomeRules.from_option(outcomes)
    view = read_structured_view(fsm, rules)
    return structured_result(view)


def structured_result(view: OutcomeView) -> ConversionResult:
    """The structured conversion of an outcome view already read."""
    models: dict[str, NodeModel] = {}
    tree_ids = _tree_ids(view)

    def emit(unit: Unit) -> BTNode:
        if unit.container:
            return builder.subtree(tree_ids[unit.path], unit.label)
        return builder.leaf(unit, models)

    trees: dict[str, BehaviorTree] = {}
    under = _under_parallel(view)
    flagged: list[str] = []
    flags: list[str] = []
    for path, region in view.regions.items():
        if region.parallel:
            trees[tree_ids[path]] = BehaviorTree(tree_ids[path], _parallel(region, emit))
            continue
        exits = exit_terms(region, view.root_result)
        structurer = RegionStructurer(region, emit, exits, yielding_loops=path in under)
        try:
            root = structurer.structure()
            flags.extend(structurer.flags)
        except Unstructured as why:
            root = flag_form(region, emit, exits)
            flagged.append(f"{path or view.fsm.name}: {why} (flag '{region.pc_key}')")
        trees[tree_ids[path]] = BehaviorTree(tree_ids[path], root)
    doc = BTDocument(trees=trees, main_tree=tree_ids[""], node_models=models)
    counts = count_nodes(doc)
    stats: dict[str, object] = {
        "style": STYLE,
        **counts,
        "flags": len(flagged) + len(flags),
        "flag_forms": len(flagged),
        "flag_loops": len(flags),
        "lebt_blocks": 0,
        "dispatches": sum(
            1 for r in view.regions.values() for u in r.units.values() if u.dispatch
        ),  # fmt: skip
        "halts": view.halts,
        "order_choices": len(view.order_choices),
        "fully_structured": not flagged and not flags,
        "subtrees": len(trees) - 1,
    }
    stats["summary"] = summary(stats)
    warnings = [  # the order choices are named in the verdict (verify.outcome_pairing)
        *(f"flag form: {f}" for f in flagged),
        *(f"flag: {f}" for f in flags),
        *_concurrences(view),
    ]
    if view.halts:
        warnings.append(
            f"'preempted' modelled as the tree being halted ({view.halts} outcome(s)); "
            "docs/semantics.md §11"
        )
    return ConversionResult(doc, STYLE, "fsm->bt", stats=stats, warnings=warnings)


def _parallel(region: Region, emit: Callable[[Unit], BTNode]) -> BTNode:
    """A Concurrence read in rounds: its parallel form over its children's leaves and
    SubTrees, in the order they were added (docs/semantics.md §11, "Concurrences: Parallel or product")."""
    concurrence = region.concurrence
    assert concurrence is not None and concurrence.form is not None
    form = concurrence.form
    children = [region.units[label] for label in concurrence.labels]
    node = builder.control(form.kind, *(emit(u) for u in children), **dict(form.ports))
    node = builder.decorator(form.wrapper, node) if form.wrapper else node
    callback = concurrence.callback_state
    if callback is None:
        return node
    return builder.control("Sequence", node, emit(region.units[callback]))


def _under_parallel(view: OutcomeView) -> set[str]:
    """The regions of a Parallel's container children (their loops return RUNNING when they
    go round: ``schedule``)."""
    tops = [u.path for r in view.regions.values() if r.parallel
            for u in r.units.values() if u.container]  # fmt: skip
    return {p for p in view.regions for top in tops if p == top or p.startswith(top + "/")}


def _concurrences(view: OutcomeView) -> list[str]:
    """Name every Concurrence: the parallel form it became, or why it is kept
    as its product machine (the named fallback form: one leaf per combination of its
    children's progress)."""
    named = []
    for path, region in view.regions.items():
        concurrence = region.concurrence
        if concurrence is None:
            continue
        where = f"{concurrence.cls} '{path or view.fsm.name}'"
        if concurrence.form is not None:
            callback = concurrence.callback_state
            then = f", then its outcome_cb's leaf '{callback}'" if callback else ""
            named.append(
                f"{where}: a {concurrence.form.describe()} over its children{then}, read in "
                'rounds (docs/semantics.md §11, "Concurrences: Parallel or product")'
            )
        else:
            named.append(
                f"{where}: kept as its product machine (one leaf per combination of its "
                f"children's progress), not a Parallel: {concurrence.why}"
            )
    return named


def _tree_ids(view: OutcomeView) -> dict[str, str]:
    ids: dict[str, str] = {}
    used: set[str] = set()
    for path, region in view.regions.items():
        base = builder.type_id(view.fsm.name or "MainTree") if not path else builder.type_id(
            region.owner.label if region.owner is not None else path)  # fmt: skip
        tree_id, n = base, 2
        while tree_id in used:
            tree_id, n = f"{base}_{n}", n + 1
        used.add(tree_id)
        ids[path] = tree_id
    return ids


_COUNTED = {
    "Sequence": "sequences",
    "Fallback": "fallbacks",
    "IfThenElse": "conditionals",
    "RetryUntilSuccessful": "retry_loops",
    "KeepRunningUntilFailure": "repeat_loops",
    "Inverter": "inverters",
    "ForceSuccess": "forced",
    "ForceFailure": "forced",
    "Parallel": "parallels",
    "ParallelAll": "parallels",
}


def count_nodes(doc: BTDocument) -> dict[str, int]:
    """Control nodes by family, all nodes, leaves, and the deepest tree's depth."""
    counts: Counter[str] = Counter({v: 0 for v in _COUNTED.values()})
    counts["switches"] = 0
    nodes = leaves = depth = 0
    for tree in doc.trees.values():
        if tree.root is None:
            continue
        stack: list[tuple[BTNode, int]] = [(tree.root, 1)]
        while stack:
            node, level = stack.pop()
            nodes += 1
            depth = max(depth, level)
            if not node.children:
                leaves += 1
            if node.type in _COUNTED:
                counts[_COUNTED[node.type]] += 1
            elif node.type.startswith("Switch"):
                counts["switches"] += 1
            stack.extend((child, level + 1) for child in node.children)
    return {**counts, "nodes": nodes, "leaves": leaves, "depth": depth}


def _plural(n: object, word: str) -> str:
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def summary(stats: Mapping[str, object]) -> str:
    """The summary line: the style and what it found."""
    loops = int(stats["retry_loops"]) + int(stats["repeat_loops"])  # type: ignore[call-overload]
    parts = [
        _plural(stats["sequences"], "sequence"),
        _plural(stats["fallbacks"], "fallback"),
        _plural(stats["conditionals"], "if-then-else"),
        _plural(stats["switches"], "switch").replace("switchs", "switches"),
        _plural(loops, "retry loop"),
        _plural(stats.get("parallels", 0), "parallel"),
        _plural(stats["subtrees"], "subtree"),
        _plural(stats["flags"], "flag"),
        f"{stats['lebt_blocks']} LEBT blocks",
    ]
    return f"{STYLE}: " + ", ".join(parts)
