"""The compositional check of a BT against an HFSM: the sum of local proofs
(docs/verification.md §5 "Compositional check"; the argument in docs/semantics.md §4c).

Scope: a behavior tree (no ``SubTree``, ``loop=False``) whose *plain skeleton* - the nodes
from the root down to the topmost non-plain nodes, where plain means a ``Sequence`` or
``Fallback`` without ports, an ``Inverter``/``ForceSuccess``/``ForceFailure`` without ports, or
an environment leaf (ports allowed, no pre-condition, no library kind) - holds every node with
memory inside a *region* (the subtree of a topmost non-plain node), checked against a hierarchical FSM in which each region is one composite state
(a sub-machine that only its completion transitions leave). That is the shape ``bt_to_hfsm``
gives a tree whose memory nodes sit under plain controls, but nothing of the converter is read:
the regions of the tree come from the node registry's meaning of each kind, the regions of the
FSM from its structure, and the two are paired by the skeleton check itself.

The proof, in three parts (each one the native checker, ``fsmbt.verify.native``, on machines
built by fsmbt's own semantics):

1. each region alone: the region's subtree as a tree of its own (its leaf-execution machine,
   ``LeafMachine``, from the interpreter: tick *and* halt rules) against the composite state's
   sub-machine as a machine of its own (final states showing their result, the data it reads
   declared as the whole machine declares it). This also gives the results ``P`` the region can
   return (bottom-up: the final states its exploration reaches);
2. the skeleton: the tree with each region replaced by an abstract action whose outcomes are
   ``P`` (``ForceSuccess``/``ForceFailure`` when ``P`` has one result), against the FSM with each
   region state replaced by a leaf state that goes where its completion transitions go;
3. the pairing: every abstract action of the tree is matched with exactly one region state of
   the FSM by walking the two skeleton machines in lockstep (a step where the two put different
   abstract labels pairs them; a second, different partner refuses the decomposition).

If every part holds, the pair is equivalent (docs/semantics.md §4c: a plain parent ticks each
child at most once per run, resumes a running child straight into it, never halts it, and
never reads its memory after it returned; a region state is entered at most once per run, from
its initial state with its variables at their declared values, and nothing but its own
completion transitions leaves it). If any part fails, or the pair does not decompose, the
caller runs the whole-product check, which gives the verdict and its shortest counterexample in
the user's terms: the compositional check never says "not equivalent" on its own.

Data: variables of the FSM's data model must each be read or written by one region only (and
nowhere in the skeleton); a region's check declares exactly its own. A tree holding a kind whose
control flow reads the blackboard (``BLACKBOARD_BASED``: ``Switch``, ``Precondition``...) or a
pre-condition is out of scope (the whole product decides it). ``Script``/``SetBlackboard`` are
never plain, so they lie inside a region; their writes are never read in the model (the readers
are refused or out of scope), so they couple no regions.

Cost: the sum of the regions' checks (each the explicit product of that region only) plus one
check of the skeleton (plain: the static leaf table, O(leaves)); a tree of k regions of at most
m states costs O(k · m) instead of the product of the regions' memories.
"""

from __future__ import annotations

import contextlib
import copy
import re
import time
from collections import deque
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from fsmbt import limits
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM, State, Transition
from fsmbt.model.fsm_data import DATAMODEL, ONEXIT, join_lines, mentioned_names, parse_lines
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.leaf_machine import LeafMachine
from fsmbt.semantics.machine import FSMLeafMachine
from fsmbt.semantics.nodes import (
    BLACKBOARD_BASED,
    PLAIN_CONTROLS,
    RESULT_MAP_DECORATORS,
    SUBTREE_TYPE,
    canonical_type,
)
from fsmbt.semantics.status import LeafOutcome, NodeStatus, RootResult
from fsmbt.verify.lift import lifted_region_report, lifted_report, walked_report, whole_tree
from fsmbt.verify.lower_bound import LowerBound, lower_bound
from fsmbt.verify.method import PER_NODE_SENTENCE
from fsmbt.verify.narrow import StagesNeverGoingOn
from fsmbt.verify.native import DEFAULT_MAX_STATES, StateLimitError, check, check_witnessed
from fsmbt.verify.pernode import (
    NODE_ATTR,
    LocalUnit,
    LocalWitness,
    NotPerNode,
    PerNodeOutcome,
    check_region,
    complete_walk,
)
from fsmbt.verify.report import COMPOSITIONAL, PER_NODE, PROPERTIES, PropertyResult, Report
from fsmbt.verify.tickable import NeverReturns, stage_never_passes

SUCCESS, FAILURE = RootResult.SUCCESS.value, RootResult.FAILURE.value
EV_SUCCESS, EV_FAILURE = LeafOutcome.SUCCESS.value, LeafOutcome.FAILURE.value
#: Labels of the abstract children (never a name a file gives: ``⟪`` is not an XML name char).
_BT_TOKEN = "⟪unit {}⟫"
_FSM_TOKEN = "⟪state {}⟫"
_NO_EXIT = "⟪no completion⟫"
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")

COMPOSITIONAL_SENTENCE = (
    "compositional: every region with memory (a topmost node that is not a plain Sequence/"
    "Fallback/result map) is checked alone against its composite state, and the plain "
    "skeleton with each region abstracted to the results it can return (docs/semantics.md "
    "§4c: equivalence is a congruence for plain parents)"
)


#: A region written per node whose sub-machine has at most this many states, and that breaks
#: the per-node check's entry condition, is checked whole first (a shortest counterexample; a
#: few hundred states cost milliseconds to a second), its per-node candidate failure lifted only
#: when that check stops at a limit; a larger one has the candidate lifted first (a tree of
#: 1 000 nodes: seconds instead of a region check that stops). ``bench_pernode_outside.py``.
WHOLE_FIRST = 250

#: Most configurations and data values the region's machine may expand to when a region
#: written per node is checked whole after its per-node check failed (``compositional_report``):
#: a few seconds of the W3C expansion at most; past it, the whole product decides as before.
WHOLE_AFTER_FAILURE_STATES = 20_000

#: The mode of a compositional verdict (a BT's leaf-execution machine against an FSM's).
LEAF_EXECUTION = "leaf-execution"

#: The share of the checker's time limit (``fsmbt.limits``: ``checker_max_seconds``) that
#: ``verify``'s compositional attempt may spend before it gives way to the whole product.
ATTEMPT_SHARE = 0.25


def attempt_seconds() -> float:
    """The wall-clock budget of ``verify``'s compositional attempt (:data:`ATTEMPT_SHARE` of the
    checker's time limit in force)."""
    return limits.current().checker_max_seconds * ATTEMPT_SHARE


#: How ``compositional_report`` starts the reason when a part's check failed.
FAILED_PART = "the local check of"


class NotDecomposable(Exception):
    """The pair is outside the compositional check's scope (the reason is the message)."""


@dataclass
class Decomposition:
    """What the compositional check found: its verdict and the figures of each part."""

    equivalent: bool
    reason: str = ""
    regions: int = 0
    region_states: int = 0
    largest_region: int = 0
    skeleton_states: int = 0
    failed_region: str | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    #: the region whose per-node check failed and that check (for ``verify/lift.py``)
    per_node_failure: tuple[BTNode, PerNodeOutcome] | None = None
    #: the region checked whole whose check failed and its report (its counterexample, for
    #: ``verify/lift.py``)
    region_failure: tuple[BTNode, Report] | None = None
    #: the lifted report of a per-node failure found past a broken entry condition
    #: (``pernode.check_region``'s ``tolerate``), already confirmed by replay
    lifted: Report | None = None
    #: the index (in ``Structure.regions``) of the tree region whose check failed
    failed_index: int | None = None
    #: a per-node failure in a region of at most ``WHOLE_FIRST`` states: when the lift finds
    #: no run to it, ``compositional_report`` checks that region whole instead
    failed_small: bool = False


# -- the tree side ---------------------------------------------------------------------------
def _is_plain(node: BTNode) -> bool:
    """A node of the skeleton: no memory, no blackboard, no pre-condition; a control or
    decorator without ports, an environment leaf with any ports but a pre-condition (the
    model never reads an environment leaf's ports: its outcome is the input)."""
    if node.semantics is not None and node.semantics != node.type:
        return False
    if node.is_leaf and not any(key.startswith("_") for key in node.attrs):
        # a library kind (``semantics`` set) may carry a gate the environment answers: not plain
        return node.semantics is None and not node.is_builtin and not node.children
    if node.attrs:
        return False
    kind_type = canonical_type(node.type)
    if node.kind is NodeKind.CONTROL:
        return kind_type in PLAIN_CONTROLS and bool(node.children)
    if node.kind is NodeKind.DECORATOR:
        return kind_type in RESULT_MAP_DECORATORS and len(node.children) == 1
    return False


def tree_regions(doc: BTDocument) -> list[BTNode]:
    """The topmost non-plain nodes of ``doc``'s main tree, in pre-order (iterative, O(N)).

    Raises:
        NotDecomposable: the tree holds a SubTree (its expansion is not decomposed here).
    """
    root = doc.main.root
    if root is None:
        raise NotDecomposable("the main tree is empty")
    found: list[BTNode] = []
    stack = [root]
    while stack:
        node = stack.pop()
        if node.kind is NodeKind.SUBTREE or node.type == SUBTREE_TYPE:
            raise NotDecomposable("the tree uses SubTrees")
        if not _is_plain(node):
            found.append(node)
            _no_subtree_below(node)
            continue
        stack.extend(reversed(node.children))
    return found


def _no_subtree_below(node: BTNode) -> None:
    """Refuse a region holding a SubTree or a kind whose control flow reads the blackboard
    (``BLACKBOARD_BASED``: even abstracted, it is kept out of the scope) or a pre-condition."""
    stack = [node]
    while stack:
        x = stack.pop()
        if x.kind is NodeKind.SUBTREE or x.type == SUBTREE_TYPE:
            raise NotDecomposable("the tree uses SubTrees")
        if canonical_type(x.semantics or x.type) in BLACKBOARD_BASED or any(
            key.startswith("_") for key in x.attrs
        ):
            raise NotDecomposable(f"{x.label} reads the blackboard")
        stack.extend(x.children)


def region_labels(doc: BTDocument, regions: list[BTNode]) -> frozenset[str]:
    """The regions' labels that no plain control of the skeleton carries (O(N))."""
    inside = {id(node) for node in regions}
    plain: set[str] = set()
    root = doc.main.root
    stack = [root] if root is not None else []
    while stack:
        node = stack.pop()
        if id(node) in inside:
            continue
        if not node.is_leaf:
            plain.add(node.label)
        stack.extend(node.children)
    return frozenset(node.label for node in regions) - plain


def _abstract_child(label: str, results: frozenset[str]) -> BTNode:
    """An action leaf standing for a region that may return ``results``."""
    leaf = BTNode(label, NodeKind.ACTION, name=label)
    if results == {SUCCESS}:
        return BTNode("ForceSuccess", NodeKind.DECORATOR, children=[leaf])
    if results == {FAILURE}:
        return BTNode("ForceFailure", NodeKind.DECORATOR, children=[leaf])
    return leaf


def skeleton_tree(
    doc: BTDocument, regions: list[BTNode], results: list[frozenset[str]]
) -> BTDocument:
    """``doc``'s main tree with region ``k`` replaced by an abstract child labelled
    ``⟪unit k⟫`` (a copy; O(N))."""
    index = {id(node): k for k, node in enumerate(regions)}
    root = doc.main.root
    assert root is not None

    def copy_shallow(node: BTNode) -> BTNode:
        k = index.get(id(node))
        if k is not None:
            return _abstract_child(_BT_TOKEN.format(k), results[k])
        return BTNode(node.type, node.kind, name=node.name, attrs={}, children=[])

    new_root = copy_shallow(root)
    stack = [(root, new_root)]
    while stack:
        old, new = stack.pop()
        if id(old) in index:
            continue
        for child in old.children:
            made = copy_shallow(child)
            new.children.append(made)
            stack.append((child, made))
    return BTDocument.single(new_root)


# -- the state machine side ------------------------------------------------------------------
def _declared(fsm: FSM) -> dict[str, str]:
    return dict(parse_lines(fsm.attrs.get(DATAMODEL, "")))


def _is_region_state(name: str, state: State, labels: frozenset[str]) -> bool:
    """A composite state made of a region: a flat sub-machine named ``compact_...`` or
    ``explored_...`` (``bt_to_hfsm``), or, once the names are lost (an SCXML file read back), a
    state named after a region of the tree and after no plain control of it; or a Parallel
    heading its region as a ``<parallel>`` (``convert/bt_parallel.py``: a sub-machine whose
    top holds one parallel state, named ``parallel_...`` or after a region of the tree).
    Recognition only: the checks decide (the region is checked whole, its W3C meaning)."""
    if len(state.regions) != 1:
        return False
    sub = state.regions[0]
    named = name.split("#")[0] in labels
    if sub.is_hierarchical:
        return (sub.name.startswith("parallel_") or named) and any(
            inner.is_parallel for inner in sub.states.values()
        )
    return sub.name.startswith(("compact_", "explored_")) or named


@dataclass
class _FsmRegion:
    path: str
    machine: FSM
    state: State
    exits: dict[str, str]  # SUCCESS/FAILURE -> target in the parent machine


def _check_machine_shape(machine: FSM, where: str) -> None:
    for t in machine.transitions:
        if t.source not in machine.states or t.target not in machine.states:
            raise NotDecomposable(f"{where}: a transition leaves its machine")


def fsm_regions(fsm: FSM, labels: frozenset[str] = frozenset()) -> list[_FsmRegion]:
    """The region states of ``fsm`` (depth first) with their completion targets; ``labels``:
    the labels of the tree's regions that no plain control of the tree carries.

    Raises:
        NotDecomposable: a region state is left by anything but one completion transition per
            result (an event transition on it could restart the region), or the skeleton
            carries data.
    """
    found: list[_FsmRegion] = []
    stack: list[tuple[str, FSM]] = [("", fsm)]
    while stack:
        prefix, machine = stack.pop()
        _check_machine_shape(machine, prefix or machine.name)
        for name, state in machine.states.items():
            path = f"{prefix}{name}"
            if _is_region_state(name, state, labels):
                exits: dict[str, str] = {}
                for t in machine.outgoing(name):
                    if t.event is not None or t.exit not in (SUCCESS, FAILURE) or t.attrs:
                        raise NotDecomposable(f"state {path}: left by more than completions")
                    if t.exit in exits:
                        raise NotDecomposable(f"state {path}: two completions on {t.exit}")
                    exits[t.exit] = t.target
                if state.action is not None or set(state.attrs) - {ONEXIT}:
                    raise NotDecomposable(f"state {path}: an action or data on the region")
                found.append(_FsmRegion(path, state.regions[0], state, exits))
                continue
            if state.attrs:
                raise NotDecomposable(f"state {path}: data outside a region")
            for sub in state.regions:
                stack.append((f"{path}/", sub))
        if any(t.attrs for t in machine.transitions):
            raise NotDecomposable(f"{prefix or machine.name}: data outside a region")
    return found


def skeleton_fsm(fsm: FSM, regions: list[_FsmRegion], results: list[frozenset[str]] | None) -> FSM:
    """A copy of ``fsm`` with region state ``j`` a leaf state labelled ``⟪state j⟫`` whose
    outcomes go where its completions go (an outcome the region never returns goes where its
    one result goes, as the abstract child of the tree maps it; ``results=None``, for the
    pairing walk: an outcome without a completion leads to a state that matches nothing);
    data dropped."""
    by_state = {id(r.state): j for j, r in enumerate(regions)}
    top = copy.copy(fsm)
    top.attrs = {k: v for k, v in fsm.attrs.items() if k != DATAMODEL}
    stack = [top]
    while stack:
        machine = stack.pop()
        states: dict[str, State] = {}
        transitions: list[Transition] = []
        replaced: set[str] = set()
        for name, state in machine.states.items():
            j = by_state.get(id(state))
            if j is None:
                new = copy.copy(state)
                new.regions = [copy.copy(sub) for sub in state.regions]
                stack.extend(new.regions)
                states[name] = new
                continue
            replaced.add(name)
            token = _FSM_TOKEN.format(j)
            states[name] = State(name, action=token)
            exits = regions[j].exits
            possible = frozenset(exits) if results is None else results[j] & set(exits)
            for outcome, result in ((EV_SUCCESS, SUCCESS), (EV_FAILURE, FAILURE)):
                if result in possible:
                    transitions.append(Transition(name, outcome, exits[result]))
                elif possible and results is not None:
                    transitions.append(Transition(name, outcome, exits[min(possible)]))
                elif results is None:  # pairing: an outcome without completion matches nothing
                    states.setdefault(_NO_EXIT, State(_NO_EXIT, action=_NO_EXIT))
                    transitions.append(Transition(name, outcome, _NO_EXIT))
        transitions.extend(t for t in machine.transitions if t.source not in replaced)
        machine.states = states
        machine.transitions = transitions
    return top


def region_fsm(region: _FsmRegion, declared: dict[str, str], names: set[str]) -> FSM:
    """The region's sub-machine as a machine of its own: final states show their result, the
    variables it names declared as the whole machine declares them."""
    sub = copy.copy(region.machine)
    sub.states = {
        name: (State(name, action=name, final=True) if state.final else state)
        for name, state in region.machine.states.items()
    }
    sub.attrs = dict(region.machine.attrs)
    if names:
        sub.attrs[DATAMODEL] = join_lines([(n, declared[n]) for n in sorted(names)])
    return sub


# -- pairing the abstract children -----------------------------------------------------------
def pair_regions(bt_machine: Any, fsm_machine: Any, max_states: int) -> dict[str, str]:
    """Walk the two skeleton machines in lockstep on the tree's offered inputs; where one
    outputs ``⟪unit k⟫`` and the other ``⟪state j⟫`` at the same position, pair them.

    Returns:
        FSM token -> tree token, one-to-one.

    Raises:
        NotDecomposable: a token meets two partners (a step whose outputs differ otherwise
            is not followed: the skeleton check decides it).
    """
    pairs: dict[str, str] = {}
    back: dict[str, str] = {}

    def match(a: tuple[str, ...], b: tuple[str, ...]) -> bool:
        """Pair the tokens of two output tuples; False when they differ otherwise (that
        branch is not followed: the skeleton check decides it)."""
        if len(a) != len(b):
            return False
        for x, y in zip(a, b, strict=True):
            if x == y:
                continue
            if not (x.startswith("⟪unit ") and y.startswith("⟪state ")):
                return False
            if pairs.setdefault(y, x) != x or back.setdefault(x, y) != y:
                raise NotDecomposable("a region state meets two regions of the tree")
        return True

    s0, out_s = bt_machine.start()
    r0, out_r = fsm_machine.start()
    if not match(out_s, out_r):
        raise NotDecomposable("the skeletons differ at the start")
    seen: set[tuple[Hashable, Hashable]] = {(s0, r0)}
    queue = deque([(s0, r0)])
    while queue:
        s, r = queue.popleft()
        for symbol in bt_machine.inputs(s):
            s2, o1 = bt_machine.step(s, symbol)
            r2, o2 = fsm_machine.step(r, symbol)
            if match(o1, o2) and (s2, r2) not in seen:
                if len(seen) >= max_states:
                    raise NotDecomposable("the skeleton is too large")
                seen.add((s2, r2))
                queue.append((s2, r2))
    return pairs


def _rename(fsm: FSM, names: dict[str, str]) -> None:
    stack = [fsm]
    while stack:
        machine = stack.pop()
        for state in machine.states.values():
            if state.action in names:
                state.action = names[state.action]
            stack.extend(state.regions)


# -- the check -------------------------------------------------------------------------------
def _results(witness: Any) -> frozenset[str]:
    """The root results a region's explored leaf machine reaches (its final states' outputs)."""
    src = witness.src
    values = src.outputs.values
    return final_results(
        src.status,
        values[src.start_outputs],
        ((nxt, values[out]) for row in src.edges for nxt, out in row.values()),
    )


def final_results(
    status: Sequence[str],
    start_outputs: Sequence[str],
    edges: Iterable[tuple[int, Sequence[str]]],
) -> frozenset[str]:
    """The root results an explored tree machine reaches: the last output of every step into
    a final state (and of the start, when the start is final). ``status`` by state number,
    ``edges`` each explored edge as (next state, outputs). O(edges)."""
    found: set[str] = set()
    if status and status[0] == "final":
        found.update(start_outputs[-1:])
    for nxt, out in edges:
        if status[nxt] == "final":
            found.update(out[-1:])
    return frozenset(found)


@dataclass
class Structure:
    """The decomposition read off the two models alone (no check run yet): the tree's regions
    in pre-order, the FSM's region states depth first, the data model and, per region state,
    the variables it names. Building it checks the side conditions of docs/semantics.md §4c
    that are structural (scope, region-state shape, data ownership); ``fsmbt.verify.
    certificate`` builds it again to re-derive what a certificate claims."""

    regions: list[BTNode]
    machine_regions: list[_FsmRegion]
    declared: dict[str, str]
    mentioned: list[set[str]]

    def tree_labels(self) -> list[str]:
        """The tree regions' labels, in pre-order (how a certificate names them)."""
        return [node.label for node in self.regions]

    def fsm_paths(self) -> list[str]:
        """The region states' paths, depth first (how a certificate names them)."""
        return [region.path for region in self.machine_regions]


def structure(source: BTDocument, result: FSM) -> Structure:
    """The decomposition of the pair and its structural side conditions (O(N + |FSM|)).

    Raises:
        NotDecomposable: the pair is outside the scope (the message says why).
    """
    if not result.is_hierarchical:
        raise NotDecomposable("the state machine is flat")
    regions = tree_regions(source)
    if not regions:
        raise NotDecomposable("no region with memory (the static table decides the tree)")
    machine_regions = fsm_regions(result, region_labels(source, regions))
    if not machine_regions:
        raise NotDecomposable("the machine has no region state")
    declared = _declared(result)
    names = set(declared)
    owner: dict[str, int] = {}
    mentioned: list[set[str]] = []
    for j, region in enumerate(machine_regions):
        used = mentioned_names(region.machine, names) | {
            w for w in _IDENT.findall(region.state.attrs.get(ONEXIT, "")) if w in names
        }
        for name in used:
            if owner.setdefault(name, j) != j:
                raise NotDecomposable(f"variable {name} is shared by two regions")
        mentioned.append(used)
    return Structure(regions, machine_regions, declared, mentioned)


def region_machines(shape: Structure, k: int, j: int) -> tuple[LeafMachine, FSMLeafMachine]:
    """Part 1's two machines for tree region ``k`` paired with region state ``j``: the
    region's subtree as a tree of its own (the interpreter's leaf machine) and the state's
    sub-machine as a machine of its own (its own variables declared)."""
    region = shape.machine_regions[j]
    return (
        LeafMachine(BTDocument.single(shape.regions[k])),
        FSMLeafMachine(region_fsm(region, shape.declared, shape.mentioned[j])),
    )


def results_allowed(possible: frozenset[str], shape: Structure, j: int) -> bool:
    """Side condition (2) of docs/semantics.md §4c: the results a region reaches are non-empty,
    within {SUCCESS, FAILURE} and within the completions its region state has."""
    exits = set(shape.machine_regions[j].exits)
    return bool(possible) and possible <= {SUCCESS, FAILURE} and possible <= exits


def skeleton_machines(
    source: BTDocument,
    result: FSM,
    shape: Structure,
    tree_of_state: dict[int, int],
    results: dict[int, frozenset[str]],
) -> tuple[LeafMachine, FSMLeafMachine]:
    """Part 2's two machines: the skeletons with each paired region abstracted to the results
    it reaches (``results``: tree region -> results; an unpaired region may return either and
    keeps its own label, so the skeleton check fails if it is ever reached), the FSM's
    region-state labels renamed to their partners'."""
    bt_skeleton, fsm_skeleton = skeleton_models(source, result, shape, tree_of_state, results)
    return LeafMachine(bt_skeleton), FSMLeafMachine(fsm_skeleton)


def skeleton_models(
    source: BTDocument,
    result: FSM,
    shape: Structure,
    tree_of_state: dict[int, int],
    results: dict[int, frozenset[str]],
) -> tuple[BTDocument, FSM]:
    """The two models ``skeleton_machines`` runs (another engine checks them too)."""
    both = frozenset({SUCCESS, FAILURE})
    tree_results = [results.get(k, both) for k in range(len(shape.regions))]
    fsm_results = [
        results[tree_of_state[j]] if tree_of_state.get(j) in results else frozenset(r.exits)
        for j, r in enumerate(shape.machine_regions)
    ]
    bt_skeleton = skeleton_tree(source, shape.regions, tree_results)
    fsm_skeleton = skeleton_fsm(result, shape.machine_regions, fsm_results)
    _rename(
        fsm_skeleton,
        {_FSM_TOKEN.format(j): _BT_TOKEN.format(k) for j, k in tree_of_state.items()},
    )
    return bt_skeleton, fsm_skeleton


#: The kind of a certificate unit that is one distinct local check of a region proven per node.
PERNODE_UNIT = "pernode"


@dataclass
class Part:
    """One local check of a compositional proof, kept for a certificate: its kind
    (``region``, ``pernode`` or ``skeleton``), the native checker's witness and, for a region
    or a per-node check, the tree region ``k`` and region state ``j`` it pairs; for a per-node
    check, the paths of the nodes it stands for, σ (status -> canonical exit) and whether it
    held with ``halt`` offered (``verify/pernode.py``)."""

    kind: str
    witness: Any
    tree_region: int = -1
    fsm_region: int = -1
    nodes: list[str] = field(default_factory=list)
    sigma: dict[int, tuple[int, tuple[int, ...]]] = field(default_factory=dict)
    can_halt: bool = False


@dataclass
class Parts:
    """A compositional proof's parts as a certificate lists them: the decomposition (the tree
    regions' labels, the region states' paths) and each part's witness, regions first, the
    skeleton last."""

    tree_regions: list[str] = field(default_factory=list)
    fsm_regions: list[str] = field(default_factory=list)
    units: list[Part] = field(default_factory=list)


@dataclass
class CheckPlan:
    """What a compositional check decided, for another engine to decide again (NuSMV,
    ``fsmbt.verify.nusmv.pernode``): each region proven per node with its distinct local
    checks (``LocalUnit``, the failing one last), and the parts checked whole - each region
    that was not, and the skeleton - as (name, tree, machine) pairs of models; ``refused``:
    each region written per node that the per-node check refused, with the side condition it
    named (``NotPerNode``'s message; what ``benchmarks/bench_pernode_outside.py`` classifies)."""

    units: list[tuple[str, list[LocalUnit]]] = field(default_factory=list)
    wholes: list[tuple[str, BTDocument, FSM]] = field(default_factory=list)
    refused: list[tuple[str, str]] = field(default_factory=list)


def decompose(
    source: BTDocument,
    result: FSM,
    *,
    max_states: int = DEFAULT_MAX_STATES,
    keep: Parts | None = None,
    min_regions: int = 1,
    max_seconds: float | None = None,
    plan: CheckPlan | None = None,
    unticked: frozenset[int] = frozenset(),
    whole: frozenset[int] = frozenset(),
    stages: dict[int, StagesNeverGoingOn] | None = None,
) -> Decomposition:
    """Run the three parts of the compositional check (module docstring); with ``keep``, each
    part's witness is appended to it (for a certificate: the parts' tables stay alive); with
    ``plan``, what each part checked is recorded (``CheckPlan``; no extra check).

    ``whole``: tree regions (indices of ``Structure.regions``) checked whole even when written
    per node (their per-node check failed and no run to the failure was lifted: a small
    region's whole check decides, and proves it where the per-node abstraction cannot).

    ``stages``: per tree region, the stages proven never to go on inside it
    (``verify/narrow.py``), which its per-node check is told, and where a failure past a broken
    entry condition that the lift does not reach adds more (``_past_stages``); ``None``: not
    used (a certificate or a plan, which list what was checked).

    ``unticked``: tree regions (indices of ``Structure.regions``) proven never ticked in the
    whole tree (``tickable.stage_never_passes``): not checked, each standing in the skeleton
    for an action that may return any result its region state has (docs/semantics.md §4c,
    "Regions never ticked").

    The give-way (the attempt costs little when it cannot win): with fewer than
    ``min_regions`` paired regions no part is checked (one region *is* the whole product,
    checked again, e.g. a tree whose root is reactive: the region is the whole tree), and the
    parts' checks share one wall-clock budget of ``max_seconds`` (default: the checker's limit).

    Raises:
        NotDecomposable: the pair is outside the scope or past the budget; the caller falls back.
    """
    budget = _Budget(max_seconds)
    shape = structure(source, result)
    regions, machine_regions = shape.regions, shape.machine_regions
    if keep is not None:
        keep.tree_regions, keep.fsm_regions = shape.tree_labels(), shape.fsm_paths()
    # 1. the skeleton pairing needs the results, the results need the pairing: pair first on
    # the widest abstraction (every region may succeed or fail), then check each pair
    both = frozenset({SUCCESS, FAILURE})
    wide_tree = skeleton_tree(source, regions, [both] * len(regions))
    wide_fsm = skeleton_fsm(result, machine_regions, None)
    pairs = pair_regions(LeafMachine(wide_tree), FSMLeafMachine(wide_fsm), max_states)
    tree_of_state = {
        int(fsm_token[len("⟪state ") : -1]): int(tree_token[len("⟪unit ") : -1])
        for fsm_token, tree_token in pairs.items()
    }
    per_node_possible = any(_tagged_per_node(machine_regions[j].machine) for j in tree_of_state)
    if len(tree_of_state) < min_regions and not per_node_possible:
        raise NotDecomposable(
            f"{len(tree_of_state)} region(s) paired: the whole product is the same check"
        )
    # a region the walk never reaches keeps its own label: if the skeleton check reaches it
    # after all, its label differs from anything on the other side and the check fails
    outcome = Decomposition(equivalent=True, regions=len(tree_of_state))
    results: dict[int, frozenset[str]] = {}
    for j, region in enumerate(machine_regions):
        k = tree_of_state.get(j)
        if k is None:
            continue
        name = f"{regions[k].label} (state {region.path})"
        if k in unticked:
            possible = frozenset(region.exits) & both
            if not possible:
                raise NotDecomposable(f"region {regions[k].label} has no completion")
            results[k] = possible
            outcome.stats.setdefault("regions_never_ticked", []).append(name)
            continue
        local: list[LocalWitness] | None = [] if keep is not None else None
        units: list[LocalUnit] | None = [] if plan is not None else None
        if k in whole:
            per_node = None
            outcome.stats.setdefault("per_node_refused", []).append(
                f"{name}: checked whole, its per-node check fails and no run was lifted"
            )
        else:
            told = None if stages is None or k not in stages else stages[k].never
            per_node = _per_node(
                regions[k], region.machine, shape.declared, outcome, local, units, told
            )
        candidate: PerNodeOutcome | None = None
        if per_node is not None and per_node.tolerated is not None:
            # a failure past a broken entry condition (``check_region``'s ``tolerate``) is
            # only a candidate, kept when the lift replays it on the two whole machines: on a
            # small region after the region's whole check (its counterexample is a shortest
            # one) could not decide, on a large one before it (docs/verification.md §5)
            candidate, per_node = per_node, None
            outcome.stats.setdefault("per_node_refused", []).append(candidate.tolerated)
            if len(region.machine.states) > WHOLE_FIRST:
                if _use_candidate(source, result, regions[k], candidate, outcome, name):
                    if plan is not None and units is not None:
                        plan.units.append((name, units))
                    return outcome
                if stages is not None and candidate.tree is not None:
                    known = stages.setdefault(k, StagesNeverGoingOn(candidate.tree))
                    per_node, lifted = _past_stages(
                        (source, result),
                        regions[k],
                        region.machine,
                        shape.declared,
                        candidate,
                        outcome,
                        known,
                        name,
                    )
                    if lifted:
                        return outcome
                if per_node is None and _use_candidate(
                    source, result, regions[k], candidate, outcome, name, walk=True
                ):
                    if plan is not None and units is not None:
                        plan.units.append((name, units))
                    return outcome
                candidate = None
        if per_node is None and plan is not None and _tagged_per_node(region.machine):
            reason = outcome.stats.get("per_node_refused", ["?"])[-1]
            plan.refused.append((f"{regions[k].label} (state {region.path})", reason))
        if per_node is not None:  # proven (or refuted) node by node (verify/pernode.py)
            if plan is not None and units is not None:
                plan.units.append((f"{regions[k].label} (state {region.path})", units))
            if not per_node.equivalent:
                outcome.equivalent = False
                outcome.failed_region = (
                    f"{regions[k].label} (state {region.path}), node {per_node.failed}"
                )
                outcome.per_node_failure = (regions[k], per_node)
                outcome.failed_index = k
                outcome.failed_small = len(region.machine.states) <= WHOLE_FIRST
                return outcome
            possible = per_node.results
            if not results_allowed(possible, shape, j):
                raise NotDecomposable(f"region {regions[k].label} ends in {sorted(possible)}")
            results[k] = possible
            if keep is not None and local is not None:  # one unit per distinct local check
                keep.units.extend(
                    Part(PERNODE_UNIT, w.witness, k, j, w.nodes, w.sigma, w.can_halt) for w in local
                )
            continue
        if plan is not None:
            plan.wholes.append(
                (
                    f"region {regions[k].label} (state {region.path})",
                    BTDocument.single(regions[k]),
                    region_fsm(region, shape.declared, shape.mentioned[j]),
                )
            )
        try:  # building the machines may stop at a limit too (the data expansion)
            # a second try after a per-node failure: a small expansion only
            with (
                limits.changed(conversion_max_states=WHOLE_AFTER_FAILURE_STATES)
                if k in whole
                else contextlib.nullcontext()
            ):
                bt_region, fsm_region = region_machines(shape, k, j)
            report, witness = check_witnessed(
                bt_region, fsm_region, max_states=max_states, max_seconds=budget.left()
            )
        except FsmbtError as exc:
            if candidate is not None and _use_candidate(
                source, result, regions[k], candidate, outcome, name
            ):
                if plan is not None and units is not None:
                    plan.wholes.pop()  # decided node by node after all
                    plan.refused.pop()
                    plan.units.append((name, units))
                return outcome
            if isinstance(exc, StateLimitError):
                raise NotDecomposable(f"region {regions[k].label}: {exc}") from None
            raise
        _add(outcome.stats, report.stats)
        outcome.region_states += report.stats["product_states"]
        outcome.largest_region = max(outcome.largest_region, report.stats["product_states"])
        if not report.equivalent:
            outcome.equivalent = False
            outcome.failed_region = f"{regions[k].label} (state {region.path})"
            # lifted by verify/lift.py, confirmed by replay on the two whole machines (the
            # result run by verify/lazy_fsm.py, tested step for step against the flattened
            # machine on regions written whole and per node and their mutants)
            outcome.region_failure = (regions[k], report)
            outcome.failed_index = k
            return outcome
        possible = _results(witness)
        if not results_allowed(possible, shape, j):
            raise NotDecomposable(f"region {regions[k].label} ends in {sorted(possible)}")
        results[k] = possible
        if keep is not None:
            keep.units.append(Part("region", witness, k, j))
    # 2. the skeleton with each region abstracted to its results
    skeleton_bt, skeleton_fsm_model = skeleton_models(source, result, shape, tree_of_state, results)
    if plan is not None:
        plan.wholes.append(("the skeleton", skeleton_bt, skeleton_fsm_model))
    bt_skeleton, fsm_skeleton = LeafMachine(skeleton_bt), FSMLeafMachine(skeleton_fsm_model)
    try:
        report, witness = check_witnessed(
            bt_skeleton, fsm_skeleton, max_states=max_states, max_seconds=budget.left()
        )
    except StateLimitError as exc:
        raise NotDecomposable(f"the skeleton: {exc}") from None
    _add(outcome.stats, report.stats)
    outcome.skeleton_states = report.stats["product_states"]
    if not report.equivalent:
        # the skeletons differ: a real difference outside the regions, or a tree whose
        # non-plain leaves the machine keeps as plain states; the whole product tells which
        raise NotDecomposable("the skeletons differ")
    if keep is not None:
        keep.units.append(Part("skeleton", witness))
    return outcome


class _Budget:
    """The wall-clock seconds the parts' checks share (``None``: each part gets the checker's
    own limit)."""

    def __init__(self, seconds: float | None) -> None:
        self.ends = None if seconds is None else time.perf_counter() + seconds

    def left(self) -> float | None:
        """Seconds left for the next part (at least a millisecond: a part past the budget
        stops at its first clock reading, ``native._Deadline``)."""
        if self.ends is None:
            return None
        return max(self.ends - time.perf_counter(), 0.001)


def _tagged_per_node(machine: FSM) -> bool:
    """Whether the converter wrote this region per node (its states carry ``fsmbt:node``)."""
    return any(NODE_ATTR in state.attrs for state in machine.states.values())


def _per_node(
    region_root: BTNode,
    machine: FSM,
    declared: dict[str, str],
    outcome: Decomposition,
    keep: list[LocalWitness] | None = None,
    units: list[LocalUnit] | None = None,
    never: Mapping[int, frozenset[int]] | None = None,
) -> PerNodeOutcome | None:
    """The per-node check of one region (``verify/pernode.py``) when its machine is tagged
    per node and decomposes; ``None``: check the region whole. With ``keep``, the distinct
    local checks' witnesses are appended (for a certificate); with ``units``, the distinct
    local checks (for NuSMV); ``never``: statuses stages are proven never to return
    (``verify/narrow.py``)."""
    if not _tagged_per_node(machine):
        return None
    try:
        found = check_region(
            region_root, machine, declared, keep, units, tolerate=True, never=never
        )
    except NotPerNode as exc:
        outcome.stats.setdefault("per_node_refused", []).append(str(exc))
        return None
    _tally(outcome.stats, found, 1)
    return found


def _tally(stats: dict[str, Any], found: PerNodeOutcome, sign: int) -> None:
    """Count (``sign`` 1) or take back (-1) one region's per-node check in ``stats``."""
    for key, value in (
        ("per_node_regions", 1),
        ("per_node_nodes", found.nodes),
        ("per_node_distinct", found.distinct),
        ("per_node_local_states", found.local_states),
        ("per_node_unticked", found.unticked),
        ("per_node_unfired", found.unfired),
    ):
        stats[key] = stats.get(key, 0) + sign * value


#: Most rounds of stage proofs one region's per-node check takes (``_past_stages``).
STAGE_ROUNDS = 3
#: Most stages one region may have proven never to go on (each proof costs a search and a
#: pass of ``decompose``).
MAX_STAGES = 8
#: What a verdict says when a stage's proof made nodes dead.
NEVER_GO_ON_SENTENCE = (
    "stages that never go on: a node whose local check failed and that no lifted run reached "
    "is skipped when an earlier sibling on its path, run alone exhaustively, never returns "
    "what its parent goes on with; the parent is then offered only what that sibling can "
    "return (docs/semantics.md §4d, 'Children that never go on')"
)


def _past_stages(
    pair: tuple[BTDocument, FSM],
    region_root: BTNode,
    machine: FSM,
    declared: dict[str, str],
    failed: PerNodeOutcome,
    outcome: Decomposition,
    stages: StagesNeverGoingOn,
    name: str,
) -> tuple[PerNodeOutcome | None, bool]:
    """A per-node failure no run reaches (the lift found none): prove stages on the failing
    nodes' paths never go on (``verify/narrow.py``; docs/semantics.md §4d, "Children that
    never go on") and check the region again knowing it, up to ``STAGE_ROUNDS`` rounds. The
    answer: the last check (proven, or failing with its side conditions intact: the caller's
    rules go on from it; a failure past a broken entry condition is lifted first, and when
    it is, the second item is True and ``outcome`` is that NOT EQUIVALENT), or ``None``: no
    stage proven, or the check refused; the region is then checked whole as before."""
    for _round in range(STAGE_ROUNDS):
        if len(stages.never) >= MAX_STAGES or not stages.add_for(failed.seen):
            return None, False
        _tally(outcome.stats, failed, -1)  # counted again as the new check
        try:
            found = check_region(region_root, machine, declared, tolerate=True, never=stages.never)
        except NotPerNode as exc:
            outcome.stats.setdefault("per_node_refused", []).append(str(exc))
            return None, False
        _tally(outcome.stats, found, 1)
        if found.tolerated is None:
            return found, False
        if _use_candidate(*pair, region_root, found, outcome, name):
            return None, True
        failed = found
    return None, False


def _use_candidate(
    source: BTDocument,
    result: FSM,
    region: BTNode,
    failed: PerNodeOutcome,
    outcome: Decomposition,
    name: str,
    walk: bool = False,
) -> bool:
    """Lift a per-node failure found past a broken entry condition - by the planned drive
    (``lift.lifted_report``), or with ``walk`` by seeded random runs when no drive reached it
    (``lift.walked_report``); when the replay separates the two whole machines, ``outcome`` is
    that NOT EQUIVALENT (``lifted``: the report) and the answer is True; else (no separation,
    or the lift cannot run: nothing claimed) False."""
    started = time.perf_counter()
    try:
        if walk:
            report = walked_report(source, result, f"node {failed.failed}")
        else:
            report = lifted_report(source, result, region, failed)
    except FsmbtError:
        return False
    if report is None:
        return False
    report.stats["lift_seconds"] = round(time.perf_counter() - started, 6)
    outcome.lifted = report
    outcome.equivalent = False
    outcome.failed_region = f"{name}, node {failed.failed}"
    outcome.per_node_failure = (region, failed)
    return True


def _lifted(source: BTDocument, result: FSM, found: Decomposition) -> Report | None:
    """NOT EQUIVALENT with the failing node's local counterexample, or the failing region's
    own, lifted to the whole tree and confirmed by replay (``verify/lift.py``), or ``None``:
    the whole product decides."""
    started = time.perf_counter()
    try:
        if found.lifted is not None:
            report: Report | None = found.lifted
        elif found.per_node_failure is not None:
            report = lifted_report(source, result, *found.per_node_failure)
        else:
            assert found.region_failure is not None
            report = lifted_region_report(source, result, *found.region_failure)
    except FsmbtError:
        return None
    if report is None:
        return None
    if found.per_node_failure is not None:
        report.abstractions.insert(0, PER_NODE_SENTENCE)
    else:
        report.abstractions.insert(0, COMPOSITIONAL_SENTENCE)
    report.stats.update(found.stats)
    if found.per_node_failure is not None:
        report.stats["per_node_failed"] = found.failed_region
        report.stats.setdefault("per_node_regions", 1)
        if found.per_node_failure[1].tolerated is not None:
            report.stats["per_node_broken"] = found.per_node_failure[1].tolerated
    else:
        report.stats["failed_region"] = found.failed_region
    report.stats["regions"] = found.regions
    report.stats.setdefault("lift_seconds", round(time.perf_counter() - started, 6))
    if found.per_node_failure is not None and not report.stats.get("shortest"):
        started = time.perf_counter()
        bound = per_node_lower_bound(source, result, *found.per_node_failure)
        report.stats["lower_bound_seconds"] = round(time.perf_counter() - started, 6)
        _claim_by_bound(report, bound)
    return report


def per_node_lower_bound(
    source: BTDocument, result: FSM, region: BTNode, failed: PerNodeOutcome
) -> LowerBound | None:
    """The lower bound of ``verify/lower_bound.py`` on any counterexample of the pair, when
    its conditions hold (docs/semantics.md §4d, "A lower bound on any counterexample"): the
    per-node failure broke no entry condition; the complete walk of its region decides every
    local check; every other paired region is proven (per node, else whole) with results its
    state completes on; and the skeleton is equivalent with each proven region abstracted to
    its results and the failing one to the results its root's settled interface pairs (else to
    every completion its state has) - §4c, read prefix by prefix. ``None`` otherwise (nothing
    is claimed). Cost: the regions' checks and the per-node walk again, the skeleton's
    product, and ``lower_bound``'s searches (about 3 s on the 15 560-node mutant)."""
    if failed.tolerated is not None:
        return None
    try:
        shape = structure(source, result)
        both = frozenset({SUCCESS, FAILURE})
        regions, machine_regions = shape.regions, shape.machine_regions
        pairs = pair_regions(
            LeafMachine(skeleton_tree(source, regions, [both] * len(regions))),
            FSMLeafMachine(skeleton_fsm(result, machine_regions, None)),
            DEFAULT_MAX_STATES,
        )
        tree_of_state = {
            int(fsm_token[len("⟪state ") : -1]): int(tree_token[len("⟪unit ") : -1])
            for fsm_token, tree_token in pairs.items()
        }
        results: dict[int, frozenset[str]] = {}
        walk = None
        for j, k in tree_of_state.items():
            machine = machine_regions[j].machine
            if regions[k] is region:
                walk = complete_walk(region, machine, shape.declared)
                if results_allowed(walk.results, shape, j):
                    results[k] = walk.results
                continue
            possible = _proven_results(shape, k, j)
            if possible is None or not results_allowed(possible, shape, j):
                return None
            results[k] = possible
        if walk is None:
            return None
        bt_skeleton, fsm_skeleton = skeleton_models(source, result, shape, tree_of_state, results)
        if not check(LeafMachine(bt_skeleton), FSMLeafMachine(fsm_skeleton)).equivalent:
            return None
        merged = walk.walk.tree.doc.main.root
        assert merged is not None
        whole = CompiledTree(whole_tree(source, region, merged))
        return lower_bound(whole, walk)
    except (NotDecomposable, NotPerNode, FsmbtError):
        return None


def _proven_results(shape: Structure, k: int, j: int) -> frozenset[str] | None:
    """The results of tree region ``k`` when it is proven equivalent to region state ``j``
    (per node when written so, else its whole product), else ``None``."""
    machine = shape.machine_regions[j].machine
    if _tagged_per_node(machine):
        try:
            found = check_region(shape.regions[k], machine, shape.declared)
        except NotPerNode:
            found = None
        if found is not None:
            return found.results if found.equivalent else None
    bt_region, fsm_region = region_machines(shape, k, j)
    report, witness = check_witnessed(bt_region, fsm_region)
    return _results(witness) if report.equivalent else None


def _named(path: str) -> str:
    """A failing node as a verdict names it: its path in its region, or the region's root
    (``lower_bound`` names that one "the root")."""
    return "its region's root" if path == "the root" else f"node {path}"


def _claim_by_bound(report: Report, bound: LowerBound | None) -> None:
    """Record the bound; when it meets the counterexample's length, the verdict says the
    counterexample is shortest and names the method."""
    length = report.stats.get("lifted_steps")
    if bound is None or not isinstance(length, int):
        return
    report.stats["shortest_lower_bound"] = bound.bound
    if bound.bound < length:
        report.abstractions.append(
            f"not known to be shortest by the lower bound either: no counterexample can be "
            f"shorter than {bound.bound} inputs (the per-node proof, docs/semantics.md §4d: "
            f"{bound.before} leaf outcomes before {_named(bound.node)} is first ticked, "
            f"{bound.inside} under it), {length - bound.bound} short of this one"
            + (
                f" (a search of the coupled stages stopped at its limit: raise "
                f"{limits.env_name('shortest_max_labels')}, now "
                f"{limits.current().shortest_max_labels})"
                if bound.cut
                else ""
            )
        )
        return
    if bound.bound > length:
        return  # it would contradict the replay: never claimed (the tests assert it is not)
    report.stats["shortest"] = True
    report.stats["shortest_method"] = "lower bound"
    said = (
        f"shortest: no counterexample can be shorter than {length} inputs (a lower bound from "
        f"the per-node proof, docs/semantics.md §4d: every local check decided, {bound.failing} "
        f"failing; a difference needs a failing node's local pair to differ, at least "
        f"{bound.before} leaf outcomes before {_named(bound.node)} is first ticked and "
        f"{bound.inside} under it)"
    )
    report.abstractions = [
        said if a.startswith("not known to be shortest") else a for a in report.abstractions
    ]


def _add(total: dict[str, Any], part: dict[str, Any]) -> None:
    """Sum each part's state and edge counts (the figures a verdict prints)."""
    for key in ("source_states", "result_states", "product_states", "product_edges"):
        total[key] = total.get(key, 0) + part.get(key, 0)


#: What a verdict says when a region was set aside as never ticked.
NEVER_TICKED_SENTENCE = (
    "regions never ticked: a region whose check failed is set aside when an earlier sibling "
    "of one of its ancestors, run alone under any ticks and halts, never returns what its "
    "parent goes on with (docs/semantics.md §4c, 'Regions never ticked'); the skeleton check "
    "then proves the machine never enters its state either"
)
#: Most failing regions one compositional check sets aside as never ticked (each costs one
#: more pass of ``decompose``).
MAX_UNTICKED = 8


class _NeverTicked:
    """Proofs that a failing region is never ticked in the whole tree
    (``tickable.stage_never_passes``), the searches shared between regions."""

    def __init__(self, source: BTDocument) -> None:
        self.tree = CompiledTree(source)
        self.searches = NeverReturns(self.tree)
        #: per region set aside: its label and the stage that never goes on (its path)
        self.proofs: list[str] = []

    def region(self, found: Decomposition) -> bool:
        """Whether the region that failed in ``found`` is proven never ticked (its proof
        recorded); ``False`` when not proven, or when the searches refuse the tree."""
        failure = found.per_node_failure or found.region_failure
        if failure is None:
            return False
        ids = [n.id for n in self.tree.nodes if n.source is failure[0]]
        if len(ids) != 1:
            return False
        try:
            proof = stage_never_passes(self.tree, ids[0], self.searches)
        except FsmbtError:
            return False
        if proof is None:
            return False
        stage = self.tree.nodes[proof[0]]
        self.proofs.append(
            f"{failure[0].label}: its earlier {stage.type} at {stage.path or 'the root'} "
            f"never returns {' or '.join(sorted(NodeStatus(s).name for s in proof[1]))}"
        )
        return True


def _marks(keep: Parts | None, plan: CheckPlan | None) -> tuple[int, ...]:
    """How much ``keep`` and ``plan`` hold before a pass (``_rewind`` drops the rest)."""
    held = [len(keep.units)] if keep is not None else [0]
    if plan is not None:
        held += [len(plan.wholes), len(plan.refused)]
    return tuple(held)


def _rewind(keep: Parts | None, plan: CheckPlan | None, marks: tuple[int, ...]) -> None:
    """Drop what a failed pass added to ``keep`` and to ``plan``'s parts checked whole (the
    next pass lists them again). ``plan``'s local checks stay: each was decided, and NuSMV
    decides each again, the failing one included (docs/nusmv.md, "Trees node by node")."""
    if keep is not None:
        del keep.units[marks[0] :]
    if plan is not None:
        del plan.wholes[marks[1] :]
        del plan.refused[marks[2] :]


def compositional_report(
    source: BTDocument,
    result: FSM,
    *,
    max_states: int = DEFAULT_MAX_STATES,
    keep: Parts | None = None,
    min_regions: int = 1,
    max_seconds: float | None = None,
    plan: CheckPlan | None = None,
) -> tuple[Report | None, str]:
    """The compositional verdict when it proves the pair equivalent, else ``None`` and why
    (out of scope, past its budget, or a part failed: the caller runs the whole product for
    the verdict and its counterexample). With ``keep``, each part's witness is appended (for a
    certificate); ``min_regions`` and ``max_seconds``: the give-way of ``decompose``.
    Cost: see the module docstring."""
    started = time.perf_counter()
    unticked: set[int] = set()
    whole: set[int] = set()
    tried: set[int] = set()
    #: the region just put in ``whole`` and the failure that sent it there: if its whole
    #: check gives up (a limit), the rules below go on from that failure
    pending: tuple[int, Decomposition] | None = None
    never: _NeverTicked | None = None
    # stages proven never to go on, per region (verify/narrow.py); not for a certificate or
    # a plan, which list what was checked
    stages: dict[int, StagesNeverGoingOn] | None = {} if keep is None and plan is None else None
    while True:
        marks = _marks(keep, plan)
        try:
            found = decompose(
                source,
                result,
                max_states=max_states,
                keep=keep,
                min_regions=min_regions,
                max_seconds=max_seconds,
                plan=plan,
                unticked=frozenset(unticked),
                whole=frozenset(whole),
                stages=stages,
            )
        except (NotDecomposable, FsmbtError) as exc:
            if pending is None:
                if isinstance(exc, NotDecomposable):
                    return None, str(exc)
                # a part the machines refuse (a limit, a construct): the whole product
                # decides and gives the error or verdict it gave before
                return None, f"a part cannot be checked ({type(exc).__name__})"
            _rewind(keep, plan, marks)
            whole.discard(pending[0])
            found, pending = pending[1], None
        else:
            pending = None
            if found.equivalent:
                break
            if found.per_node_failure is not None or found.region_failure is not None:
                lifted = _lifted(source, result, found)
                if lifted is not None:
                    return lifted, ""
        k = found.failed_index
        if found.per_node_failure is not None and found.failed_small and k not in tried:
            # no run found to a per-node failure in a small region: the region's whole check
            # (part 1) decides - it proves the region where the per-node abstraction is too
            # coarse, or gives a counterexample from the region's fresh tick to lift; what the
            # failed pass kept for a certificate or a plan is dropped (listed once)
            assert k is not None
            _rewind(keep, plan, marks)
            whole.add(k)
            tried.add(k)
            pending = (k, found)
            continue
        # no run found to a per-node failure: a stage on its path that never goes on makes it
        # dead; the check runs again knowing it (docs/semantics.md §4d, "Children that never
        # go on")
        if stages is not None and k is not None and found.per_node_failure is not None:
            failed = found.per_node_failure[1]
            if failed.tree is not None:
                known = stages.setdefault(k, StagesNeverGoingOn(failed.tree))
                if len(known.never) < MAX_STAGES and known.add_for(failed.seen):
                    continue
        # no run found to the failure: a region the whole tree never ticks is no difference
        # (docs/semantics.md §4c, "Regions never ticked"); not for a certificate or a plan,
        # which list what was checked
        if keep is None and plan is None and k is not None and k not in unticked:
            try:
                never = never or _NeverTicked(source)
            except FsmbtError:  # the whole tree does not compile: nothing is set aside
                return None, f"{FAILED_PART} {found.failed_region} fails"
            if len(unticked) < MAX_UNTICKED and never.region(found):
                unticked.add(k)
                continue
        # no rule sets the failure aside and no planned drive reached it: seeded random runs
        # may still (a real counterexample when one separates the machines); in a large region
        # only - a small one's whole product is cheap and gives a shortest counterexample
        if found.per_node_failure is not None and not found.failed_small:
            walked = walked_report(source, result, found.failed_region or "a region")
            if walked is not None:
                return walked, ""
        return None, f"{FAILED_PART} {found.failed_region} fails"
    seconds = time.perf_counter() - started
    report = Report(engine="native", source="source", result="result", mode=LEAF_EXECUTION)
    detail = (
        f"proved compositionally: {found.regions} regions checked alone "
        f"({found.region_states} product states, largest {found.largest_region}) and the "
        f"skeleton ({found.skeleton_states} product states)"
    )
    for name in PROPERTIES:
        report.properties[name] = PropertyResult(name, True, detail)
    report.method = COMPOSITIONAL
    report.abstractions = [COMPOSITIONAL_SENTENCE]
    if found.stats.get("per_node_regions"):
        report.method = PER_NODE
        report.abstractions.append(PER_NODE_SENTENCE)
        detail += (
            f"; {found.stats['per_node_regions']} of them node by node "
            f"({found.stats['per_node_nodes']} nodes, {found.stats['per_node_distinct']} "
            "distinct local checks"
            + (
                f", {found.stats['per_node_unticked']} nodes the tree never ticks skipped"
                if found.stats.get("per_node_unticked")
                else ""
            )
            + (
                f", {found.stats['per_node_unfired']} transitions no local check follows left "
                "out of the entry condition"
                if found.stats.get("per_node_unfired")
                else ""
            )
            + ")"
        )
        for name in PROPERTIES:
            report.properties[name] = PropertyResult(name, True, detail)
    if whole:
        report.stats["regions_checked_whole"] = len(whole)
        detail += (
            f"; {len(whole)} region(s) written per node checked whole (their per-node check "
            "failed and no run to the failure was lifted)"
        )
        for name in PROPERTIES:
            report.properties[name] = PropertyResult(name, True, detail)
    proofs = [proof for known in (stages or {}).values() for proof in known.proofs]
    if proofs:
        report.stats["never_go_on"] = proofs
        detail += "; nodes behind a stage that never goes on skipped: " + "; ".join(proofs)
        report.abstractions.append(NEVER_GO_ON_SENTENCE)
        for name in PROPERTIES:
            report.properties[name] = PropertyResult(name, True, detail)
    if never is not None and found.stats.get("regions_never_ticked"):
        report.stats["never_ticked_by"] = never.proofs
        detail += "; not checked, never ticked by the tree: " + "; ".join(never.proofs)
        report.abstractions.append(NEVER_TICKED_SENTENCE)
        for name in PROPERTIES:
            report.properties[name] = PropertyResult(name, True, detail)
    report.stats = {
        **report.stats,
        **found.stats,
        "regions": found.regions,
        "region_product_states": found.region_states,
        "largest_region": found.largest_region,
        "skeleton_product_states": found.skeleton_states,
        "seconds": round(seconds, 6),
    }
    return report, ""
