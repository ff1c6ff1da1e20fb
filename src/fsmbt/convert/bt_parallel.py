"""A BT ``Parallel`` / ``ParallelAll`` as an SCXML ``<parallel>``: one region per child, the
thresholds as data (docs/semantics.md §6a, "Parallel as `<parallel>`"; docs/conversion.md).

BehaviorTree.CPP 4.8.2's Parallel ticks its not yet completed children one after the other, in
order, within one tick, and checks its thresholds after each child's return (success first);
ParallelAll checks once every child has completed. A leaf-execution machine observes that
order leaf by leaf, so the regions must not run at once: they take **turns**. The composite
written for a Parallel ``P`` with children ``c0 .. c(n-1)`` is::

    <state P>                      onexit: P_turn = 0; P_successes = 0; P_failures = 0
      <parallel P_regions>
        <state P_r0> ... <state P_r(n-1)>      one region per child, document order
        done.state -> SUCCESS  cond: the success rule; done.state -> FAILURE
      <final SUCCESS/> <final FAILURE/>

Region ``i`` holds, for the child's subtree (plain: leaves, Sequence, Fallback, Inverter,
ForceSuccess, ForceFailure; wired by the paper's sequence and fallback rules, flat):

- one state per leaf (action: its label); a leaf's ``success``/``failure`` goes where the
  child's rules say (next leaf of the child, or the child's end);
- ``wait_<leaf>`` (no action) for every action leaf and for the child's first leaf: the region
  holds there while another region has the turn. An action's ``running`` ends the child's tick
  (a plain child returns RUNNING exactly when a leaf does, and its next tick resumes at that
  leaf): ``running -> wait_<leaf>`` with ``P_turn = (i+1) % n``;
- the child's end: ``-> DONE`` with ``P_successes + 1`` (or ``P_failures + 1``) and the turn
  passed on; ``DONE`` (no action) passes the turn on again whenever it comes back (a completed
  child is not ticked again);
- eventless transitions of ``wait_*`` and ``DONE``, in this order: ``cond stop -> END``
  (``<final>``), ``cond P_turn == i -> <leaf>`` (``DONE``: ``-> DONE``, the turn passed on).

A child that is not plain (memory, restarts, reactive re-checks) is explored alone with its
tick ends marked (``LeafMachine(mark_ticks=True)``: ``TICK_END`` where its root returns
RUNNING, a wake-up's re-tick included) and compacted (``bt_compact``, ``tick_marks``): its
leaf states and guarded transitions are the region's, a marked step goes to ``wait_<target>``
and passes the turn on, its ends go to ``DONE``; its variables join the composite's reset.
Alone or under the Parallel the child is ticked the same way, once per tick until it
completes, and halted with the Parallel.

Turn ``0`` after child ``n-1`` is the next tick: the Parallel heads its region, so its
ancestors (plain Sequence/Fallback/stateless decorators) resume straight into it.
``stop`` is ``P_successes >= S or P_failures >= F'`` with ``S`` the success threshold and
``F' = min(F, n - S + 1)`` (failure threshold, or success no longer possible); ParallelAll:
``P_successes + P_failures >= n``. When it holds every region reaches ``END`` in the same
macro step (W3C: eventless transitions before the next event), the ``<parallel>`` completes
and its first ``done.state`` transition whose ``cond`` holds gives the result: SUCCESS when
``P_successes >= S`` (success is checked first, as BehaviorTree.CPP does), else FAILURE
(ParallelAll: FAILURE when ``P_failures >= max_failures``). Leaving the composite halts every
region (``haltChildren``) and resets the counters (its ``<onexit>``).

At every stable configuration exactly one region is at a leaf: the flat state's action (the
active atomic states' actions joined, empty ones dropped) is that leaf's label, the leaf the
Parallel ticks next. Proof obligation: the W3C meaning of the composite equals the Parallel's
leaf-execution machine (§4); the checker proves it for every conversion.

Not expressed (``parallel_region`` returns the reason; the caller keeps the product form and
warns): a child that can livelock or return its result in a tick that ticks none of its
leaves (the turn would have to pass without a leaf), a threshold of 0 (the node returns after
its first child whatever it does), a single child (nothing runs side by side) and a node with
a meaning other than the built-in one.

Costs: O(nodes of the Parallel's subtree) for plain children; a child that is not plain costs
its exploration and compaction (``bt_compact``'s costs), never the product of the children.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from fsmbt.convert.bt_compact import TICK_MARK, CompactRegion
from fsmbt.model.bt import BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import ASSIGN, COND, join_lines
from fsmbt.model.nodes import canonical_type
from fsmbt.semantics.families.parallel import COUNTING_PARALLELS, parallel_counts
from fsmbt.semantics.leaf_machine import leaf_label
from fsmbt.semantics.nodes import SEQUENCE_TYPES, rewired
from fsmbt.semantics.status import LeafOutcome, RootResult

SUCCESS, FAILURE = RootResult.SUCCESS.value, RootResult.FAILURE.value
EV_SUCCESS, EV_FAILURE, EV_RUNNING = (
    LeafOutcome.SUCCESS.value,
    LeafOutcome.FAILURE.value,
    LeafOutcome.RUNNING.value,
)
DONE, END = "DONE", "END"
#: A child's end, as a target of the flat wiring: ("end", "success"/"failure").
_END_SUCCESS, _END_FAILURE = ("end", "s"), ("end", "f")


@dataclass
class ParallelRegion:
    """A Parallel as a composite holding one ``<parallel>``.

    Attributes:
        fsm: the composite's sub-machine (the parallel state, finals SUCCESS and FAILURE).
        ends: the final states it reaches (both).
        variables: ``(name, initial expression)`` of its counters and turn.
        regions: the regions written (one per child).
    """

    fsm: FSM
    ends: set[str]
    variables: list[tuple[str, str]]
    regions: int


def is_parallel_kind(node: BTNode) -> bool:
    """Whether ``node`` is a built-in Parallel or ParallelAll (a project type given that
    meaning by a node library is not: its ports may differ)."""
    kind = canonical_type(node.type)
    return kind in COUNTING_PARALLELS and node.semantics in (None, node.type)


def parallel_region(
    node: BTNode,
    *,
    name: str,
    plain: Callable[[BTNode], bool],
    new_variable: Callable[[str], str],
    compact_child: Callable[[BTNode], CompactRegion] | None = None,
) -> ParallelRegion | str:
    """``node`` (a Parallel/ParallelAll heading its region) as a ``<parallel>`` composite, or
    the reason it cannot be one exactly (see the module docstring).

    Args:
        node: the Parallel or ParallelAll.
        name: the composite's sub-machine name.
        plain: whether a node is one the paper's rules wire (leaves, plain Sequence/Fallback,
            stateless decorators); every node of every child must be.
        new_variable: a unique variable name for a base name (shared by the conversion).
        compact_child: a child that is not plain as a compact region of its tick-marked
            leaf-execution machine (``bt_compact``, ``tick_marks``); ``None``: such a child
            is a reason to keep the product form.

    Raises:
        InputError: a threshold above the number of children (as the interpreter).
    """
    n = len(node.children)
    if n < 2:
        return "a single child: no regions run side by side"
    counts = parallel_counts(node)
    assert counts is not None, "is_parallel_kind holds"
    need_s, need_f = counts.successes, counts.failures
    if not counts.waits_for_all and (need_s == 0 or need_f == 0):
        return "a threshold of 0 ends the node after its first child, whatever it returns"
    opaque: dict[int, BTNode] = {}
    for index, child in enumerate(node.children):
        stack = [child]
        while stack:
            inner = stack.pop()
            if not plain(inner):
                if compact_child is None:
                    return (
                        f"child {index + 1} holds {inner.type} '{inner.label}', whose memory "
                        "or restarts are not the paper's rules"
                    )
                opaque[index] = inner
                break
            stack.extend(inner.children)
    compacted: dict[int, CompactRegion] = {}
    for index in opaque:
        assert compact_child is not None
        try:
            compacted[index] = compact_child(node.children[index])
        except (InputError, UnsupportedError) as exc:
            return f"child {index + 1}: {getattr(exc, 'message', exc)}"
        odd = _odd_ends(compacted[index])
        if odd:
            return f"child {index + 1} {odd}"
    base = node.label
    turn = new_variable(f"{base}_turn")
    successes = new_variable(f"{base}_successes")
    failures = new_variable(f"{base}_failures")
    if not counts.waits_for_all:
        stop = f"{successes} >= {need_s} or {failures} >= {min(need_f, n - need_s + 1)}"
        first_end, first_cond = SUCCESS, f"{successes} >= {need_s}"
        other_end = FAILURE
    else:
        stop = f"{successes} + {failures} >= {n}"
        first_end, first_cond = FAILURE, f"{failures} >= {need_f}"
        other_end = SUCCESS
    sub = FSM(name=name)
    regions = []
    variables = [(turn, "0"), (successes, "0"), (failures, "0")]
    for i, child in enumerate(node.children):
        region_name = f"{name}_r{i}"
        counters = (turn, successes, failures, stop)
        if i in compacted:
            regions.append(_compact_region(compacted[i], i, n, region_name, *counters))
            variables.extend(compacted[i].variables)
        else:
            regions.append(_region(child, i, n, region_name, *counters))
    parallel_name = f"{base}_regions"
    sub.add_state(State(parallel_name, action=None, regions=regions))
    for result in (SUCCESS, FAILURE):
        sub.add_state(State(result, action=None, final=True))
    sub.initial = parallel_name
    sub.add_transition(parallel_name, None, first_end, attrs={COND: first_cond})
    sub.add_transition(parallel_name, None, other_end)
    return ParallelRegion(sub, {SUCCESS, FAILURE}, variables, len(regions))


def _region(
    child: BTNode,
    index: int,
    count: int,
    name: str,
    turn: str,
    successes: str,
    failures: str,
    stop: str,
) -> FSM:
    """Region ``index``: the child's leaves wired flat, its waits, DONE and END."""
    fsm = FSM(name=name)
    pass_on = f"{turn}={(index + 1) % count}"
    leaves: list[BTNode] = []
    stack = [child]
    while stack:  # leaves in document order
        node = stack.pop()
        if node.is_leaf:
            leaves.append(node)
        stack.extend(reversed(node.children))
    state_of: dict[int, str] = {}
    for leaf in leaves:
        state_of[id(leaf)] = _unique(fsm, leaf_label(leaf))
        fsm.add_state(State(state_of[id(leaf)], action=leaf_label(leaf)))
    first = _first_leaf(child)
    waits: dict[int, str] = {}
    for leaf in leaves:
        if leaf is first or leaf.kind is NodeKind.ACTION:
            waits[id(leaf)] = _unique(fsm, f"wait_{leaf_label(leaf)}")
            fsm.add_state(State(waits[id(leaf)], action=""))
    done = _unique(fsm, DONE)
    fsm.add_state(State(done, action=""))
    end = _unique(fsm, END)
    fsm.add_state(State(end, action="", final=True))
    fsm.initial = waits[id(first)]
    ends = {
        _END_SUCCESS: (done, join_lines([(successes, f"{successes} + 1")]) + "\n" + pass_on),
        _END_FAILURE: (done, join_lines([(failures, f"{failures} + 1")]) + "\n" + pass_on),
    }
    # wiring: (node, where its success goes, where its failure goes), targets being a leaf's
    # entry node or a child's end
    work: list[tuple[BTNode, object, object]] = [(child, _END_SUCCESS, _END_FAILURE)]
    while work:
        node, on_success, on_failure = work.pop()
        if node.kind is NodeKind.DECORATOR:
            on_success, on_failure = rewired(node.type, on_success, on_failure)
            work.append((node.children[0], on_success, on_failure))
            continue
        if node.is_leaf:
            source = state_of[id(node)]
            for event, target in ((EV_SUCCESS, on_success), (EV_FAILURE, on_failure)):
                if isinstance(target, tuple):
                    state, assign = ends[target]
                    fsm.add_transition(source, event, state, attrs={ASSIGN: assign})
                else:
                    assert isinstance(target, BTNode)
                    fsm.add_transition(source, event, state_of[id(_first_leaf(target))])
            if node.kind is NodeKind.ACTION:
                fsm.add_transition(source, EV_RUNNING, waits[id(node)], attrs={ASSIGN: pass_on})
            continue
        is_sequence = node.type in SEQUENCE_TYPES
        kids = node.children
        for k, kid in enumerate(kids):
            following: object = kids[k + 1] if k + 1 < len(kids) else None
            if is_sequence:
                work.append((kid, following if following is not None else on_success, on_failure))
            else:
                work.append((kid, on_success, following if following is not None else on_failure))
    for leaf_id, wait in waits.items():
        fsm.add_transition(wait, None, end, attrs={COND: stop})
        fsm.add_transition(wait, None, state_of[leaf_id], attrs={COND: f"{turn} == {index}"})
    fsm.add_transition(done, None, end, attrs={COND: stop})
    fsm.add_transition(done, None, done, attrs={COND: f"{turn} == {index}", ASSIGN: pass_on})
    return fsm


def _odd_ends(region: CompactRegion) -> str:
    """Why a child's compact region cannot be a turn-taking region (``""``: it can): it ends
    otherwise than SUCCESS/FAILURE, or in a tick that ran no leaf (its first tick included)."""
    if region.ends - {SUCCESS, FAILURE}:
        return f"can end in {', '.join(sorted(region.ends - {SUCCESS, FAILURE}))}"
    if region.fsm.initial in region.ends:
        return "returns its result in its first tick without ticking a leaf"
    for t in region.fsm.transitions:
        if t.attrs.get(TICK_MARK) and t.target in region.ends:
            return "can return its result in a tick that ticks none of its leaves"
    return ""


def _compact_region(
    compact: CompactRegion,
    index: int,
    count: int,
    name: str,
    turn: str,
    successes: str,
    failures: str,
    stop: str,
) -> FSM:
    """Region ``index`` from a child's tick-marked compact region: its leaf states and
    guarded transitions as they are; a step that ended the child's tick goes to the wait
    state of its target and passes the turn on; the child's end goes to DONE."""
    source = compact.fsm
    fsm = FSM(name=name)
    pass_on = f"{turn}={(index + 1) % count}"
    for state in source.states.values():
        if not state.final:
            fsm.add_state(State(state.name, action=state.action))
    waits: dict[str, str] = {}

    def wait_for(leaf: str) -> str:
        if leaf not in waits:
            waits[leaf] = _unique(fsm, f"wait_{leaf}")
            fsm.add_state(State(waits[leaf], action=""))
        return waits[leaf]

    assert source.initial is not None
    fsm.initial = wait_for(source.initial)
    done = _unique(fsm, DONE)
    fsm.add_state(State(done, action=""))
    end = _unique(fsm, END)
    fsm.add_state(State(end, action="", final=True))
    counter = {SUCCESS: successes, FAILURE: failures}
    for t in source.transitions:
        attrs = {k: v for k, v in t.attrs.items() if k != TICK_MARK}
        assigns = [attrs[ASSIGN]] if ASSIGN in attrs else []
        if t.target in counter:
            name_ = counter[t.target]
            attrs[ASSIGN] = "\n".join([*assigns, f"{name_}={name_} + 1", pass_on])
            fsm.add_transition(t.source, t.event, done, attrs=attrs)
        elif t.attrs.get(TICK_MARK):
            attrs[ASSIGN] = "\n".join([*assigns, pass_on])
            fsm.add_transition(t.source, t.event, wait_for(t.target), attrs=attrs)
        else:
            fsm.add_transition(t.source, t.event, t.target, attrs=attrs)
    for leaf, wait in waits.items():
        fsm.add_transition(wait, None, end, attrs={COND: stop})
        fsm.add_transition(wait, None, leaf, attrs={COND: f"{turn} == {index}"})
    fsm.add_transition(done, None, end, attrs={COND: stop})
    fsm.add_transition(done, None, done, attrs={COND: f"{turn} == {index}", ASSIGN: pass_on})
    return fsm


def _first_leaf(node: BTNode) -> BTNode:
    while not node.is_leaf:
        node = node.children[0]
    return node


def _unique(fsm: FSM, base: str) -> str:
    if base not in fsm.states:
        return base
    n = 2
    while f"{base}#{n}" in fsm.states:
        n += 1
    return f"{base}#{n}"
