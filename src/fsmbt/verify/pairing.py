"""Which two machines represent a (source, result) pair of models (docs/verification.md).

- FSM source, BT result (macro steps): the FSM's macro-step machine against the LEBT run under
  the LEBT protocol (docs/semantics.md); inputs are events (the FSM's, then any the LEBT's guards name).
- dispatch BT source, FSM result (macro steps, docs/semantics.md section 12): the tree's
  macro-step machine against the FSM's, over the union of their events.
- BT source, FSM result (leaf execution): the BT's leaf-execution machine against the FSM read as
  one (``FSMLeafMachine``): a state is the leaf about to be ticked, inputs are leaf outcomes.
- FSM source, structured BT result (outcome execution): both leaf-execution machines over the
  source states' outcomes (``fsmbt.verify.outcome_pairing``, docs/semantics.md §11).
- FSM vs FSM: both macro-step machines over the union of their events.
- BT vs BT: both leaf-execution machines.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_runtime import is_dispatch_bt, machines_for_dispatch
from fsmbt.semantics.execution import Flavour, flavour_of, leaf_machine
from fsmbt.semantics.lebt.machine import LEBTMachine
from fsmbt.semantics.lebt.spec import GUARD_TYPE, GuardSpec
from fsmbt.semantics.machine import FSMMachine, Machine
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.verify.outcome_pairing import is_outcome_pair, outcome_machines

MACRO_STEP = "macro-step"
LEAF_EXECUTION = "leaf-execution"


class LEBTWithActiveInputs:
    """``LEBTMachine`` plus a sound ``active_inputs``, so ignored events are not stepped.

    Why it is sound: under the LEBT protocol (docs/semantics.md) an event's identity is read only by two tests,
    made while it is pending: a guard's ``(state, event) in pairs`` and a running state leaf's
    ``event in exits``. ``state`` cannot change while an event is pending (the only writer, a
    state leaf's start, clears the event), and a leaf tested with ``event in exits`` was running
    before the macro step began. So in LEBT state ``x`` every event outside
    ``relevant(x)`` = {e : (x.state, e) in some guard} | exits of the leaves running in ``x``
    gets the same answers everywhere and leads to the same next state and outputs. One such
    event is stepped: if it is a silent self-loop, only ``relevant(x)`` is active; otherwise
    (a broken tree) every event is. Cost per state: O(|relevant(x)| + running leaves).
    """

    def __init__(self, machine: Machine[Any]) -> None:
        self.machine = machine
        self.name = machine.name
        self.alphabet: tuple[str, ...] = tuple(machine.alphabet)  # type: ignore[attr-defined]
        self._alphabet_set = frozenset(self.alphabet)
        leaves = machine.runtime.leaves  # type: ignore[attr-defined]
        self._by_source: dict[str, list[str]] = {}
        for guard in leaves.guards.values():
            for source, event in guard.pairs:
                if event:
                    self._by_source.setdefault(source, []).append(event)
        self._exits = {nid: spec.exits for nid, spec in leaves.states.items()}
        self._running_leaves = machine.running_leaves  # type: ignore[attr-defined]

    def start(self):  # type: ignore[no-untyped-def]
        return self.machine.start()

    def inputs(self, state) -> Sequence[str]:  # type: ignore[no-untyped-def]
        return self.machine.inputs(state)

    def step(self, state, symbol: str):  # type: ignore[no-untyped-def]
        return self.machine.step(state, symbol)

    def status(self, state) -> str:  # type: ignore[no-untyped-def]
        return self.machine.status(state)

    def describe(self, state) -> str:  # type: ignore[no-untyped-def]
        return self.machine.describe(state)

    def active_inputs(self, state) -> Sequence[str]:  # type: ignore[no-untyped-def]
        relevant: dict[str, None] = dict.fromkeys(self._by_source.get(state.bb_state, ()))
        for nid in self._running_leaves(state):
            relevant.update(dict.fromkeys(self._exits[nid]))
        active = [e for e in relevant if e in self._alphabet_set]
        other = next((e for e in self.alphabet if e not in relevant), None)
        if other is None:
            return active
        nxt, outputs = self.machine.step(state, other)
        if nxt == state and not outputs:
            return active
        return self.alphabet


def lebt_guard_events(doc: BTDocument) -> list[str]:
    """Events named by the LEBT guard leaves (so the checker also offers events that only the
    result knows: reacting to one is additional behaviour)."""
    seen: dict[str, None] = {}
    for _tree, node in doc.nodes():
        if node.type == GUARD_TYPE:
            try:
                spec = GuardSpec.from_attrs(node.attrs)
            except ValueError as exc:
                raise InputError(str(exc), location=node.location, element=node.label) from None
            for _source, event in spec.pairs:
                if event:
                    seen.setdefault(event, None)
    return list(seen)


def machines_for(
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    *,
    loop: bool = False,
    faithful: bool = False,
    outcomes: OutcomeRules | None = None,
    outcome_driven: bool = False,
) -> tuple[Machine[Any], Machine[Any], str]:
    """The (source machine, result machine, mode) for a pair of models.

    An outcome-driven FSM and a tree without LEBT or state-variable leaves (a structured
    conversion) are compared by the outcome pairing (``fsmbt.verify.outcome_pairing``) under
    ``outcomes`` (the outcome rules; ``None``: the defaults); ``outcome_driven`` says the FSM's
    events are outcomes although no state declares them (a SMACH/FlexBE/YASMIN file).

    ``faithful``: BT sides in leaf-execution mode use the faithful interpreter
    (``LeafMachine(generic=True)``) instead of the static table or canonical states, whose
    merged states can change the state-based reachability property of a failing pair
    (docs/verification.md); every other property and the verdict are the same.
    """
    if isinstance(source, FSM) and isinstance(result, FSM):
        alphabet = _union(source.events(), result.events(), *sub_machine_events(source, result))
        return (
            FSMMachine(source, alphabet=alphabet),
            FSMMachine(result, alphabet=alphabet),
            MACRO_STEP,
        )
    if isinstance(source, FSM) and isinstance(result, BTDocument):
        from fsmbt.semantics.state_variable_runtime import machines_for_state_variable

        if flavour_of(result) is Flavour.STATE_VARIABLE:  # the baselines' leaves (BSD, CHDS)
            return (*machines_for_state_variable(source, result), MACRO_STEP)
        if is_dispatch_bt(result):  # the dispatch form (docs/semantics.md section 12)
            return (*machines_for_dispatch(source, result), MACRO_STEP)
        if is_outcome_pair(source, result, outcome_driven=outcome_driven):
            return outcome_machines(source, result, outcomes, faithful=faithful)

        source_machine = FSMMachine(source)
        alphabet = _union(source_machine.alphabet, lebt_guard_events(result))
        source_machine = FSMMachine(source, alphabet=alphabet)
        return source_machine, LEBTWithActiveInputs(LEBTMachine(result, alphabet)), MACRO_STEP
    if isinstance(source, BTDocument) and isinstance(result, FSM) and is_dispatch_bt(source):
        # BT -> FSM of a dispatch tree (fsmbt.convert.dispatch_fsm): macro steps, both ways
        fsm_machine, dispatch_machine = machines_for_dispatch(result, source)
        return dispatch_machine, fsm_machine, MACRO_STEP
    if isinstance(source, BTDocument):  # leaf execution against an FSM or another BT
        return (
            leaf_machine(source, loop=loop, generic=faithful),
            leaf_machine(result, loop=loop, generic=faithful),
            LEAF_EXECUTION,
        )
    raise InputError(f"cannot compare a {type(source).__name__} with a {type(result).__name__}")


def sub_machine_events(*fsms: FSM) -> list[list[str]]:
    """The events of every nested sub-machine of ``fsms`` (a hierarchical FSM's top level does
    not list them), so both verifiers (native here, ``fsmbt.verify.nusmv``) step one alphabet.

    Args:
        fsms: the machines, flat or hierarchical.

    Returns:
        One event list per sub-machine (region), in walk order; flat machines add none.
    """
    out: list[list[str]] = []
    for fsm in fsms:
        for _path, _machine, state in fsm.walk():
            out.extend(region.events() for region in state.regions)  # each sub-machine once
    return out


def _union(*groups: Sequence[str]) -> list[str]:
    seen: dict[str, None] = {}
    for group in groups:
        for item in group:
            seen.setdefault(item, None)
    return list(seen)
