"""An FSM read as an outcome-driven machine (docs/semantics.md, "11. Outcome-driven machines").

SMACH, FlexBE and YASMIN machines are read (``fsmbt.formats``) into FSMs whose events are the
states' outcomes: a state ``S`` that returned ``o`` takes ``S --o--> T``; a container is a
composite state whose completion transitions ``exit=o`` say where each container outcome goes,
with one final state per container outcome. This module checks that a machine has exactly that
shape and gives every state a ``Unit``: its outcomes in declaration order (those a transition
names; ``preempted`` ones that halt the machine removed, ``outcome_rules`` rule 4), their
targets and statuses, and whether a leaf needs a dispatch on its outcome.

Rules (each violation is an ``OutcomeError`` naming the state and the cause, exit 2):
- no parallel state (a reader builds a Concurrence as a composite whose region is the product
  of its children; one whose semantics a BehaviorTree.CPP parallel node has is read in rounds
  instead, its units being its children: ``outcome_parallel``; a container child is one unit
  whose own regions join the view, read as a container's, when the ``ChildSchedule`` says its
  tree can run under a Parallel: docs/semantics.md §11, "Container children");
- the machine needs no start event; an atomic state has no completion transition and at
  least one outcome; a composite state leaves only by completion transitions;
- when a state declares its outcomes (``fsmbt.model.state_info``), every event of its
  transitions is one of them (else the machine mixes external events and outcomes);
- every final state a container reaches has a completion transition in the parent.

A unit is *binary* when, grouping its outcomes by status, each group has one target (or all
outcomes share one target); else it is a *dispatch* unit: its leaf (or SubTree) writes the
outcome to the blackboard entry ``key`` and a ``Switch`` reads it.

Everything is computed with explicit work lists, O(states + transitions).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

from fsmbt.model import state_info
from fsmbt.model.fsm import FSM, State
from fsmbt.semantics.outcome_parallel import (
    Concurrence,
    ParallelForm,
    choose_form,
    read_concurrence,
)
from fsmbt.semantics.outcome_rules import (
    FAILURE,
    HALT_OUTCOME,
    SUCCESS,
    OutcomeError,
    OutcomeRules,
)

#: The leaf outcome a running state gives (not an outcome of the source machine).
RUNNING_INPUT = "running"


@dataclass
class Unit:
    """One non-final state of a region: a leaf (atomic state) or a container (composite)."""

    path: str
    name: str
    state: State
    container: bool
    outcomes: tuple[str, ...]
    targets: dict[str, str]
    status: dict[str, str | None]
    halted: tuple[str, ...]
    order_choice: bool
    label: str = ""
    key: str = ""
    #: Its status is its container's result (a SMACH ``outcome_cb``'s leaf, last in its
    #: container's tree): never dispatched on.
    gives_result: bool = False

    @property
    def dispatch(self) -> bool:
        """Whether the outcome must be written to the blackboard and dispatched on."""
        if self.gives_result or len(set(self.targets.values())) <= 1:
            return False
        if any(self.status[o] is None for o in self.outcomes):
            return True
        for status in (SUCCESS, FAILURE):
            group = {self.targets[o] for o in self.outcomes if self.status[o] == status}
            if len(group) > 1:
                return True
        return False

    def target_of(self, status: str) -> str | None:
        """The one target of the outcomes with ``status`` (binary units), else ``None``."""
        for o in self.outcomes:
            if self.status[o] == status:
                return self.targets[o]
        return None


@dataclass
class Region:
    """One machine (the top level or a container's region) with its units and exits."""

    path: str
    machine: FSM
    owner: Unit | None
    units: dict[str, Unit] = field(default_factory=dict)
    exits: list[str] = field(default_factory=list)
    exit_status: dict[str, str | None] = field(default_factory=dict)
    pc_key: str = ""
    #: A Concurrence of leaf children (``outcome_parallel``); with a ``form`` the region's
    #: units are its children, read in rounds, else its product machine's states.
    concurrence: Concurrence | None = None
    #: In a Concurrence read in rounds: the (unit path, outcome) transitions of its container
    #: children that go round a loop - their SubTree returns RUNNING there, so the turn passes
    #: to the next child (``ChildSchedule``).
    round_trips: frozenset[tuple[str, str]] = frozenset()

    @property
    def parallel(self) -> bool:
        """Whether the region is a Concurrence read in rounds (a Parallel in the tree)."""
        return self.concurrence is not None and self.concurrence.form is not None

    @property
    def initial(self) -> str:
        assert self.machine.initial is not None
        return self.machine.initial


@dataclass
class OutcomeView:
    """Every region and unit of an outcome-driven machine, and the rules it was read under."""

    fsm: FSM
    rules: OutcomeRules
    regions: dict[str, Region]
    by_label: dict[str, Unit]
    order_choices: list[str]
    halts: int

    @property
    def top(self) -> Region:
        return self.regions[""]

    def root_result(self, exit_name: str) -> str:
        """The root's result (``SUCCESS``/``FAILURE``) when the machine ends in ``exit_name``;
        a top-level outcome with no status ends it with SUCCESS (named in the verdict)."""
        status = self.top.exit_status.get(exit_name)
        return "FAILURE" if status == FAILURE else "SUCCESS"

    def leaf_units(self) -> list[Unit]:
        return [u for region in self.regions.values() for u in region.units.values()
                if not u.container]  # fmt: skip


#: How a container child's tree runs under a Parallel, given its top region (owner set) and
#: every region of its hierarchy: why it cannot (or None), and the transitions where its tree
#: returns RUNNING without a leaf doing so (a loop going round). The structured conversion
#: gives it (``convert.structured.schedule``): the reading follows the tree the conversion
#: writes, which is a function of the source alone.
ChildSchedule = Callable[[Region, dict[str, Region]], tuple[str | None, frozenset[tuple[str, str]]]]


def declares_outcomes(fsm: FSM) -> bool:
    """Whether some state declares its outcomes (a reader of an outcome-driven format)."""
    return any(
        state_info.declared_outcomes(state) is not None
        for _path, _machine, state in fsm.walk()
        if state.is_atomic and not state.final
    )


_NOT_KEY = re.compile(r"[^A-Za-z0-9_]+")


def _sanitize(text: str) -> str:
    out = _NOT_KEY.sub("_", text).strip("_") or "state"
    return out if not out[0].isdigit() else f"s_{out}"


def read_outcome_view(
    fsm: FSM, rules: OutcomeRules | None = None, schedule: ChildSchedule | None = None
) -> OutcomeView:
    """Check ``fsm`` is outcome-driven and read its units (see the module docstring).

    ``schedule`` says how a Concurrence's container child runs under a Parallel; without it
    only a child without loops is read in rounds.

    Raises:
        OutcomeError: the first violation, naming the state's path and the cause.
    """
    rules = rules or OutcomeRules()
    if fsm.initial_event is not None:
        raise OutcomeError(
            f"the start waits for the external event "
            f"'{fsm.initial_event}' (an event-driven machine, not an outcome-driven one)",
            element=f"machine '{fsm.name}'",
        )
    regions: dict[str, Region] = {}
    notes: dict[str, list[str]] = {}  # unit path -> its order choices, in words
    top_halting = frozenset(
        {HALT_OUTCOME} if HALT_OUTCOME in fsm.states and fsm.states[HALT_OUTCOME].final else ()
    )
    _read_regions(fsm, [("", fsm, None, top_halting)], regions)
    _read_statuses(regions, rules, notes)
    top = regions[""]
    top.exit_status, top_choice = rules.statuses(top.exits)
    _read_exit_statuses(regions)
    for region in list(regions.values()):
        _read_parallel(region, fsm, rules, notes, regions, schedule)
    order_choices = [
        note for r in regions.values() for u in r.units.values() for note in notes.get(u.path, [])
    ]
    if top_choice:
        order_choices.append(
            f"{fsm.name}: outcome '{top.exits[0]}' read as SUCCESS, '{top.exits[1]}' as FAILURE"
        )
    halts = sum(len(u.halted) for r in regions.values() for u in r.units.values())
    by_label = _assign_labels(regions)
    return OutcomeView(fsm, rules, regions, by_label, order_choices, halts)


#: A region to read: its path, machine, owner unit and the halting finals of its machine.
_Job = tuple[str, FSM, "Unit | None", frozenset[str]]


def _read_regions(fsm: FSM, work: list[_Job], regions: dict[str, Region]) -> None:
    """Read every region the work list reaches into ``regions`` (the shape rules of the
    module docstring; each violation an ``OutcomeError``)."""
    while work:
        path, machine, owner, halting = work.pop()
        region = Region(path, machine, owner)
        regions[path] = region
        if machine.initial is None or machine.initial not in machine.states:
            raise OutcomeError("no initial state", element=f"machine '{path or fsm.name}'")
        for name, state in machine.states.items():
            where = f"{path}/{name}" if path else name
            if state.final:
                continue
            if state.is_parallel:
                raise OutcomeError(
                    "a Concurrence (parallel regions) has no structured form in this version",
                    element=f"state '{where}'",
                    location=state.location,
                )
            outgoing = machine.outgoing(name)
            if state.is_composite:
                unit, inner_halting = _container_unit(where, name, state, outgoing, halting)
                work.append((where, state.regions[0], unit, inner_halting))
            else:
                unit = _leaf_unit(where, name, state, outgoing, halting)
            region.units[name] = unit
        reached = {t for u in region.units.values() for t in u.targets.values()}
        reached.add(region.initial)
        region.exits = [n for n, s in machine.states.items() if s.final and n in reached]


def _read_statuses(
    regions: dict[str, Region], rules: OutcomeRules, notes: dict[str, list[str]]
) -> None:
    """Each unit's outcome statuses (a container's exits have its outcomes' statuses)."""
    for region in regions.values():
        for unit in region.units.values():
            if unit.container:
                inner = regions[unit.path]
                unit.outcomes = tuple(o for o in inner.exits if o in unit.targets)
                unit.targets = {o: unit.targets[o] for o in unit.outcomes}
            unit.status, unit.order_choice = rules.statuses(list(unit.outcomes))
            if unit.dispatch and len(set(unit.targets.values())) == 2:
                # two places to go: a binary leaf, whatever the names (docs/semantics.md §11)
                first = unit.targets[unit.outcomes[0]]
                unit.status = {
                    o: SUCCESS if unit.targets[o] == first else FAILURE for o in unit.outcomes
                }
                unit.order_choice = False
                notes.setdefault(unit.path, []).append(
                    f"{unit.path}: the outcomes leading to '{first}' read as SUCCESS, the "
                    "others as FAILURE (two places to go)"
                )
            if not unit.dispatch:  # one place to go whatever the status: say SUCCESS
                unit.status = {o: s or SUCCESS for o, s in unit.status.items()}
            if unit.order_choice:
                notes.setdefault(unit.path, []).append(_order_note(unit))


def _read_exit_statuses(regions: dict[str, Region]) -> None:
    """A container's region: its exits' statuses (its owner's); every region's flag key."""
    for path, region in regions.items():
        if region.owner is not None:
            region.exit_status = {e: region.owner.status.get(e) for e in region.exits}
        region.pc_key = "pc" if not path else f"pc_{_sanitize(path)}"


def _order_note(unit: Unit) -> str:
    first, second = unit.outcomes
    return f"{unit.path}: '{first}' read as SUCCESS, '{second}' as FAILURE (first declared outcome)"


def _read_parallel(
    region: Region,
    fsm: FSM,
    rules: OutcomeRules,
    notes: dict[str, list[str]],
    regions: dict[str, Region],
    schedule: ChildSchedule | None,
) -> None:
    """A Concurrence: read in rounds when a parallel form is exactly equivalent (its units
    become its children, a container child's regions join ``regions``), else named with the
    cause (``outcome_parallel``; docs/semantics.md §11, "Concurrences: Parallel or product")."""
    owner = region.owner
    concurrence = read_concurrence(owner.state if owner is not None else fsm)
    if concurrence is None:
        return
    region.concurrence = concurrence
    children: dict[str, Unit] = {}
    statuses: list[dict[str, str]] = []
    inner: dict[str, Region] = {}
    trips: set[tuple[str, str]] = set()
    if concurrence.machines and not concurrence.smach:
        concurrence.why = (
            "FlexBE steps a container child one state per tick, where its SubTree would go on "
            "in the same tick"
        )
        return
    for index, state in enumerate(concurrence.child_states()):
        where = f"{region.path}/{state.name}" if region.path else state.name
        outcomes = concurrence.outcomes[index]
        machine = concurrence.machines.get(state.name)
        if machine is not None:
            found = _container_child(where, machine, fsm, rules, notes, inner, schedule is None)
            if isinstance(found, str):
                concurrence.why = f"child '{state.name}' {found}"
                return
            outcomes = list(found)
            concurrence.outcomes[index] = outcomes
        status, choice = rules.statuses(outcomes)
        if RUNNING_INPUT in outcomes:
            concurrence.why = f"child '{state.name}' has an outcome named '{RUNNING_INPUT}'"
            return
        missing = [o for o in outcomes if status[o] is None]
        if missing or not outcomes:
            concurrence.why = (
                f"child '{state.name}': outcome '{missing[0]}' has no status under the outcome "
                "rules"
                if missing
                else f"child '{state.name}' declares no outcome"
            )
            return
        full = {o: str(s) for o, s in status.items()}
        statuses.append(full)
        unit = Unit(where, state.name, state, machine is not None, tuple(outcomes),
                    {o: "" for o in outcomes}, dict(full), (), choice)  # fmt: skip
        children[state.name] = unit
        if machine is not None and schedule is not None:
            inner[where].owner = unit
            mine = {p: r for p, r in inner.items() if p == where or p.startswith(where + "/")}
            _read_exit_statuses(mine)
            why, yields = schedule(inner[where], mine)
            if why is not None:
                concurrence.why = f"child '{state.name}' {why}"
                return
            trips |= yields

    def outcome_status(outcome: str) -> tuple[str | None, str]:
        if owner is None:
            return (FAILURE if region.exit_status.get(outcome) == FAILURE else SUCCESS), ""
        if outcome in owner.halted:
            return None, "halts the tree ('preempted' modelled as a halt)"
        if owner.dispatch:
            return None, "is dispatched on (the container's outcomes lead to more than two places)"
        return owner.status.get(outcome), "leads nowhere"

    callback = _callback_unit(region, concurrence, outcome_status)
    if isinstance(callback, Unit):
        concurrence.form = ParallelForm("ParallelAll", (("max_failures", "1"),), "ForceSuccess")
        children[callback.name] = callback
        notes.pop(callback.path, None)  # its statuses are its container's
    elif callback:
        concurrence.why = callback
        return
    else:
        choose_form(concurrence, statuses, outcome_status)
    if concurrence.form is None:
        return
    region.units = children
    region.round_trips = frozenset(trips)
    for unit in children.values():
        if unit.container:
            inner[unit.path].owner = unit
        if unit.order_choice:
            notes.setdefault(unit.path, []).append(_order_note(unit))
    regions.update(inner)
    _read_exit_statuses(inner)


def _callback_unit(
    region: Region,
    concurrence: Concurrence,
    outcome_status: Callable[[str], tuple[str | None, str]],
) -> Unit | str:
    """A SMACH ``outcome_cb``: its product state as the leaf run once every child has ended,
    returning its container's result (``ForceSuccess(ParallelAll)`` then that leaf:
    docs/semantics.md §11, "Concurrence callbacks"); why not; "" without one."""
    name = concurrence.callback_state
    if "outcome_cb" not in concurrence.callbacks:
        return ""
    unit = region.units.get(name or "")
    if unit is None or unit.container:
        return "its outcome_cb has no state of its own"
    status: dict[str, str | None] = {}
    for outcome in unit.outcomes:
        status[outcome], why = outcome_status(outcome)
        if status[outcome] is None:
            text = concurrence.callbacks["outcome_cb"]
            return f"its outcome_cb {text} may give '{outcome}', which {why}"
    unit.status = status
    unit.gives_result = True
    unit.order_choice = False
    return unit


def _container_child(
    where: str,
    machine: FSM,
    fsm: FSM,
    rules: OutcomeRules,
    notes: dict[str, list[str]],
    regions: dict[str, Region],
    no_loops: bool,
) -> tuple[str, ...] | str:
    """A container child of a concurrence (a StateMachine, a YASMIN Region): its regions read
    into ``regions`` and its outcomes (the exits its machine reaches), or why it keeps the
    product. The round reading must know where its tree returns RUNNING: without a
    ``ChildSchedule`` (``no_loops``) only where a leaf does, so it may have no loop (a loop
    node returns RUNNING between iterations: docs/semantics.md §11); no concurrence inside;
    and it must run a state before it ends."""
    found: dict[str, Region] = {}
    try:
        _read_regions(fsm, [(where, machine, None, frozenset())], found)
    except OutcomeError as error:
        return f"is not outcome-driven ({error})"
    for sub in found.values():
        looping = _loop_state(sub) if no_loops else None
        if looping is not None:
            return (
                f"loops back to '{looping}' (a loop node returns RUNNING between iterations, "
                "which the round reading does not follow)"
            )
        if any(read_concurrence(u.state) is not None for u in sub.units.values()):
            return "holds a concurrence"
    top = found[where]
    if machine.states[top.initial].final:
        return "ends before running a state"
    if not top.exits:
        return "never ends"
    _read_statuses(found, rules, notes)
    regions.update(found)
    return tuple(top.exits)


def _loop_state(region: Region) -> str | None:
    """A unit of the region on a cycle of its transitions, else None (iterative DFS)."""
    graph = {name: [t for t in u.targets.values() if t in region.units]
             for name, u in region.units.items()}  # fmt: skip
    colour: dict[str, int] = {}
    for root in graph:
        if root in colour:
            continue
        colour[root] = 1
        stack: list[tuple[str, int]] = [(root, 0)]
        while stack:
            node, i = stack.pop()
            if i < len(graph[node]):
                stack.append((node, i + 1))
                nxt = graph[node][i]
                if colour.get(nxt) == 1:
                    return nxt
                if nxt not in colour:
                    colour[nxt] = 1
                    stack.append((nxt, 0))
            else:
                colour[node] = 2
    return None


def _leaf_unit(
    where: str,
    name: str,
    state: State,
    outgoing: list,  # type: ignore[type-arg]
    halting: frozenset[str],
) -> Unit:
    declared = state_info.declared_outcomes(state)
    order: list[str] = []
    targets: dict[str, str] = {}
    for t in outgoing:
        if t.event is None:
            raise OutcomeError(
                f"a completion transition to '{t.target}' (an atomic "
                "outcome-driven state leaves only on one of its outcomes)",
                element=f"state '{where}'",
                location=t.location or state.location,
            )
        if declared is not None and t.event not in declared:
            raise OutcomeError(
                f"event '{t.event}' is not one of its declared outcomes "
                f"({', '.join(declared) or 'none'}): the machine mixes external events and "
                "outcomes",
                element=f"state '{where}'",
                location=t.location or state.location,
            )
        if t.event == RUNNING_INPUT:
            raise OutcomeError(
                f"an outcome named '{RUNNING_INPUT}' cannot be told from a running leaf",
                element=f"state '{where}'",
            )
        if t.event not in targets:
            targets[t.event] = t.target
            order.append(t.event)
    if declared is not None:
        order = [o for o in declared if o in targets] + [o for o in order if o not in declared]
    halted = tuple(o for o in order if o == HALT_OUTCOME and targets[o] in halting)
    kept = [o for o in order if o not in halted]
    if not kept and not halted:
        raise OutcomeError(
            "no outcome leaves it (an outcome-driven state must return one)",
            element=f"state '{where}'",
            location=state.location,
        )
    return Unit(
        where, name, state, False, tuple(kept), {o: targets[o] for o in kept}, {}, halted, False
    )


def _container_unit(
    where: str,
    name: str,
    state: State,
    outgoing: list,  # type: ignore[type-arg]
    halting: frozenset[str],
) -> tuple[Unit, frozenset[str]]:
    inner = state.regions[0]
    finals = [n for n, s in inner.states.items() if s.final]
    targets: dict[str, str] = {}
    any_target: str | None = None
    for t in outgoing:
        if t.event is not None:
            raise OutcomeError(
                f"the container handles event '{t.event}' (an event that "
                "interrupts a running container is not an outcome)",
                element=f"state '{where}'",
                location=t.location or state.location,
            )
        if t.exit is None:
            any_target = any_target or t.target
        elif t.exit in inner.states and inner.states[t.exit].final:
            targets.setdefault(t.exit, t.target)
        else:
            raise OutcomeError(
                f"a completion transition waits for '{t.exit}', which is no "
                "outcome of the container",
                element=f"state '{where}'",
                location=t.location or state.location,
            )
    for final in finals:
        if final not in targets and any_target is not None:
            targets[final] = any_target
    inner_halting = frozenset(f for f in finals if f in targets and targets[f] in halting)
    halted = tuple(f for f in finals if f == HALT_OUTCOME and f in inner_halting)
    kept = [f for f in finals if f in targets and f not in halted]
    unit = Unit(
        where, name, state, True, tuple(kept), {o: targets[o] for o in kept}, {}, halted, False
    )
    return unit, inner_halting


def _assign_labels(regions: dict[str, Region]) -> dict[str, Unit]:
    """Labels: the state's name, or its path where two units share a name; blackboard keys
    ``<label>_outcome`` made unique."""
    counts: dict[str, int] = {}
    for region in regions.values():
        for unit in region.units.values():
            counts[unit.name] = counts.get(unit.name, 0) + 1
    by_label: dict[str, Unit] = {}
    keys: set[str] = set()
    for region in regions.values():
        for unit in region.units.values():
            unit.label = unit.name if counts[unit.name] == 1 else unit.path
            by_label[unit.label] = unit
            key = f"{_sanitize(unit.label)}_outcome"
            suffix = 2
            while key in keys:
                key = f"{_sanitize(unit.label)}_outcome{suffix}"
                suffix += 1
            keys.add(key)
            unit.key = key
    return by_label
