"""CHDS-BT: the mappings of Marzinotto, Colledanchise, Smith & Ögren (ICRA 2014) between BTs and
controlled hybrid dynamical systems (CHDS), both directions. Choices the paper leaves open:
docs/baselines.md.

A CHDS has discrete modes, each with a controller, and switching guards with reset maps. Read as
an FSM: a mode per state (the controller = the state's action), a guard + reset per transition.

FSM -> BT: the root selector (``ReactiveFallback``, the paper's selector re-ticks from its first
child) holds first one switching subtree per transition ``q --e--> q'``:
``ReactiveSequence(SvGuard(q, e), SvAssign(q'))``, then one mode subtree per reachable state:
``ReactiveSequence(SvIsState(q), SvMode(q))`` (the mode's controller: RUNNING while the mode is
active, SUCCESS in a final mode). Transition-centred, unlike BSD's one subtree per state:
6T + 6M + 1 graphical elements. The initial event of an FSM with a start pseudo-state is one
more switching subtree (guard on the pseudo-state); the pseudo-state has no mode.

BT -> FSM: the paper's execution reading, compositional: every control node becomes a CHDS of
its own (a composite state holding a sub-FSM; k = number of control nodes), every leaf a mode
(an atomic state, action = its label) inside its parent's sub-FSM, wired by return status
(success/failure to the next sibling's entry or to the sub-FSM's ``SUCCESS``/``FAILURE`` end
state; a composite leaves by completion transitions with ``exit`` = that end state). ``running``
re-ticks the same leaf, or under a reactive node restarts the outermost reactive ancestor: the
sub-FSMs in between leave through a ``RUNNING`` end state, and that ancestor's sub-FSM re-enters
its first child. Inverter, ForceSuccess and ForceFailure rewire outcomes. Exact under the same
condition as BSD's (no plain control node below a reactive one).

Complexity: O(S + T) for FSM -> BT; O(N) for BT -> FSM (explicit stacks).
"""

from __future__ import annotations

from fsmbt.convert.baselines.bsd import rewire
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
from fsmbt.semantics.nodes import SEQUENCE_TYPES
from fsmbt.semantics.status import NodeStatus

ENGINE = "chds"
RESTART = NodeStatus.RUNNING.name  # the end state a reactive restart leaves through


# -- FSM -> BT ---------------------------------------------------------------------------------
def fsm_to_chds(fsm: FSM, **_options: object) -> ConversionResult:
    """Switching subtrees, then mode subtrees, under a root selector (module docstring)."""
    flat, reachable, warnings = prepare_fsm(fsm)
    root = control("ReactiveFallback", "CHDS", [])
    switches: list[BTNode] = []
    start = flat.start_name or "__start__"
    if flat.initial_event is not None and flat.initial is not None:
        switches.append(_switch(start, flat.initial_event, flat.initial, initial=True))
    for name in reachable:
        for event, target in exits_of(flat, name):
            switches.append(_switch(name, event, target, initial=False))
    modes = []
    for name in reachable:
        state = flat.states[name]
        initial = "true" if name == flat.initial and flat.initial_event is None else "false"
        modes.append(
            control(
                "ReactiveSequence",
                f"{name}_mode",
                [
                    leaf_node(sv.IS_STATE, f"In_{name}", state=name, initial=initial),
                    leaf_node(
                        sv.MODE,
                        name,
                        state=name,
                        action=state.action or "",
                        final="true" if state.final else "false",
                    ),
                ],
            )
        )
    root.children.extend(switches + modes)
    doc = BTDocument.single(root)
    doc.node_models.update(sv_node_models((sv.GUARD, sv.ASSIGN, sv.IS_STATE, sv.MODE)))
    stats = {
        "states": len(reachable),
        "switches": len(switches),
        "nodes": sum(1 for _ in root.walk()),
    }
    return ConversionResult(doc, ENGINE, "fsm->bt", stats, warnings)


def _switch(source: str, event: str, target: str, *, initial: bool) -> BTNode:
    return control(
        "ReactiveSequence",
        f"{source}_{event}_{target}",
        [
            leaf_node(
                sv.GUARD,
                f"{source}_on_{event}",
                state=source,
                event=event,
                initial="true" if initial else "false",
            ),
            leaf_node(sv.ASSIGN, f"to_{target}", target=target),
        ],
    )


# -- BT -> FSM ---------------------------------------------------------------------------------
class _Builder:
    """Builds one sub-FSM per control node, top-down with a work list."""

    def __init__(self, root: BTNode) -> None:
        self.owner: dict[int, int | None] = {}  # control node -> its outermost reactive ancestor
        self.needs_restart_exit: set[int] = set()  # control nodes whose sub-FSM has RUNNING end
        self.machines = 0
        self._mark_restarts(root)

    def _mark_restarts(self, root: BTNode) -> None:
        """For every leaf action under a reactive node, every control node strictly between it
        and its outermost reactive ancestor needs a ``RUNNING`` end state."""
        stack: list[tuple[BTNode, int | None, tuple[int, ...]]] = [(root, None, ())]
        while stack:
            node, reactive, chain = stack.pop()
            check_baseline_node(node)
            if node.is_leaf:
                if reactive is not None and node.kind is NodeKind.ACTION:
                    self.needs_restart_exit.update(chain[chain.index(reactive) + 1 :])
                continue
            if node.kind is NodeKind.CONTROL:
                if reactive is None and node.type in REACTIVE_CONTROLS:
                    reactive = id(node)
                self.owner[id(node)] = reactive
                chain = chain + (id(node),)
            for child in node.children:
                stack.append((child, reactive, chain))

    @staticmethod
    def unique_name(fsm: FSM, base: str) -> str:
        name, n = base, 2
        while name in fsm.states:
            name, n = f"{base}#{n}", n + 1
        return name

    def new_machine(self, name: str, node: BTNode | None, top: bool) -> FSM:
        self.machines += 1
        fsm = FSM(name=name)
        fsm.add_state(State(SUCCESS, action=SUCCESS if top else None, final=True))
        fsm.add_state(State(FAILURE, action=FAILURE if top else None, final=True))
        if node is not None and id(node) in self.needs_restart_exit:
            fsm.add_state(State(RESTART, action=None, final=True))
        fsm.initial = None
        return fsm

    def leaf_state(self, node: BTNode, machine: FSM, cont: Cont, restart: str | None) -> str:
        """An atomic state for a leaf; ``running`` goes to ``restart`` (None = itself)."""
        name = self.unique_name(machine, leaf_label(node))
        machine.add_state(State(name, action=leaf_label(node)))
        machine.add_transition(name, EV_SUCCESS, cont.success)
        machine.add_transition(name, EV_FAILURE, cont.failure)
        if node.kind is NodeKind.ACTION:
            machine.add_transition(name, EV_RUNNING, restart or name)
        return name


def _fill(builder: _Builder, node: BTNode, machine: FSM, work: list[tuple[BTNode, FSM]]) -> str:
    """Wire a control node's children into its own sub-FSM ``machine``; returns its entry."""
    owner = builder.owner[id(node)]
    is_sequence = node.type in SEQUENCE_TYPES
    # running: restart here when this node is the outermost reactive one; leave through the
    # RUNNING end when an outer reactive node owns the restart; else re-tick the leaf
    restart_here = owner == id(node)
    entry = SUCCESS if is_sequence else FAILURE
    first_entry_placeholder = "\x00first"
    for child in reversed(node.children):
        cont = Cont(entry, FAILURE) if is_sequence else Cont(SUCCESS, entry)
        while child.kind is NodeKind.DECORATOR:
            cont = rewire(child, cont)
            child = child.children[0]
        if child.is_leaf:
            restart = None
            if owner is not None and child.kind is NodeKind.ACTION:
                restart = first_entry_placeholder if restart_here else RESTART
            entry = builder.leaf_state(child, machine, cont, restart)
        else:
            name = builder.unique_name(machine, child.name or child.type)
            sub = builder.new_machine(name, child, top=False)
            machine.add_state(State(name, action=None, regions=[sub]))
            machine.add_transition(name, None, cont.success, exit=SUCCESS)
            machine.add_transition(name, None, cont.failure, exit=FAILURE)
            if RESTART in sub.states:
                target = first_entry_placeholder if restart_here else RESTART
                machine.add_transition(name, None, target, exit=RESTART)
            work.append((child, sub))
            entry = name
    for t in machine.transitions:
        if t.target == first_entry_placeholder:
            t.target = entry
    return entry


def bt_to_chds_fsm(doc: BTDocument, *, loop: bool = False, **_options: object) -> ConversionResult:
    """A hierarchical FSM with one sub-FSM per control node (see the module docstring)."""
    from fsmbt.convert.compress import inline_subtrees

    root = inline_subtrees(doc)
    builder = _Builder(root)
    top = builder.new_machine(f"{doc.main.id}_chds", None, top=True)
    work: list[tuple[BTNode, FSM]] = []
    top.initial = _top_entry(builder, root, top, work)
    while work:
        node, machine = work.pop()
        machine.initial = _fill(builder, node, machine, work)
    stats = {
        "k": builder.machines,
        "control_nodes": len(builder.owner),
        "leaves": sum(1 for n in root.walk() if n.is_leaf),
    }
    return ConversionResult(top, ENGINE, "bt->fsm", stats, [])


def _top_entry(builder: _Builder, root: BTNode, top: FSM, work: list[tuple[BTNode, FSM]]) -> str:
    """The root inside the top machine: a leaf state, or the root control node's composite."""
    cont = Cont(SUCCESS, FAILURE)
    node = root
    while node.kind is NodeKind.DECORATOR:
        check_baseline_node(node)
        cont = rewire(node, cont)
        node = node.children[0]
    if node.is_leaf:
        return builder.leaf_state(node, top, cont, None)
    name = builder.unique_name(top, node.name or node.type)
    sub = builder.new_machine(name, node, top=False)
    top.add_state(State(name, action=None, regions=[sub]))
    top.add_transition(name, None, cont.success, exit=SUCCESS)
    top.add_transition(name, None, cont.failure, exit=FAILURE)
    work.append((node, sub))
    return name


register_engine(
    ENGINE, fsm_to_chds, bt_to_chds_fsm, "Marzinotto et al.'s BT <-> CHDS mappings (baseline)"
)
