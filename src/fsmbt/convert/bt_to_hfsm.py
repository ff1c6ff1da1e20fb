"""BT -> hierarchical FSM, the paper's way (docs/conversion.md, 'BT -> FSM: depth compression and conversion units'), done exactly.

Steps:
1. inline ``SubTree`` references and compress depth (``compress``): same-type Sequence/Fallback
   children merge into their parent;
2. cut the tree into conversion units of three levels: a unit is a control node (level 0), its
   children (level 1) and its grandchildren (level 2); a control node on level 2 starts its own
   unit and is a composite state of the unit above. The stateless decorators Inverter,
   ForceSuccess and ForceFailure are transparent: they take no level and only rewire outcomes;
3. each unit becomes a sub-FSM by the sequence and fallback rules: a state per leaf (action = the
   leaf's label, ``leaf_label``), events ``success``/``failure``/``running``; in a Sequence a
   child's success leads to the next child's first state and its failure to the unit's
   ``FAILURE`` end state (dually for a Fallback); an action's ``running`` is a self-loop (the
   next tick resumes it); the last child's outcome leads to the unit's end states;
4. the sub-FSMs are nested: a composite state leaves its sub-FSM by completion transitions with
   ``exit="SUCCESS"`` / ``exit="FAILURE"``. The top machine's end states are the final states
   ``SUCCESS`` and ``FAILURE`` (actions ``SUCCESS``/``FAILURE``: the root's result).

Beyond the paper's node set (ReactiveSequence/ReactiveFallback, SequenceWithMemory, Parallel,
Repeat, RetryUntilSuccessful, KeepRunningUntilFailure, RunOnce, the built-in leaves ...): such a
node keeps memory between ticks or restarts children, so its behaviour is not a function of the
paper's per-leaf rules. The topmost such node on a path (its ancestors are all plain
Sequence/Fallback/stateless decorators, which always resume straight into it, so it behaves the
same in isolation) becomes one composite state whose sub-FSM is the leaf-execution machine of its
subtree, explored with the reference interpreter (``fsmbt.semantics.leaf_machine``; the
interpreter is cross-checked against BehaviorTree.CPP). With ``unroll=True``, or inside a region
headed by another node, a Parallel is part of that product (one state per combination of
running children); by default a Parallel/ParallelAll heading its region is an SCXML
``<parallel>`` whose regions take turns on data, so that the interleaving of its children's
ticks, observable leaf by leaf, is BehaviorTree.CPP's (``fsmbt.convert.bt_parallel``;
docs/semantics.md §6a; a Parallel it cannot express is warned about, naming the reason). The
whole tree is explored instead when such a region can end in ``SKIPPED`` or
``LIVELOCK`` (no sequence/fallback rule covers them) and, with ``loop=True``, when any such node
exists (its memory outlives the root's restart). The verdict for those parts then checks the
assembly and the flattening; the node semantics come from the interpreter.

By default (docs/conversion.md, "Compact conversion") such a region is not kept as its explored
machine but as one state per leaf with the memory as data (``fsmbt.convert.bt_compact``;
docs/semantics.md §6a): guards and assignments whose W3C meaning the checker proves equivalent
to the region's leaf-execution machine. ``unroll=True`` keeps the explored machine.

Complexity: O(N) for the structural part (explicit work lists, no recursion over the tree);
explored regions cost O(S · 3) interpreter steps for their S reachable states.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from fsmbt import limits
from fsmbt.convert.bt_compact import CompactRegion, Namer, compact_region
from fsmbt.convert.bt_parallel import ParallelRegion, is_parallel_kind, parallel_region
from fsmbt.convert.bt_pernode import (
    PERNODE_MIN_LOG2,
    PERNODE_SURE_NODES,
    PERNODE_TRY_STATES,
    PerNodeRegion,
    pernode_estimate,
    pernode_region,
    region_size,
)
from fsmbt.convert.compress import inline_and_compress
from fsmbt.convert.perf import without_gc_pauses
from fsmbt.convert.result import ConversionResult
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import Hint, InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import DATAMODEL, ONEXIT, join_lines
from fsmbt.semantics.leaf_machine import ExploredMachine, LeafMachine, StateLimitError, explore
from fsmbt.semantics.nodes import (
    PLAIN_CONTROLS,
    RESULT_MAP_DECORATORS,
    SEQUENCE_TYPES,
    rewired,
)
from fsmbt.semantics.status import LeafOutcome, NodeStatus, RootResult

#: Exit-state names (``RootResult``) and leaf-outcome events (``LeafOutcome``), as plain str.
SUCCESS, FAILURE = RootResult.SUCCESS.value, RootResult.FAILURE.value
RUNNING = NodeStatus.RUNNING.name
EV_SUCCESS, EV_FAILURE, EV_RUNNING = (
    LeafOutcome.SUCCESS.value,
    LeafOutcome.FAILURE.value,
    LeafOutcome.RUNNING.value,
)
ROOT_RESULTS = (SUCCESS, FAILURE)


def leaf_label(node: BTNode) -> str:
    """The leaf's label as the leaf-execution machine prints it (the shared definition is
    ``fsmbt.semantics.leaf_machine.leaf_label``: name, else type; asserted in the tests)."""
    return node.name or node.type


@dataclass
class _Cont:
    """Where a node's outcomes lead inside the current unit's sub-FSM."""

    success: str
    failure: str


def _is_structural(node: BTNode) -> bool:
    if node.semantics is not None and node.semantics != node.type:
        return False  # a custom type with a library kind's meaning: explored
    if node.kind is NodeKind.CONTROL:
        return node.type in PLAIN_CONTROLS and not node.attrs
    if node.kind is NodeKind.DECORATOR:
        return node.type in RESULT_MAP_DECORATORS and not node.attrs
    if node.is_leaf:
        return not node.is_builtin and not any(k.startswith("_") for k in node.attrs)
    return False


def _opaque_roots(root: BTNode) -> list[BTNode]:
    """The topmost non-structural nodes (each heads an explored region)."""
    found: list[BTNode] = []
    stack = [root]
    while stack:
        node = stack.pop()
        if not _is_structural(node):
            found.append(node)
            continue
        if (
            node.kind is not NodeKind.ACTION
            and node.kind is not NodeKind.CONDITION
            and not node.children
        ):
            raise InputError(
                f"{node.type} node without children", element=node.label, location=node.location
            )
        stack.extend(node.children)
    return found


@dataclass
class _Builder:
    top_results: bool = True
    units: int = 0
    explored: int = 0
    machines: int = 0
    explored_states: int = 0
    warnings: list[str] = field(default_factory=list)
    loop: bool = False
    max_states: int | None = None
    where: _Places | None = None
    compact: bool = True
    namer: Namer = field(default_factory=Namer)
    variables: list[tuple[str, str]] = field(default_factory=list)
    guarded: int = 0
    parallels: int = 0
    #: write regions per node (``bt_pernode``): True always, False never, None past the estimate
    pernode: bool | None = None
    pernode_regions: int = 0
    #: explorations made while choosing the form, reused by the compact form
    explored_cache: dict[int, tuple[LeafMachine, ExploredMachine[Any]]] = field(
        default_factory=dict
    )
    #: per machine (by id, the machine held): the next ``#n`` suffix to try per state name
    _suffixes: dict[int, tuple[FSM, dict[str, int]]] = field(default_factory=dict, repr=False)

    # -- naming ----------------------------------------------------------------------------
    def _unique(self, fsm: FSM, base: str) -> str:
        """``base`` when no state of ``fsm`` has that name, else ``base#n`` for the smallest
        n >= 2 free. The builder only adds states, so a suffix found taken stays taken: the
        search resumes where the last one for (``fsm``, ``base``) stopped (``_suffixes``;
        ``fsm`` is kept alive there, so its id is not reused). Cost: O(1) amortised per name
        (a search from 2 each time was O(k^2) for k states of one name: 0.7 s of the 15 560-node
        ``mixed`` tree's conversion, under cProfile)."""
        if base not in fsm.states:
            return base
        held, next_of = self._suffixes.setdefault(id(fsm), (fsm, {}))
        n = next_of.get(base, 2)
        while f"{base}#{n}" in held.states:
            n += 1
        next_of[base] = n
        return f"{base}#{n}"

    def _new_machine(self, name: str, top: bool) -> FSM:
        self.machines += 1
        fsm = FSM(name=name)
        for result in ROOT_RESULTS:
            fsm.add_state(State(result, action=result if top else None, final=True))
        fsm.initial = None
        return fsm

    # -- units -----------------------------------------------------------------------------
    def build(self, root: BTNode, opaque: set[int]) -> FSM:
        top = self._new_machine("HFSM", top=True)
        # work list of (unit root node, its machine)
        work: list[tuple[BTNode, FSM]] = [(root, top)]
        while work:
            node, machine = work.pop()
            self.units += 1
            entry = self._compile_unit(node, machine, opaque, work)
            machine.initial = entry
        return top

    def _compile_unit(
        self, unit_root: BTNode, machine: FSM, opaque: set[int], work: list[tuple[BTNode, FSM]]
    ) -> str:
        """Wire the unit's nodes into ``machine``; returns the unit's initial state."""
        # items: (node, level, continuation); processed so a node's later siblings are wired
        # first (their entry states are the earlier siblings' targets)
        return self._compile(unit_root, 0, _Cont(SUCCESS, FAILURE), machine, opaque, work)

    def _compile(
        self,
        node: BTNode,
        level: int,
        cont: _Cont,
        machine: FSM,
        opaque: set[int],
        work: list[tuple[BTNode, FSM]],
    ) -> str:
        """The entry state of ``node`` wired to ``cont`` (recursion depth <= 3 levels; chains
        of transparent decorators are unrolled in a loop)."""
        while node.kind is NodeKind.DECORATOR and id(node) not in opaque:
            cont = _Cont(*rewired(node.type, cont.success, cont.failure))
            node = node.children[0]
        if id(node) in opaque:
            return self._explored_state(node, cont, machine)
        if node.is_leaf:
            name = self._unique(machine, leaf_label(node))
            machine.add_state(State(name, action=leaf_label(node)))
            machine.add_transition(name, EV_SUCCESS, cont.success)
            machine.add_transition(name, EV_FAILURE, cont.failure)
            if node.kind is NodeKind.ACTION:
                machine.add_transition(name, EV_RUNNING, name)
            return name
        if level == 2:
            name = self._unique(machine, node.name or node.type)
            sub = self._new_machine(name, top=False)
            machine.add_state(State(name, action=None, regions=[sub]))
            machine.add_transition(name, None, cont.success, exit=SUCCESS)
            machine.add_transition(name, None, cont.failure, exit=FAILURE)
            work.append((node, sub))
            return name
        # a unit control node (level 0) or a child control node (level 1): wire its children
        is_sequence = node.type in SEQUENCE_TYPES
        entry = cont.success if is_sequence else cont.failure
        for child in reversed(node.children):
            if is_sequence:
                child_cont = _Cont(entry, cont.failure)
            else:
                child_cont = _Cont(cont.success, entry)
            entry = self._compile(child, level + 1, child_cont, machine, opaque, work)
        return entry

    # -- explored regions --------------------------------------------------------------------
    def _explored_state(self, node: BTNode, cont: _Cont, machine: FSM) -> str:
        reset: list[tuple[str, str]] = []
        per_node = self.pernode_region(node) if self.compact else None
        parallel = self.parallel_region(node) if self.compact and per_node is None else None
        if parallel is not None:
            sub, ends = parallel.fsm, parallel.ends
            reset = parallel.variables
            self.variables.extend(reset)
            self.parallels += 1
        elif per_node is not None:
            sub, ends = per_node.fsm, per_node.ends
            reset = per_node.variables
            self.variables.extend(reset)
            self.guarded += per_node.guarded
            self.pernode_regions += 1
        elif self.compact:
            region = self.compact_region(node, loop=False, top=False)
            sub, ends = region.fsm, region.ends
            reset = region.variables
        else:
            sub, ends = explore_region(
                node, loop=False, max_states=self.max_states, where=self.where
            )
            self.explored_states += len(sub.states)
        self.explored += 1
        self.machines += 1
        unexpected = ends - set(ROOT_RESULTS)
        if unexpected:
            raise _NeedsWholeTree(", ".join(sorted(unexpected)))
        name = self._unique(machine, node.name or node.type)
        state = machine.add_state(State(name, action=None, regions=[sub]))
        if reset:  # leaving the region forgets its memory (docs/semantics.md, data)
            state.attrs[ONEXIT] = join_lines(reset)
        # only the ends the region reaches: a completion transition waiting for a final state
        # the sub-machine does not have never fires (and SCXML cannot name that state)
        if SUCCESS in ends:
            machine.add_transition(name, None, cont.success, exit=SUCCESS)
        if FAILURE in ends:
            machine.add_transition(name, None, cont.failure, exit=FAILURE)
        return name

    def pernode_region(self, node: BTNode) -> PerNodeRegion | None:
        """``node``'s region written per node (``bt_pernode``) when ``pernode`` says so (by
        default: when the estimate of its explored size passes ``PERNODE_MIN_LOG2``), else
        ``None`` (the compact form, or ``<parallel>`` for a Parallel heading a small region; a
        large region that cannot be written per node is warned about, naming why)."""
        if self.pernode is False:
            return None
        if self.pernode is None and not self._large(node):
            return None
        found = pernode_region(
            node, name=f"pernode_{node.label}", new_variable=self.namer.name, unique=self._unique
        )
        if isinstance(found, str):
            if self.pernode is None:
                self.warnings.append(
                    f"{self._place(node)}: explored as a whole, not per node: {found}"
                )
            return None
        return found

    def _large(self, node: BTNode) -> bool:
        """Whether the default writes ``node``'s region per node: its estimate passes
        ``PERNODE_MIN_LOG2`` and either it holds ``PERNODE_SURE_NODES`` nodes or more, or its
        exploration passes ``PERNODE_TRY_STATES`` (a region that fits keeps the compact form,
        byte for byte; the exploration is kept for it)."""
        if pernode_estimate(node) < PERNODE_MIN_LOG2:
            return False
        if region_size(node) >= PERNODE_SURE_NODES:
            return True
        limit = PERNODE_TRY_STATES
        if self.max_states is not None:
            limit = min(limit, self.max_states)
        machine = LeafMachine(BTDocument.single(node), loop=False)
        try:
            self.explored_cache[id(node)] = (machine, explore(machine, max_states=limit))
        except StateLimitError:
            return True
        return False

    def parallel_region(self, node: BTNode) -> ParallelRegion | None:
        """A Parallel/ParallelAll heading its region as a ``<parallel>`` (``bt_parallel``), or
        ``None`` (not such a node, or not exactly expressible: the reason is warned)."""
        if not is_parallel_kind(node):
            return None
        found = parallel_region(
            node,
            name=f"parallel_{node.label}",
            plain=_is_structural,
            new_variable=self.namer.name,
            compact_child=self._tick_marked_region,
        )
        if isinstance(found, str):
            self.warnings.append(f"{self._place(node)}: kept as a product, not <parallel>: {found}")
            return None
        self.warn_inner_parallels(node)  # a Parallel inside a child: part of its compact region
        return found

    def _tick_marked_region(self, node: BTNode) -> CompactRegion:
        """``node``'s subtree as a compact region whose steps say where its ticks end (a
        Parallel's child that is not plain; ``bt_parallel``)."""
        limit = (
            self.max_states
            if self.max_states is not None
            else limits.current().conversion_max_states
        )
        machine = LeafMachine(BTDocument.single(node), loop=False, mark_ticks=True)
        try:
            explored = explore(machine, max_states=limit)
        except StateLimitError:
            raise StateLimitError(
                f"exploring this subtree (a child of a Parallel with memory or reactive "
                f"children) reaches more than {limit} states",
                element=self.where.path(node) if self.where else node.label,
                location=node.location,
                hints=(Hint.MAX_STATES,),
            ) from None
        region = compact_region(
            machine,
            explored,
            name=f"compact_{node.label}",
            top=False,
            namer=self.namer,
            unique=self._unique,
            tick_marks=True,
        )
        self.explored_states += region.explored_states
        self.guarded += region.guarded
        return region

    def _place(self, node: BTNode) -> str:
        return f"{node.type} at {self.where.path(node) if self.where else node.label}"

    def warn_inner_parallels(self, node: BTNode) -> None:
        """Warn for each Parallel inside ``node``'s explored region (below its head): it stays
        part of the region's product (docs/semantics.md §6a); ``node`` too when it is the
        whole tree (``loop``: the root's memory outlives its restart)."""
        stack = [node] if self.loop else list(node.children)
        while stack:
            inner = stack.pop()
            if is_parallel_kind(inner) and self.loop:
                self.warnings.append(
                    f"{self._place(inner)}: kept as a product, not <parallel>: with loop the "
                    "whole tree is one explored region (its memory outlives the root's restart)"
                )
            elif is_parallel_kind(inner):
                self.warnings.append(
                    f"{self._place(inner)}: kept as a product, not <parallel>: it runs inside "
                    f"the region of {node.type} '{node.label}', whose memory, restarts or "
                    "re-checks halt and restart it"
                )
            stack.extend(inner.children)

    def compact_region(self, node: BTNode, *, loop: bool, top: bool):  # noqa: ANN201
        """``node``'s region as one state per leaf with data (``bt_compact``); its variables
        join the conversion's data model."""
        self.warn_inner_parallels(node)
        cached = self.explored_cache.pop(id(node), None) if not loop else None
        if cached is not None:
            machine, explored = cached
        else:
            machine, explored = _explore(
                node, loop=loop, max_states=self.max_states, where=self.where
            )
        region = compact_region(
            machine,
            explored,
            name=f"compact_{node.label}",
            top=top,
            namer=self.namer,
            unique=self._unique,
        )
        self.explored_states += region.explored_states
        self.guarded += region.guarded
        self.variables.extend(region.variables)
        return region


class _NeedsWholeTree(Exception):
    """A region ends in a way no sequence/fallback rule covers: explore the whole tree."""


class _Places:
    """Where each node of the prepared tree sits, in the words a user finds in the file: the
    tree's id, then the labels (name, else type) from the root down, then the line."""

    def __init__(self, tree_id: str, root: BTNode) -> None:
        self.tree_id = tree_id
        self.parent: dict[int, BTNode | None] = {id(root): None}
        stack = [root]
        while stack:
            node = stack.pop()
            for child in node.children:
                self.parent[id(child)] = node
                stack.append(child)

    def path(self, node: BTNode) -> str:
        """``tree 'MainTree', Sequence > Fallback 'patrol' > RetryUntilSuccessful`` - the
        labels from the root down to ``node`` (at most 8, the middle elided)."""
        labels: list[str] = []
        current: BTNode | None = node
        while current is not None:
            labels.append(
                current.label
                if current.label == current.type
                else f"{current.type} '{current.label}'"
            )
            current = self.parent.get(id(current))
        labels.reverse()
        if len(labels) > 8:
            labels = labels[:3] + ["..."] + labels[-4:]
        return f"tree '{self.tree_id}', " + " > ".join(labels)


def explore_region(
    node: BTNode,
    *,
    loop: bool = False,
    top: bool = False,
    max_states: int | None = None,
    where: _Places | None = None,
) -> tuple[FSM, set[str]]:
    """The leaf-execution machine of ``node``'s subtree as a (flat) FSM.

    One state per reachable interpreter configuration (``q0``, ``q1`` ... in breadth-first
    order), named after the leaf it is about to tick; its action is that leaf's label. A root
    result becomes an end state named after it (final; action = the result at the top, none
    inside a composite).

    Args:
        node: the subtree's root.
        loop: the subtree's root is ticked again after it returns.
        top: the subtree is the whole tree (its results are the machine's actions).
        max_states: most reachable configurations explored (``None``:
            ``fsmbt.limits.current().conversion_max_states``).
        where: names the subtree in a refusal (default: its label alone).

    Returns:
        The machine and the set of end states that occur.

    Raises:
        StateLimitError: more than ``max_states`` configurations; names the subtree (tree,
        node path, line) and carries ``Hint.MAX_STATES``.
    """
    from fsmbt.semantics.leaf_machine import RootResult

    _machine, explored = _explore(node, loop=loop, max_states=max_states, where=where)
    fsm = FSM(name=f"explored_{node.label}")
    names: dict[object, str] = {}
    ends: set[str] = set()

    def state_for(state: object, outputs: tuple[str, ...]) -> str:
        known = names.get(state)
        if known is not None:
            return known
        if isinstance(state, RootResult):
            name = state.result
            ends.add(name)
            fsm.add_state(State(name, action=name if top else None, final=True))
        else:
            if len(outputs) != 1:
                raise InputError(
                    f"cannot express the outputs {outputs} of one step as one state's action",
                    element=node.label,
                )
            name = f"q{len(names)}:{outputs[0]}"
            fsm.add_state(State(name, action=outputs[0]))
        names[state] = name
        return name

    fsm.initial = state_for(explored.start, explored.start_outputs)
    for state in explored.states:
        source = names[state]
        for symbol, (target, outputs) in explored.transitions[state].items():
            if loop and top and len(outputs) == 2:
                name = _looped_result(fsm, explored, target, outputs, ends, node)
            else:
                name = state_for(target, outputs)
                if top and outputs != (fsm.states[name].action,):  # never drop an output
                    raise UnsupportedError(
                        f"cannot express the outputs {outputs} of one step as one state's action",
                        element=node.label,
                    )
            fsm.add_transition(source, symbol, name)
    fsm.initial = names[explored.start]
    return fsm, ends


def _explore(
    node: BTNode, *, loop: bool, max_states: int | None, where: _Places | None
) -> tuple[LeafMachine, ExploredMachine[Any]]:
    """The leaf machine of ``node``'s subtree and every state it reaches (bounded; a refusal
    names the subtree)."""
    limit = max_states if max_states is not None else limits.current().conversion_max_states
    machine = LeafMachine(BTDocument.single(node), loop=loop)
    try:
        return machine, explore(machine, max_states=limit)
    except StateLimitError:
        subtree = where.path(node) if where is not None else node.label
        raise StateLimitError(
            f"exploring this subtree (a {node.type} with memory or reactive children, "
            f"converted as one composite state) reaches more than {limit} states",
            element=subtree,
            location=node.location,
            hints=(Hint.MAX_STATES,),
        ) from None


def _looped_result(
    fsm: FSM, explored, target: object, outputs: tuple[str, ...], ends: set[str], node: BTNode
) -> str:
    """With ``loop`` a step can end the tick and start the next one: outputs ``(result,
    first leaf)``. An FSM read as a leaf machine with ``loop`` says exactly that on entering a
    final state named after the result (its action, then the initial state's), provided the
    new tick is back in the start configuration; anything else cannot be expressed."""
    result, leaf = outputs
    start_action = fsm.states[fsm.initial].action if fsm.initial else None
    if target != explored.start or result not in ROOT_RESULTS or leaf != start_action:
        raise UnsupportedError(
            f"cannot express the outputs {outputs} of one step as one state's action",
            element=node.label,
        )
    if result not in fsm.states:
        fsm.add_state(State(result, action=result, final=True))
    ends.add(result)
    return result


@without_gc_pauses
def bt_to_hfsm(
    doc: BTDocument,
    *,
    loop: bool = False,
    style: str = "paper",
    max_states: int | None = None,
    unroll: bool = False,
    pernode: bool | None = None,
    **_options: object,
) -> ConversionResult:
    """Convert a BT document into a hierarchical FSM whose flattening is the BT's
    leaf-execution machine (see the module docstring).

    Args:
        doc: the BT document (its main tree is converted).
        loop: the root is ticked again after it returns.
        style: the output style (``paper``).
        max_states: most states explored per region (``None``: the limits in force).
        unroll: keep every memory as states (a region = its explored leaf-execution
            machine) instead of data (the default, ``bt_compact``; docs/conversion.md).
        pernode: write regions one sub-machine per node (``bt_pernode``): ``True`` every
            region it can, ``False`` none, ``None`` (default) a large region (``_large``:
            past the estimate, and past ``PERNODE_SURE_NODES`` nodes or
            ``PERNODE_TRY_STATES`` explored states; smaller trees unchanged).

    Returns:
        The HFSM with the conversion's figures and warnings.
    """
    prepared = inline_and_compress(doc)
    compression = prepared.compression
    root = compression.root
    places = _Places(doc.main.id, root)
    builder = _Builder(
        loop=loop, max_states=max_states, where=places, compact=not unroll, pernode=pernode
    )
    opaque_nodes = _opaque_roots(root)
    whole_tree = loop and bool(opaque_nodes)
    hfsm: FSM | None = None
    if not whole_tree:
        try:
            hfsm = builder.build(root, {id(n) for n in opaque_nodes})
        except _NeedsWholeTree as exc:
            builder.warnings.append(f"a region can end in {exc}: the whole tree is explored")
            whole_tree = True
    if whole_tree:
        builder = _Builder(loop=loop, max_states=max_states, where=places, compact=not unroll)
        if unroll:
            hfsm, _ends = explore_region(
                root, loop=loop, top=True, max_states=max_states, where=places
            )
            builder.explored_states = len(hfsm.states)
        else:
            hfsm = builder.compact_region(root, loop=loop, top=True).fsm
        builder.explored, builder.machines = 1, 1
    assert hfsm is not None
    hfsm.name = f"{doc.main.id}_hfsm"
    if builder.variables:  # docs/semantics.md, "Data in state machines"
        hfsm.attrs[DATAMODEL] = join_lines(builder.variables)
    stats = {
        "k": builder.machines,
        "units": builder.units,
        "explored_regions": builder.explored,
        "explored_states": builder.explored_states,
        "depth_before": compression.depth_before,
        "depth_after": compression.depth_after,
        "merged_nodes": compression.merged,
        "leaves": prepared.leaves,
        "loop": loop,
        "unroll": unroll,
        "data_variables": len(builder.variables),
        "guarded_transitions": builder.guarded,
        "parallel_states": builder.parallels,
        "pernode_regions": builder.pernode_regions,
    }
    return ConversionResult(hfsm, "rules", "bt->fsm", stats, builder.warnings)
