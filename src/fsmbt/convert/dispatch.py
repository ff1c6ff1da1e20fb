"""FSM -> BT, dispatch style: a balanced ``Switch`` dispatch over a state index on the
blackboard (docs/semantics.md, "12. The dispatch form"; runs as
``fsmbt.semantics.dispatch_runtime`` says).

Shape, for reachable states numbered 0..n-1 in declaration order (index digits base 7, letters
``a``..``g``, in the entries ``fsm_d0`` (least significant) .. ``fsm_d{L-1}``):

- the root is a tree of ``Switch2``..``Switch6`` nodes: level ``j`` (counted from the leaves)
  switches on ``{fsm_dj}``; below the root a full group of seven takes ``a``..``f`` as cases
  and ``g`` as the default child (no comparison for it); a smaller group's default is
  ``AlwaysFailure`` (unreachable), and a group of one gets a padding case (``AlwaysFailure``).
  The root's default is the start case (the digits are unset before the first transition), so
  a full root group puts its seventh member under a ``Switch2`` on the same digit whose default
  is the start case;
- a final state's case is ``AlwaysSuccess``; a non-final state's case switches on ``{event}``
  over its outgoing events (chains of ``Switch6`` when it has more than 6), each case the
  transition ``KeepRunningUntilFailure(DispatchEntry(target, _onSuccess="the target's digits
  that differ from the source's"))`` (BehaviorTree.CPP's post-condition writes them after the
  leaf's SUCCESS; no ``_onSuccess`` when no digit differs: a self-loop;
  ``KeepRunningUntilFailure`` left out when the target is final), the default
  ``KeepRunningUntilFailure(AlwaysSuccess)`` (RUNNING: the event is ignored);
- the start case is the transition to the initial state (every digit written), or, when the FSM
  has an initial event, an event switch with that one case.

Why this shape (issue 23 item 6, measured in benchmarks/bench_dispatch_floor.py and
bench_runtime.py): in BehaviorTree.CPP 4.8.2 every ticked node costs about 100 ns (two clock
reads and mutexes in ``executeTick``) and a ``Switch`` more per case read, so the tree ticks
as few nodes as it can: base 7 (one index level fewer than base 6 from 2 402 to 7 776 states,
and so at 10 000), the transition as one or two nodes instead of four to five (the digits
written by the leaf's post-condition, not by a ``Script`` node under a ``Sequence``), writing
one digit on most chain steps instead of all of them.

A hierarchical machine gets the hierarchical form (``fsmbt.convert.dispatch_hier``,
docs/semantics.md §12a: one dispatch level per composite state) unless it has a construct that
form cannot keep (``hierarchy_blocker``) or ``hierarchy="flatten"`` is asked for: then it is
flattened first and this shape written for the flat machine, with a warning naming the state
and the cause.

Bad input (UnsupportedError, state named): an event name BehaviorTree.CPP's ``Switch`` would
not compare as a plain string (a number, a blackboard reference ``{..}``, empty).

Cost: O(states + transitions) to build (the cyclic collector paused, ``convert/perf.py``: the
tree is acyclic); depth O(log7 states + max out-degree / 6).
"""

from __future__ import annotations

from collections import deque

from fsmbt.convert.dispatch_hier import fsm_to_hier_dispatch, hierarchy_blocker
from fsmbt.convert.dispatch_parts import (
    check_event,
    digits_of,
    entry_model,
    event_switch,
    index_levels,
    index_tree,
    leaf,
    running,
    size,
)
from fsmbt.convert.perf import without_gc_pauses
from fsmbt.convert.result import ConversionResult
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import InputError
from fsmbt.model.flatten import flatten, needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.dispatch_runtime import DIGIT_PREFIX, ENTRY, ON_SUCCESS

STYLE = "dispatch"


def _reachable(flat: FSM) -> list[str]:
    assert flat.initial is not None
    table = flat.transition_map()
    seen, queue = {flat.initial}, deque([flat.initial])
    while queue:
        name = queue.popleft()
        if flat.states[name].final:
            continue
        for event, t in table.get(name, {}).items():
            if event is None:
                raise InputError("eventless transition in a flat FSM", element=name)
            if t.target not in flat.states:
                raise InputError(f"transition to unknown state '{t.target}'", element=name)
            if t.target not in seen:
                seen.add(t.target)
                queue.append(t.target)
    return [name for name in flat.states if name in seen]


@without_gc_pauses
def fsm_to_dispatch(
    fsm: FSM, *, hierarchy: str = "subtrees", **_options: object
) -> ConversionResult:
    """The dispatch form of ``fsm`` (see the module docstring): the hierarchical form
    (``fsmbt.convert.dispatch_hier``, docs/semantics.md §12a) for a hierarchical machine
    whose hierarchy it keeps, else the flat form of the machine, flattened first when it is
    hierarchical (a warning names the state and the cause, or ``--hierarchy flatten``)."""
    warnings: list[str] = []
    flat = fsm
    if needs_flattening(fsm):
        reason = hierarchy_blocker(fsm) if hierarchy != "flatten" else "--hierarchy flatten"
        if reason is None:
            return fsm_to_hier_dispatch(fsm)
        flat = flatten(fsm)
        warnings.append(f"hierarchical FSM flattened to {len(flat.states)} states: {reason}")
    if flat.initial is None or flat.initial not in flat.states:
        raise InputError("the state machine has no initial state", element=fsm.name)
    states = _reachable(flat)
    index = {name: i for i, name in enumerate(states)}
    levels = index_levels(len(states))

    def transition(source: str | None, target: str, label: str) -> BTNode:
        """The transition to ``target``; its post-condition writes only the digits that
        differ from ``source``'s (all of them from the start, ``source`` None)."""
        want = digits_of(index[target], levels)
        have = digits_of(index[source], levels) if source is not None else [""] * levels
        code = [f"{DIGIT_PREFIX}{j}:='{want[j]}'" for j in range(levels) if want[j] != have[j]]
        st = flat.states[target]
        attrs = {"state": target, "action": st.action or ""}
        if code:
            attrs[ON_SUCCESS] = "; ".join(code)
        node = leaf(ENTRY, target, **attrs)
        if st.final:
            return node
        return BTNode(
            type="KeepRunningUntilFailure", kind=NodeKind.DECORATOR, name=label, children=[node]
        )

    def events_switch(source: str | None, name: str, exits: list[tuple[str, str]]) -> BTNode:
        cases = [(ev, transition(source, t, f"{name}/{ev}")) for ev, t in exits]
        return event_switch(name, cases, running)

    table = flat.transition_map()
    transitions = sum(len(table.get(name, {})) for name in states if not flat.states[name].final)
    cases: list[BTNode] = []
    for name in states:
        st = flat.states[name]
        if st.final:
            cases.append(leaf("AlwaysSuccess", f"{name}_final"))
            continue
        exits = [(str(e), t.target) for e, t in table.get(name, {}).items()]
        for ev, _t in exits:
            check_event(ev, name)
        cases.append(events_switch(name, name, exits))
    if flat.initial_event is not None:
        check_event(flat.initial_event, flat.start_name or "start")
        start = events_switch(None, "start", [(flat.initial_event, flat.initial)])
    else:
        start = transition(None, flat.initial, "start")
    root = index_tree(cases, DIGIT_PREFIX, levels, start, ("dispatch", "digit"))
    doc = BTDocument.single(root)
    doc.node_models[ENTRY] = entry_model()
    count, depth = size(root)
    stats: dict[str, object] = {
        "states": len(states),
        "transitions": transitions,
        "nodes": count,
        "depth": depth,
        "style": STYLE,
        "index_digits": levels,
    }
    if flat is not fsm:
        stats["flattened"] = True
    return ConversionResult(doc, "rules", "fsm->bt", stats, warnings)
