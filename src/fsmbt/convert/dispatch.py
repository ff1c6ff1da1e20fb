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

Bad input (UnsupportedError, state named): an event name BehaviorTree.CPP's ``Switch`` would
not compare as a plain string (a number, a blackboard reference ``{..}``, empty).

Cost: O(states + transitions) to build (the cyclic collector paused, ``convert/perf.py``: the
tree is acyclic); depth O(log7 states + max out-degree / 6).
"""

from __future__ import annotations

import re
from collections import deque

from fsmbt.convert.perf import without_gc_pauses
from fsmbt.convert.result import ConversionResult
from fsmbt.model.bt import BTDocument, BTNode, NodeModel, PortModel
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten, needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.dispatch_runtime import (
    BASE,
    DIGIT_PREFIX,
    DIGITS,
    ENTRY,
    EVENT_KEY,
    MAX_CASES,
    ON_SUCCESS,
)

STYLE = "dispatch"
_NUMBER = re.compile(r"\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*")


def _control(type_name: str, name: str, children: list[BTNode], **attrs: str) -> BTNode:
    return BTNode(type=type_name, kind=NodeKind.CONTROL, name=name, children=children, attrs=attrs)


def _leaf(type_name: str, name: str = "", **attrs: str) -> BTNode:
    kind = NodeKind.ACTION
    return BTNode(type=type_name, kind=kind, name=name, attrs=attrs)


def _running() -> BTNode:
    return BTNode(
        type="KeepRunningUntilFailure",
        kind=NodeKind.DECORATOR,
        children=[_leaf("AlwaysSuccess")],
    )


def _switch(key: str, cases: list[tuple[str, BTNode]], default: BTNode, name: str) -> BTNode:
    """``Switch{k}`` over ``cases`` (1..6 of them). One case gets a padding case: an unused
    digit (``AlwaysFailure``, never written), or for ``{event}`` (only the last chunk of a
    state's events has one case, its default is RUNNING) another name that also runs RUNNING."""
    if len(cases) == 1:
        pad = next(v for v in (*DIGITS, "z", "zz") if v != cases[0][0])
        cases = [*cases, (pad, _running() if key == EVENT_KEY else _leaf("AlwaysFailure"))]
    attrs = {"variable": "{" + key + "}"}
    attrs.update({f"case_{i}": value for i, (value, _n) in enumerate(cases, 1)})
    return _control(f"Switch{len(cases)}", name, [n for _v, n in cases] + [default], **attrs)


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


def _check_event(event: str, state: str) -> None:
    if not event or "{" in event or "'" in event or _NUMBER.fullmatch(event):
        raise UnsupportedError(
            f"event {event!r} cannot be a Switch case (BehaviorTree.CPP compares numbers "
            "numerically and reads {..} as a blackboard entry); use --style lebt",
            element=f"state '{state}'",
        )


@without_gc_pauses
def fsm_to_dispatch(fsm: FSM, **_options: object) -> ConversionResult:
    """The dispatch form of ``fsm`` (see the module docstring)."""
    warnings: list[str] = []
    flat = fsm
    if needs_flattening(fsm):
        flat = flatten(fsm)
        warnings.append(f"hierarchical FSM flattened to {len(flat.states)} states")
    if flat.initial is None or flat.initial not in flat.states:
        raise InputError("the state machine has no initial state", element=fsm.name)
    states = _reachable(flat)
    index = {name: i for i, name in enumerate(states)}
    levels = 1
    while BASE**levels < len(states):
        levels += 1

    def digits(i: int) -> list[str]:
        out = []
        for _j in range(levels):
            out.append(DIGITS[i % BASE])
            i //= BASE
        return out

    def transition(source: str | None, target: str, label: str) -> BTNode:
        """The transition to ``target``; its Script writes only the digits that differ from
        ``source``'s (all of them from the start, ``source`` None)."""
        want = digits(index[target])
        have = digits(index[source]) if source is not None else [""] * levels
        code = [f"{DIGIT_PREFIX}{j}:='{want[j]}'" for j in range(levels) if want[j] != have[j]]
        st = flat.states[target]
        attrs = {"state": target, "action": st.action or ""}
        if code:
            attrs[ON_SUCCESS] = "; ".join(code)
        node = _leaf(ENTRY, target, **attrs)
        if st.final:
            return node
        return BTNode(
            type="KeepRunningUntilFailure", kind=NodeKind.DECORATOR, name=label, children=[node]
        )

    def events_switch(source: str | None, name: str, exits: list[tuple[str, str]]) -> BTNode:
        if not exits:
            return _running()
        node = _running()
        chunks = [exits[k : k + 6] for k in range(0, len(exits), 6)]
        for c, chunk in reversed(list(enumerate(chunks))):
            cases = [(ev, transition(source, t, f"{name}/{ev}")) for ev, t in chunk]
            node = _switch(EVENT_KEY, cases, node, f"{name}_events{c or ''}")
        return node

    table = flat.transition_map()
    transitions = sum(len(table.get(name, {})) for name in states if not flat.states[name].final)
    cases: list[BTNode] = []
    for name in states:
        st = flat.states[name]
        if st.final:
            cases.append(_leaf("AlwaysSuccess", f"{name}_final"))
            continue
        exits = [(str(e), t.target) for e, t in table.get(name, {}).items()]
        for ev, _t in exits:
            _check_event(ev, name)
        cases.append(events_switch(name, name, exits))
    if flat.initial_event is not None:
        _check_event(flat.initial_event, flat.start_name or "start")
        start = events_switch(None, "start", [(flat.initial_event, flat.initial)])
    else:
        start = transition(None, flat.initial, "start")
    nodes: list[BTNode] = cases
    for j in range(levels):
        key = f"{DIGIT_PREFIX}{j}"
        groups = [nodes[k : k + BASE] for k in range(0, len(nodes), BASE)]
        last = j == levels - 1
        nodes = []
        for g, group in enumerate(groups):
            name = "dispatch" if last else f"digit{j}_{g}"
            cases_j = [(DIGITS[i], n) for i, n in enumerate(group)]
            if len(cases_j) <= MAX_CASES:
                default = start if last else _leaf("AlwaysFailure")
            elif last:  # the root's default is the start case: the seventh digit is a case
                default = _switch(key, cases_j[MAX_CASES:], start, f"{name}_{DIGITS[-1]}")
            else:  # the seventh digit is the default child: one comparison fewer
                default = cases_j[MAX_CASES][1]
            nodes.append(_switch(key, cases_j[:MAX_CASES], default, name))
    assert len(nodes) == 1
    doc = BTDocument.single(nodes[0])
    doc.node_models[ENTRY] = NodeModel(
        ENTRY, NodeKind.ACTION, [PortModel("state", "input"), PortModel("action", "input")]
    )
    count = depth = 0
    stack = [(nodes[0], 1)]
    while stack:
        node, d = stack.pop()
        count += 1
        depth = max(depth, d)
        stack.extend((child, d + 1) for child in node.children)
    stats: dict[str, object] = {
        "states": len(states),
        "transitions": transitions,
        "nodes": count,
        "depth": depth,
        "style": STYLE,
        "index_digits": levels,
    }
    return ConversionResult(doc, "rules", "fsm->bt", stats, warnings)
