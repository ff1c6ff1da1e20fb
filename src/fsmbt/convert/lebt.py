"""FSM -> BT: the loop-execution behavior tree (LEBT) of the paper, built exactly (docs/conversion.md, 'FSM -> BT: the loop-execution BT').

Steps (``docs/conversion.md`` has the worked A-J example):
1. flatten a hierarchical FSM (``model.flatten``; its states are named ``Composite/inner``);
2. recognise the structure (``structure.analyse``): entry state, loop states (in-degree >= 2),
   ordinary states linked below their only predecessor, unreachable states dropped with a warning;
3. the root is a ``Sequence`` with one selector subtree per root state (entry first, then loop
   states in declaration order);
4. selector subtree of state ``s`` = ``Fallback(guard(s), body(s))``; ``guard(s)`` is one
   ``LebtGuard`` holding every (source, event) pair entering ``s`` (the start pseudo-state's
   initialisation pair included for the entry state); ``body(s)`` is the ``LebtState`` leaf of
   ``s`` alone when no ordinary state hangs below ``s``, else ``Sequence(leaf(s), selector(c1),
   ..., selector(ck))`` - a chain for k = 1, a branch for k >= 2 - nested without recursion;
6. depth bound (``structure.bound_depth``, docs/semantics.md §5 "Depth-bounded LEBT"): a state
   whose selector would nest deeper than ``MAX_SELECTOR_LEVELS`` (98) is promoted to a root
   selector instead, so every written ``<BehaviorTree>`` nests at most 200 XML levels and
   BehaviorTree.CPP loads it (a 100 000-state chain: 1 021 root selectors, depth 197);
   machines that shallow keep the paper's exact shape.

Leaves are named for people: the guard of ``C`` is ``Enter_C``, the state leaf is ``C``; the
selector is ``C_selector`` and the body ``C_chain`` / ``C_branch``. The document declares
``LebtGuard`` and ``LebtState`` and their ports in its ``TreeNodesModel`` (Groot2).

Only the paper's structure is offered: a "compact" style (a chain as one flat Sequence) changes
what the tree returns when an event leaves the chain (the flat Sequence fails where the nested
Fallbacks succeed), so it is not macro-step equivalent under the LEBT protocol and is refused.

How it is built (``_build``; the tree is the one the steps above define): the nodes of each
state are made in declaration order - the order the FSM's objects lie in memory - and the
selectors are then hung below their predecessor's body, walking the structure's flat link
arrays; a body's child list is made at its final length; guard texts are made in source order
and dealt out to their targets, exit texts in source order; escaping is skipped when one scan
finds nothing to escape; nodes are constructed with positional fields (docs/conversion.md,
'Benchmark' and 'Cost of FSM -> BT').

Complexity: O(S + T) time and memory for S states and T transitions (after flattening); about
1.3 KB and 7 collector-tracked objects per state in the result.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Iterable, Sequence

from fsmbt.convert.perf import without_gc_pauses
from fsmbt.convert.result import ConversionResult
from fsmbt.convert.structure import LebtStructure, analyse, bound_depth
from fsmbt.model.bt import BTDocument, BTNode, NodeModel, PortModel
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.flatten import flatten, needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE, escape

STYLES = ("paper",)
ROOT_NAME = "LEBT"
SEQUENCE, FALLBACK = "Sequence", "Fallback"

#: The leading ``BTNode`` fields in order: the builder passes them by position, because the
#: generated dataclass ``__init__`` is slower to call with keywords and the LEBT makes 3-4 nodes
#: per state. ``tests/convert/test_conv_linear.py`` asserts the order.
NODE_FIELDS = ("type", "kind", "name", "attrs", "children")


def lebt_node_models() -> dict[str, NodeModel]:
    """``TreeNodesModel`` entries for the two LEBT leaf types (so Groot2 knows them)."""
    return {
        GUARD_TYPE: NodeModel(
            GUARD_TYPE,
            NodeKind.CONDITION,
            [
                PortModel("target", "input", description="the state this guard enters"),
                PortModel(
                    "pairs",
                    "input",
                    description="source/event pairs entering the target, ';'-separated",
                ),
            ],
        ),
        STATE_TYPE: NodeModel(
            STATE_TYPE,
            NodeKind.ACTION,
            [
                PortModel("state", "input", description="the FSM state"),
                PortModel("action", "input", description="the state's action (empty = none)"),
                PortModel("final", "input", description="true when the state is final"),
                PortModel("exits", "input", description="events leaving the state, ';'-separated"),
            ],
        ),
    }


class LebtLeafWriter:
    """Writes the guard and state leaves' ports exactly as ``GuardSpec.to_attrs`` /
    ``StateSpec.to_attrs`` do, escaping each distinct name once (names repeat: a state is the
    source of all its outgoing pairs, an event occurs on many transitions). Asserted equal to
    the spec classes in the tests.

    Public because both LEBT builders use it: ``fsm_to_lebt`` here and the hierarchical
    ``fsmbt.convert.hfsm_to_bt`` (one writer per flat machine and its ``LebtStructure``)."""

    def __init__(self, fsm: FSM, structure: LebtStructure) -> None:
        self.fsm = fsm
        self.structure = structure
        self._escaped: dict[str, str] = {}

    def esc(self, text: str) -> str:
        known = self._escaped.get(text)
        if known is None:
            known = escape(text) if ("\\" in text or ";" in text or "/" in text) else text
            self._escaped[text] = known
        return known

    def guard(self, state: str) -> BTNode:
        esc = self.esc
        pairs = ";".join(
            f"{esc(source)}/{esc(event)}" for source, event in self.structure.guard_pairs[state]
        )
        return BTNode(
            type=GUARD_TYPE,
            kind=NodeKind.CONDITION,
            name=f"Enter_{state}",
            attrs={"target": state, "pairs": pairs},
        )

    def state_leaf(self, state: str) -> BTNode:
        model_state = self.fsm.states[state]
        esc = self.esc
        attrs = {
            "state": state,
            "action": model_state.action or "",
            "final": "true" if model_state.final else "false",
            "exits": ";".join(esc(event) for event in self.structure.exits[state]),
        }
        return BTNode(type=STATE_TYPE, kind=NodeKind.ACTION, name=state, attrs=attrs)

    def selector(self, state: str) -> tuple[BTNode, BTNode | None]:
        """``Fallback(guard, body)``; returns it and the body Sequence to fill (None = leaf)."""
        leaf = self.state_leaf(state)
        below = self.structure.children[state]
        if not below:
            return BTNode(
                type="Fallback",
                kind=NodeKind.CONTROL,
                name=f"{state}_selector",
                children=[self.guard(state), leaf],
            ), None
        shape = "chain" if len(below) == 1 else "branch"
        body = BTNode(
            type="Sequence", kind=NodeKind.CONTROL, name=f"{state}_{shape}", children=[leaf]
        )
        return BTNode(
            type="Fallback",
            kind=NodeKind.CONTROL,
            name=f"{state}_selector",
            children=[self.guard(state), body],
        ), body


def build_lebt(fsm: FSM, structure: LebtStructure) -> BTNode:
    """The LEBT root for a flat FSM and its recognised structure (iterative)."""
    return _build(fsm, structure)[0]


def _needs_escape(texts: Iterable[str]) -> bool:
    """Whether any text holds a character ``escape`` rewrites (one scan of their concatenation)."""
    joined = "".join(texts)
    return "\\" in joined or ";" in joined or "/" in joined


def _escaped_texts(structure: LebtStructure) -> tuple[list[str], Callable[[str], str]]:
    """The escaped name of every state (and, last, of the start pseudo-state) by index, and
    the event escaper: the identity when no name and no event needs escaping (the usual case,
    found by one scan), else ``escape`` once per distinct event."""
    sources = [*structure.names, structure.start]
    if not (
        _needs_escape(sources)
        or _needs_escape(structure.kept_events)
        or _needs_escape([structure.initial_event])
    ):
        return sources, str
    known: dict[str, str] = {}

    def esc_event(text: str) -> str:
        done = known.get(text)
        if done is None:
            done = known[text] = escape(text)
        return done

    return [escape(name) for name in sources], esc_event


def _gathered(
    count: int, keys: Iterable[int], texts: Iterable[str]
) -> list[str | list[str] | None]:
    """Per index, the texts given for it in order: one text alone (most states have one),
    several in a list, None for none."""
    gathered: list[str | list[str] | None] = [None] * count
    for key, text in zip(keys, texts):
        known = gathered[key]
        if known is None:
            gathered[key] = text
        elif type(known) is str:
            gathered[key] = [known, text]
        else:
            known.append(text)  # type: ignore[union-attr]
    return gathered


def _joined(texts: str | list[str] | None) -> str:
    """``;``-joined ``_gathered`` texts ("" for none)."""
    return texts if type(texts) is str else ";".join(texts or ())  # type: ignore[arg-type]


def _guard_pair_texts(
    structure: LebtStructure,
    esc_names: list[str],
    esc_event: Callable[[str], str],
    esc_events: Sequence[str],
) -> list[str | list[str] | None]:
    """Per state, its guard's ``source/event`` texts (escaped; see ``_gathered``), made in
    source order - where the source's name and its events are at hand - and dealt out to the
    targets: the start pair first for the entry state, then by source in declaration order
    and by the source's transitions (``LebtStructure.guard_ids``'s order). ``esc_events``:
    ``kept_events`` escaped."""
    texts: list[str | list[str] | None] = [None] * len(structure.names)
    texts[structure.entry_id] = (
        f"{esc_names[structure.start_id]}/{esc_event(structure.initial_event)}"
    )
    previous, prefix = -1, ""
    for source, target, event in zip(structure.kept_sources, structure.kept_targets, esc_events):
        if source != previous:
            previous, prefix = source, esc_names[source] + "/"
        known = texts[target]
        if known is None:
            texts[target] = prefix + event
        elif type(known) is str:
            texts[target] = [known, prefix + event]
        else:
            known.append(prefix + event)  # type: ignore[union-attr]
    return texts


def _build(fsm: FSM, structure: LebtStructure) -> tuple[BTNode, int, int]:
    """The LEBT root, its node count and depth.

    Built in two passes over the states in declaration order - the order their objects lie in
    memory - rather than in tree order (a random order for a random machine): pass 1 makes each
    placed state's guard, state leaf, selector and body; pass 2 hangs each link's child
    selector below its predecessor's body (flat lists, by index). The tree is the same as the
    tree-order construction of docs/conversion.md step 5. A selector on level ``L`` holds its
    guard and body on ``L + 1``; a body Sequence holds the state leaf and the child selectors
    on ``L + 2``: the depth is found by a walk over the links. O(S + T).
    """
    names = structure.names
    states = list(fsm.states.values())
    if len(states) != len(names):
        raise ValueError("the structure was not analysed from this FSM")
    esc_names, esc_event = _escaped_texts(structure)
    child_counts = structure.child_counts
    placed = structure.placed
    events = structure.kept_events
    if esc_event is not str:
        events = [esc_event(event) for event in events]
    pair_texts = _guard_pair_texts(structure, esc_names, esc_event, events)
    exit_texts = _gathered(len(names), structure.kept_sources, events)
    control, condition, action = NodeKind.CONTROL, NodeKind.CONDITION, NodeKind.ACTION
    selectors: list[BTNode | None] = [None] * len(names)
    bodies: list[list[BTNode] | None] = [None] * len(names)  # each body Sequence's children
    nodes = 1
    # a body's list is made at its final length - the leaf, then one slot per child selector,
    # filled in pass 2 - so no list grows (and none is over-allocated)
    for i in structure.reachable_ids:
        if not placed[i]:
            continue  # reached only through a transition that never fires: no predecessor
        name = names[i]
        state = states[i]
        # positional (type, kind, name, attrs, children): see NODE_FIELDS
        pairs = _joined(pair_texts[i])
        pair_texts[i] = None  # released here, while hot, not by a random-order sweep at the end
        guard = BTNode(GUARD_TYPE, condition, f"Enter_{name}", {"target": name, "pairs": pairs})
        leaf = BTNode(
            STATE_TYPE,
            action,
            name,
            {
                "state": name,
                "action": state.action or "",
                "final": "true" if state.final else "false",
                "exits": _joined(exit_texts[i]),
            },
        )
        below = child_counts[i]
        if below:
            if below == 1:
                body = BTNode(SEQUENCE, control, name + "_chain", {}, [leaf, None])  # type: ignore[list-item]
            else:
                body = BTNode(SEQUENCE, control, name + "_branch", {}, [leaf, *[None] * below])  # type: ignore[list-item]
            bodies[i] = body.children
            selectors[i] = BTNode(FALLBACK, control, name + "_selector", {}, [guard, body])
            nodes += 4
        else:
            selectors[i] = BTNode(FALLBACK, control, name + "_selector", {}, [guard, leaf])
            nodes += 3
    previous, slot = -1, 0
    for parent, child in zip(structure.child_sources, structure.child_targets):  # pass 2
        if parent != previous:
            previous, slot = parent, 1  # the links of one parent are consecutive
        else:
            slot += 1
        bodies[parent][slot] = selectors[child]  # type: ignore[index,assignment]
    root = BTNode(
        type="Sequence",
        kind=control,
        name=ROOT_NAME,
        children=[selectors[i] for i in structure.root_ids],  # type: ignore[misc]
    )
    return root, nodes, _lebt_depth(structure)


def _lebt_depth(structure: LebtStructure) -> int:
    """Levels of the LEBT (root = 1) from the structure alone, level by level over the flat
    link lists (each state's links found by offset, no per-state lists): root selectors are on
    level 2 and the selectors hung below a state's body two levels under its own, so with
    ``k`` levels of selectors the deepest ones are on level ``2k`` and - having nothing below
    - their leaves on ``2k + 1``."""
    counts = structure.child_counts
    first = array("l", [0]) * (len(counts) + 1)  # where each state's links start
    total = 0
    for state, count in enumerate(counts):
        first[state] = total
        total += count
    child_targets = structure.child_targets
    frontier: list[int] = list(structure.root_ids)
    levels = 0
    while frontier:
        levels += 1
        below: list[int] = []
        for state in frontier:
            count = counts[state]
            if count:
                start = first[state]
                below.extend(child_targets[start : start + count])
        frontier = below
    return 2 * levels + 1


def tree_depth(root: BTNode) -> int:
    """Levels of nodes on the longest root-to-leaf path (root = 1), without recursion."""
    deepest = 0
    stack = [(root, 1)]
    while stack:
        node, level = stack.pop()
        deepest = max(deepest, level)
        stack.extend((child, level + 1) for child in node.children)
    return deepest


@without_gc_pauses
def fsm_to_lebt(fsm: FSM, *, style: str = "paper", **_options: object) -> ConversionResult:
    """Convert an FSM (flat or hierarchical) into its LEBT document."""
    if style not in STYLES:
        raise UnsupportedError(
            f"LEBT style '{style}' (offered: {', '.join(STYLES)}); a compact "
            "chain is not macro-step equivalent under the LEBT protocol"
        )
    warnings: list[str] = []
    flat = fsm
    if needs_flattening(fsm):
        flat = flatten(fsm)
        warnings.append(
            f"hierarchical FSM flattened to {len(flat.states)} states before conversion"
        )
    structure = bound_depth(analyse(flat))
    promoted = (
        len(structure.root_ids)
        - 1
        - len([i for i in structure.loop_ids if i != structure.entry_id])
    )
    if structure.unreachable:
        shown = ", ".join(structure.unreachable[:10])
        more = "" if len(structure.unreachable) <= 10 else f" (+{len(structure.unreachable) - 10})"
        warnings.append(f"dropped {len(structure.unreachable)} unreachable state(s): {shown}{more}")
    root, node_count, depth = _build(flat, structure)
    doc = BTDocument.single(root)
    doc.node_models.update(lebt_node_models())
    counts = structure.child_counts
    stats = {
        "states": len(structure.reachable_ids),
        "transitions": len(structure.kept_sources),
        "entry": structure.entry,
        "loop_states": len(structure.loop_ids),
        "root_subtrees": len(structure.root_ids),
        "chains": counts.count(1),
        "branches": len(counts) - counts.count(0) - counts.count(1),
        "unreachable_dropped": len(structure.unreachable),
        "flattened": flat is not fsm,
        "nodes": node_count,
        "depth": depth,
    }
    if promoted:
        stats["depth_bound_roots"] = promoted  # docs/semantics.md §5, "Depth-bounded LEBT"
    return ConversionResult(doc, "rules", "fsm->bt", stats, warnings)
