"""FSM -> BT: the loop-execution behavior tree (LEBT) of the paper, built exactly (DESIGN §3).

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
   ..., selector(ck))`` - a chain for k = 1, a branch for k >= 2 - built recursively (with an
   explicit stack: a 100 000-state chain is 200 000 levels deep).

Leaves are named for people: the guard of ``C`` is ``Enter_C``, the state leaf is ``C``; the
selector is ``C_selector`` and the body ``C_chain`` / ``C_branch``. The document declares
``LebtGuard`` and ``LebtState`` and their ports in its ``TreeNodesModel`` (Groot2).

Only the paper's structure is offered: a "compact" style (a chain as one flat Sequence) changes
what the tree returns when an event leaves the chain (the flat Sequence fails where the nested
Fallbacks succeed), so it is not macro-step equivalent under the LEBT protocol and is refused.

Complexity: O(S + T) time and memory for S states and T transitions (after flattening).
"""

from __future__ import annotations

from fsmbt.convert.engines import ConversionResult
from fsmbt.convert.structure import LebtStructure, analyse
from fsmbt.model.bt import BTDocument, BTNode, NodeModel, PortModel
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.flatten import flatten, needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.semantics.lebt_spec import GUARD_TYPE, STATE_TYPE, GuardSpec, StateSpec

STYLES = ("paper",)
ROOT_NAME = "LEBT"


def lebt_node_models() -> dict[str, NodeModel]:
    """``TreeNodesModel`` entries for the two LEBT leaf types (so Groot2 knows them)."""
    return {
        GUARD_TYPE: NodeModel(GUARD_TYPE, NodeKind.CONDITION, [
            PortModel("target", "input", description="the state this guard enters"),
            PortModel("pairs", "input",
                      description="source/event pairs entering the target, ';'-separated"),
        ]),
        STATE_TYPE: NodeModel(STATE_TYPE, NodeKind.ACTION, [
            PortModel("state", "input", description="the FSM state"),
            PortModel("action", "input", description="the state's action (empty = none)"),
            PortModel("final", "input", description="true when the state is final"),
            PortModel("exits", "input", description="events leaving the state, ';'-separated"),
        ]),
    }


def _guard(structure: LebtStructure, state: str) -> BTNode:
    spec = GuardSpec(state, tuple(structure.guard_pairs[state]))
    return BTNode(type=GUARD_TYPE, kind=NodeKind.CONDITION, name=f"Enter_{state}",
                  attrs=spec.to_attrs())


def _state_leaf(fsm: FSM, structure: LebtStructure, state: str) -> BTNode:
    model_state = fsm.states[state]
    spec = StateSpec(state, model_state.action, model_state.final,
                     tuple(structure.exits[state]))
    return BTNode(type=STATE_TYPE, kind=NodeKind.ACTION, name=state, attrs=spec.to_attrs())


def _selector(fsm: FSM, structure: LebtStructure, state: str) -> tuple[BTNode, BTNode | None]:
    """``Fallback(guard, body)``; returns it and the body Sequence to fill (None = leaf body)."""
    leaf = _state_leaf(fsm, structure, state)
    selector = BTNode(type="Fallback", kind=NodeKind.CONTROL, name=f"{state}_selector")
    selector.children.append(_guard(structure, state))
    below = structure.children.get(state, [])
    if not below:
        selector.children.append(leaf)
        return selector, None
    shape = "chain" if len(below) == 1 else "branch"
    body = BTNode(type="Sequence", kind=NodeKind.CONTROL, name=f"{state}_{shape}",
                  children=[leaf])
    selector.children.append(body)
    return selector, body


def build_lebt(fsm: FSM, structure: LebtStructure) -> BTNode:
    """The LEBT root for a flat FSM and its recognised structure (iterative)."""
    root = BTNode(type="Sequence", kind=NodeKind.CONTROL, name=ROOT_NAME)
    pending: list[tuple[str, BTNode]] = []
    for state in structure.roots:
        selector, body = _selector(fsm, structure, state)
        root.children.append(selector)
        if body is not None:
            pending.append((state, body))
    while pending:
        state, body = pending.pop()
        for child in structure.children[state]:
            selector, child_body = _selector(fsm, structure, child)
            body.children.append(selector)
            if child_body is not None:
                pending.append((child, child_body))
    return root


def tree_depth(root: BTNode) -> int:
    """Levels of nodes on the longest root-to-leaf path (root = 1), without recursion."""
    deepest = 0
    stack = [(root, 1)]
    while stack:
        node, level = stack.pop()
        deepest = max(deepest, level)
        stack.extend((child, level + 1) for child in node.children)
    return deepest


def fsm_to_lebt(fsm: FSM, *, style: str = "paper", **_options: object) -> ConversionResult:
    """Convert an FSM (flat or hierarchical) into its LEBT document."""
    if style not in STYLES:
        raise UnsupportedError(f"LEBT style '{style}' (offered: {', '.join(STYLES)}); a compact "
                               "chain is not macro-step equivalent under the LEBT protocol")
    warnings: list[str] = []
    flat = fsm
    if needs_flattening(fsm):
        flat = flatten(fsm)
        warnings.append(f"hierarchical FSM flattened to {len(flat.states)} states before "
                        "conversion")
    structure = analyse(flat)
    if structure.unreachable:
        shown = ", ".join(structure.unreachable[:10])
        more = "" if len(structure.unreachable) <= 10 else f" (+{len(structure.unreachable) - 10})"
        warnings.append(f"dropped {len(structure.unreachable)} unreachable state(s): {shown}{more}")
    root = build_lebt(flat, structure)
    doc = BTDocument.single(root)
    doc.node_models.update(lebt_node_models())
    below = [len(children) for children in structure.children.values()]
    stats = {
        "states": len(structure.predecessors),
        "transitions": sum(len(v) for v in structure.exits.values()),
        "entry": structure.entry,
        "loop_states": len(structure.loop_states),
        "root_subtrees": len(structure.roots),
        "chains": below.count(1),
        "branches": sum(1 for count in below if count >= 2),
        "unreachable_dropped": len(structure.unreachable),
        "flattened": flat is not fsm,
        "nodes": sum(1 for _ in root.walk()),
        "depth": tree_depth(root),
    }
    return ConversionResult(doc, "rules", "fsm->bt", stats, warnings)
