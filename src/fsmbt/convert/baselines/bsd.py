"""BSD: the explicit state-variable mapping of Colledanchise & Ögren (T-RO 2017; their book,
"FSMs vs BTs"), both directions. Choices the publications leave open: docs/baselines.md.

FSM -> BT: the FSM's current state lives in a blackboard variable. The root is a selector
(``ReactiveFallback``: the book's Fallback is reactive, docs/semantics.md, 'Names') with, per reachable
state ``s``, one guarded subtree ``ReactiveSequence(SvIsState(s), SvEntryAction(s),
SvTransition(s))``: 4 nodes and 4 edges per state, plus the root: 8M+1 graphical elements. The
transition leaf holds all of ``s``'s outgoing transitions and sets the state variable. An FSM
with an initial event gets one more subtree for the start pseudo-state, without an action leaf
(``ReactiveSequence(SvIsState(Start), SvTransition(Start))``). The leaves run as
``fsmbt.semantics.state_variable_runtime`` says; the checker pairs them with the FSM there.

BT -> FSM: the classic direct mapping, one state per leaf (action = the leaf's label), the
final states ``SUCCESS``/``FAILURE`` for the root's result, and transitions by return status:
in a Sequence a child's success enters the next child's first leaf and its failure leaves the
Sequence failing (dually for a Fallback); ``running`` re-ticks the same leaf, or, under a
reactive node, restarts the outermost reactive ancestor at its first leaf. Inverter,
ForceSuccess and ForceFailure rewire outcomes. Exact for trees whose reactive nodes contain no
plain control node (a plain Sequence/Fallback below a reactive node resumes its running child,
memory that one state per leaf cannot hold: the checker then reports a counterexample).

Complexity: O(S + T) for FSM -> BT; O(N) for BT -> FSM (explicit stacks, no recursion).
"""

from __future__ import annotations

from fsmbt.convert.baselines.common import (
    EV_FAILURE,
    EV_RUNNING,
    EV_SUCCESS,
    FAILURE,
    REACTIVE_CONTROLS,
    SUCCESS,
    Cont,
    check_baseline_node,
    control,
    exits_of,
    leaf_node,
    prepare_fsm,
    sv_node_models,
)
from fsmbt.convert.engines import register_engine
from fsmbt.convert.result import ConversionResult
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM, State
from fsmbt.semantics import state_variable_runtime as sv
from fsmbt.semantics.leaf_machine import leaf_label
from fsmbt.semantics.nodes import SEQUENCE_TYPES, rewired

ENGINE = "bsd"


# -- FSM -> BT ---------------------------------------------------------------------------------
def fsm_to_bsd(fsm: FSM, **_options: object) -> ConversionResult:
    """One guarded subtree per state under a root selector (see the module docstring)."""
    flat, reachable, warnings = prepare_fsm(fsm)
    root = control("ReactiveFallback", "BSD", [])
    start = flat.start_name or "__start__"
    if flat.initial_event is not None and flat.initial is not None:
        root.children.append(
            control(
                "ReactiveSequence",
                f"{start}_subtree",
                [
                    leaf_node(sv.IS_STATE, f"Is_{start}", state=start, initial="true"),
                    leaf_node(
                        sv.TRANSITION,
                        f"{start}_transitions",
                        state=start,
                        transitions=sv.encode_transitions([(flat.initial_event, flat.initial)]),
                        final="false",
                    ),
                ],
            )
        )
    for name in reachable:
        state = flat.states[name]
        initial = "true" if name == flat.initial and flat.initial_event is None else "false"
        root.children.append(
            control(
                "ReactiveSequence",
                f"{name}_subtree",
                [
                    leaf_node(sv.IS_STATE, f"Is_{name}", state=name, initial=initial),
                    leaf_node(sv.ENTRY_ACTION, name, state=name, action=state.action or ""),
                    leaf_node(
                        sv.TRANSITION,
                        f"{name}_transitions",
                        state=name,
                        transitions=sv.encode_transitions(exits_of(flat, name)),
                        final="true" if state.final else "false",
                    ),
                ],
            )
        )
    doc = BTDocument.single(root)
    doc.node_models.update(sv_node_models((sv.IS_STATE, sv.ENTRY_ACTION, sv.TRANSITION)))
    nodes = sum(1 for _ in root.walk())
    stats = {
        "states": len(reachable),
        "nodes": nodes,
        "start_subtree": flat.initial_event is not None,
    }
    return ConversionResult(doc, ENGINE, "fsm->bt", stats, warnings)


# -- BT -> FSM ---------------------------------------------------------------------------------
def _leaf_names(root: BTNode) -> tuple[dict[int, str], dict[int, BTNode]]:
    """A unique state name per leaf (its label, ``#2``... on repeats) and each node's leftmost
    leaf (the leaf a fresh tick of the node reaches first), both by ``id(node)``."""
    names: dict[int, str] = {}
    used: set[str] = {SUCCESS, FAILURE}
    for node in root.walk():
        check_baseline_node(node)
        if node.is_leaf:
            base = leaf_label(node)
            name, n = base, 2
            while name in used:
                name, n = f"{base}#{n}", n + 1
            used.add(name)
            names[id(node)] = name
    leftmost: dict[int, BTNode] = {}
    order = list(root.walk())
    for node in reversed(order):  # children before parents
        leftmost[id(node)] = node if node.is_leaf else leftmost[id(node.children[0])]
    return names, leftmost


def rewire(node: BTNode, cont: Cont) -> Cont:
    """The continuation a transparent decorator passes to its child."""
    return Cont(*rewired(node.type, cont.success, cont.failure))


def bt_to_bsd_fsm(doc: BTDocument, *, loop: bool = False, **_options: object) -> ConversionResult:
    """One state per leaf, transitions by return status (see the module docstring)."""
    from fsmbt.convert.compress import inline_subtrees

    root = inline_subtrees(doc)
    names, leftmost = _leaf_names(root)
    fsm = FSM(name=f"{doc.main.id}_bsd")
    fsm.add_state(State(SUCCESS, action=SUCCESS, final=True))
    fsm.add_state(State(FAILURE, action=FAILURE, final=True))
    fsm.initial = names[id(leftmost[id(root)])]
    # work items: (node, continuation, restart entry for "running" or None)
    stack: list[tuple[BTNode, Cont, str | None]] = [(root, Cont(SUCCESS, FAILURE), None)]
    pending: list[tuple[str, str, str]] = []
    while stack:
        node, cont, restart = stack.pop()
        if node.is_leaf:
            name = names[id(node)]
            fsm.add_state(State(name, action=leaf_label(node)))
            pending.append((name, EV_SUCCESS, cont.success))
            pending.append((name, EV_FAILURE, cont.failure))
            if node.kind is NodeKind.ACTION:
                pending.append((name, EV_RUNNING, restart or name))
            continue
        if node.kind is NodeKind.DECORATOR:
            stack.append((node.children[0], rewire(node, cont), restart))
            continue
        if node.type in REACTIVE_CONTROLS and restart is None:
            restart = names[id(leftmost[id(node)])]
        is_sequence = node.type in SEQUENCE_TYPES
        kids = node.children
        for index, child in enumerate(kids):
            after = names[id(leftmost[id(kids[index + 1])])] if index + 1 < len(kids) else None
            if is_sequence:
                child_cont = Cont(after or cont.success, cont.failure)
            else:
                child_cont = Cont(cont.success, after or cont.failure)
            stack.append((child, child_cont, restart))
    # states first (SUCCESS/FAILURE, then leaves in tick order), then transitions
    leaves = [fsm.states.pop(n) for n in list(fsm.states) if n not in (SUCCESS, FAILURE)]
    order = {names[id(n)]: i for i, n in enumerate(x for x in root.walk() if x.is_leaf)}
    for state in sorted(leaves, key=lambda s: order[s.name]):
        fsm.states[state.name] = state
    for source, event, target in sorted(pending, key=lambda p: order[p[0]]):
        fsm.add_transition(source, event, target)
    stats = {"leaves": len(names), "states": len(fsm.states), "transitions": len(fsm.transitions)}
    # ``loop`` needs nothing here: the checker reads SUCCESS/FAILURE as "tick the root again"
    return ConversionResult(fsm, ENGINE, "bt->fsm", stats, [])


register_engine(
    ENGINE,
    fsm_to_bsd,
    bt_to_bsd_fsm,
    "Colledanchise & Ögren's explicit state-variable mapping (baseline)",
)
