"""Every behavioural difference of two models, grouped by the step where the runs part
(docs/diff.md, 'Behavioural differences').

The two models are paired into two machines by the verifier's pairing rules
(``fsmbt.verify.orient``, ``fsmbt.verify.pairing``: two BTs by leaf execution, two FSMs by macro
steps, a BT against the FSM it implements by either rule), and the native checker's product
lists every *frontier point* (``fsmbt.verify.native.frontier``): a pair of states reached on
one input sequence on which both agreed at every step, and an input on which they then differ
(outputs, status, or one refuses it), or a pair where one side is stuck.

Points are grouped by *where* they part and *how*: the OLD state (for a BT, the leaf about to
be ticked, ``label@path``), the NEW state, the input, what OLD does and what NEW does. Many
product pairs can share a group (the same leaf reached with different memories); the group
keeps the count and its first point in breadth-first order, whose witness is a shortest input
sequence showing that difference. Groups are listed in that order, at most ``max_groups``.

Pairs that cannot be compared are refused with one sentence: a loop-execution or
state-variable BT (inputs are events) against a plain BT (inputs are leaf outcomes).

Costs: the checker's (``O(|P| k)`` steps for ``|P|`` product pairs and ``k`` inputs), plus one
step of each machine per group.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import Machine
from fsmbt.verify.native import DEFAULT_MAX_STATES, FrontierPoint, frontier, replay
from fsmbt.verify.orient import fsm_side_rule, orient
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import DEADLOCK_ABSENCE, TraceStep

Model = FSM | BTDocument

#: Groups listed by default.
DEFAULT_MAX_GROUPS = 20


@dataclass
class Divergence:
    """One group of distinguishing runs: where OLD and NEW part, and how.

    Attributes:
        old_state, new_state: where each model is when they part (``label@path`` for a BT:
            the leaf about to be ticked; the state or configuration for an FSM).
        input: the input on which they part (``None``: at the start, or one side is stuck).
        old_does, new_does: what each does then, in words.
        witness: a shortest input sequence from the start that shows it.
        points: how many frontier points (product pairs and inputs) fall in this group.
        old_next, new_next: where each is after that step (``None`` at the start, when stuck
            or when the input is refused): for a BT the leaf each ticks next.
        trace: the witness replayed on both (OLD first), each step with both outputs.
    """

    old_state: str
    new_state: str
    input: str | None
    old_does: str
    new_does: str
    witness: tuple[str, ...]
    points: int = 1
    old_next: str | None = None
    new_next: str | None = None
    trace: list[TraceStep] = field(default_factory=list)


@dataclass
class BehaviourDiff:
    """The behavioural comparison of OLD and NEW.

    Attributes:
        rule: the pairing rule used (``fsmbt.verify.orient.PAIRING_RULES``).
        groups: the divergences shown (at most ``max_groups``), first-parting order.
        total_groups: how many groups there are in all.
        total_points: how many frontier points in all.
        stats: the product's sizes and seconds.
    """

    rule: str
    groups: list[Divergence]
    total_groups: int
    total_points: int
    stats: dict[str, Any]

    @property
    def same(self) -> bool:
        """True when no run tells the two apart."""
        return self.total_points == 0


def _describe_outputs(outputs: tuple[str, ...] | list[str], status: str) -> str:
    shown = ", ".join(outputs) if outputs else "nothing"
    return f"outputs {shown}" + (f" and is {status}" if status != "running" else "")


def _does(machine: Machine[Any], state: Any, symbol: str | None, point: FrontierPoint) -> str:
    """What ``machine`` does in ``state`` on ``symbol`` (in words)."""
    if symbol is None:
        if point.property == DEADLOCK_ABSENCE:
            status = machine.status(state)
            if status != "running":
                return f"has ended ({status})"
            if _stuck_side(machine, state) == "stuck":
                return "is stuck (no input ever makes it act)"
            return "can still act"
        start, outputs = machine.start()
        return "starts: " + _describe_outputs(tuple(outputs), machine.status(start))
    follows = bool(getattr(machine, "follows_environment", False))
    if not follows and symbol not in machine.inputs(state):
        return f"does not accept {symbol!r}"
    nxt, outputs = machine.step(state, symbol)
    return _describe_outputs(tuple(outputs), machine.status(nxt))


def _next(machine: Machine[Any], state: Any, symbol: str | None) -> str | None:
    if symbol is None:
        return None
    follows = bool(getattr(machine, "follows_environment", False))
    if not follows and symbol not in machine.inputs(state):
        return None
    return machine.describe(machine.step(state, symbol)[0])


def _stuck_side(machine: Machine[Any], state: Any) -> str:
    """``"stuck"`` when no input sequence from ``state`` makes ``machine`` act (bounded BFS
    over its own steps; the checker has already decided it for one side of the pair)."""
    seen = {state}
    frontier_states = [state]
    status = machine.status(state)
    while frontier_states:
        nxt_states = []
        for s in frontier_states:
            for symbol in machine.inputs(s):
                nxt, out = machine.step(s, symbol)
                if out or machine.status(nxt) != status:
                    return "acts"
                if nxt not in seen:
                    seen.add(nxt)
                    nxt_states.append(nxt)
        frontier_states = nxt_states
    return "stuck"


def check_pairable(old: Model, new: Model) -> None:
    """Refuse a pair the checker cannot compare meaningfully, in one sentence.

    Raises:
        InputError: a macro-step BT (loop-execution or state-variable leaves: its inputs are
            events) against a plain BT (its inputs are leaf outcomes).
    """
    if isinstance(old, BTDocument) and isinstance(new, BTDocument):
        rules = (fsm_side_rule(old), fsm_side_rule(new))
        if (rules[0] is None) != (rules[1] is None):
            macro = "OLD" if rules[0] is not None else "NEW"
            plain = "NEW" if macro == "OLD" else "OLD"
            raise InputError(
                f"cannot pair these two trees: {macro} is a converted state machine's tree "
                f"(its leaves read events; {rules[0] or rules[1]}) and {plain} a plain behavior "
                "tree (its leaves return outcomes); diff each against the FSM it implements, "
                "or two trees of one kind"
            )


def behaviour_diff(
    old: Model,
    new: Model,
    *,
    max_groups: int = DEFAULT_MAX_GROUPS,
    loop: bool = False,
    max_states: int = DEFAULT_MAX_STATES,
) -> BehaviourDiff:
    """Every way ``new`` behaves differently from ``old`` (see the module docstring).

    Raises:
        InputError: a pair that cannot be compared; a machine or product over ``max_states``
            (``StateLimitError``).
    """
    check_pairable(old, new)
    oriented = orient(old, new)
    source, result, _mode = machines_for(oriented.source, oriented.result, loop=loop)
    found = frontier(source, result, max_states=max_states)
    old_m, new_m = (result, source) if oriented.swapped else (source, result)
    groups: dict[tuple[str, str, str | None, str, str], Divergence] = {}
    for point in found.points:
        s_state, r_state = point.source_state, point.result_state
        old_state, new_state = (r_state, s_state) if oriented.swapped else (s_state, r_state)
        key_old = old_m.describe(old_state)
        key_new = new_m.describe(new_state)
        old_does = _does(old_m, old_state, point.symbol, point)
        new_does = _does(new_m, new_state, point.symbol, point)
        key = (key_old, key_new, point.symbol, old_does, new_does)
        group = groups.get(key)
        if group is not None:
            group.points += 1
            continue
        groups[key] = Divergence(
            key_old,
            key_new,
            point.symbol,
            old_does,
            new_does,
            point.witness,
            old_next=_next(old_m, old_state, point.symbol),
            new_next=_next(new_m, new_state, point.symbol),
        )
    shown = list(groups.values())[: max(max_groups, 0)]
    for group in shown:
        group.trace = _trace(old_m, new_m, group.witness)
    return BehaviourDiff(
        rule=oriented.rule,
        groups=shown,
        total_groups=len(groups),
        total_points=len(found.points),
        stats=found.stats,
    )


def _trace(old_m: Machine[Any], new_m: Machine[Any], witness: tuple[str, ...]) -> list[TraceStep]:
    """The witness replayed with OLD as the trace's source side (a follows-environment FSM
    side is put second, as the replay needs)."""
    if getattr(old_m, "follows_environment", False):
        steps = replay(new_m, old_m, list(witness)).steps
        return [
            TraceStep(
                st.step,
                st.input,
                st.result_outputs,
                st.source_outputs,
                st.result_state,
                st.source_state,
                st.result_status,
                st.source_status,
                st.note,
            )
            for st in steps
        ]
    return replay(old_m, new_m, list(witness)).steps
