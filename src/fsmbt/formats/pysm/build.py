"""SMACH / FlexBE container records -> fsmbt's hierarchical FSM (docs/formats/smach.md).

Mapping rules:
- A ``StateMachine`` / ``Sequence`` / ``OperatableStateMachine`` / ``PriorityContainer`` is a
  machine: one state per ``add`` (label = state name, action = the state's class; a container
  or embedded behaviour is a composite state with no action of its own), one final state per
  container outcome, the first added state initial unless ``set_initial_state`` names another.
- Events are outcomes: ``transitions={o: t}`` of a leaf state is ``label --o--> t``; of a
  composite state a completion transition ``exit=o`` (it fires when the inner machine ends in
  its final state ``o``). An outcome left unmapped or mapped to ``None`` falls through to the
  container outcome of the same name, as SMACH does; when there is none that is the run-time
  error SMACH raises, reported here as ``InputError`` with the line. A target that is neither a
  label nor a container outcome, an outcome the state does not declare, or a ``Concurrence``
  outcome map naming an unknown child is an ``InputError`` too. A container outcome no
  transition reaches is a warning.
- ``Sequence`` links each state's connector outcome to the next added state unless mapped;
  ``add_auto`` links its connector outcomes to the next added state (overriding, as SMACH's
  code does).
- ``Concurrence`` / ``ConcurrencyContainer`` is a composite state whose inner machine is the
  product of its children (a leaf child is its state plus one final state per outcome; a
  container child its flattened machine): a state per combination of child positions, one
  event per child event (qualified ``LABEL.event`` when two children share an event name, so
  each child's input stays independent). SMACH: when all children are done, the last matching
  entry of ``outcome_map`` (else ``default_outcome``) ends it; FlexBE: after each child step
  the first satisfied condition ends it (children not finished are stopped). Entering it runs
  every child's first action (``A+B``); a later product state runs only what the child that
  moved starts (product states are split by that action).
- ``Iterator`` with a static item list (literal list/tuple, ``range`` of integers, at most
  ``MAX_UNROLLED_ITEMS``) is unrolled, one copy of the contained state per item; with items
  computed at run time, the number of items is an environment choice after each loop outcome
  (events ``<label>.next`` / ``<label>.exhausted``), named in a warning.
- An embedded FlexBE behaviour is read from the file its import names, looked up in its own
  ROS package (``fsmbt.formats.pysm.find``; docs/formats/flexbe.md "Embedded behaviours"),
  and nested as a composite; not found, it is one opaque state whose outcomes are those its
  transitions name (a warning; reader option ``strict`` refuses).
- ConcurrencyContainer / Concurrence product states get names no other state has
  (``_product_name``).
- What each state was configured with (parameters, declared outcomes, userdata keys,
  remapping, ROS interface, editor position) goes into ``State.attrs`` through
  ``fsmbt.model.state_info`` (``leaf_info``, ``container_info``); it never changes the machine.

Everything is built with an explicit work stack. Costs: O(S + T) per machine; a concurrence
costs the product of (1 + outcomes) over its children, capped at ``MAX_PRODUCT_STATES``.
"""

from __future__ import annotations

import ast
import hashlib
import json
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from fsmbt import limits
from fsmbt.formats.pysm.analyze import (
    MAX_UNROLLED_ITEMS,
    Analysis,
    Child,
    ClassResolver,
    Container,
    Embedded,
    StateRef,
    analyze,
)
from fsmbt.formats.pysm.find import find_module_file
from fsmbt.formats.pysm.params import ClassDecl, class_declaration
from fsmbt.formats.pysm.source import parse_python
from fsmbt.formats.registry import ReadContext, decode
from fsmbt.model import state_info
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.model.files import note_read, read_bounded, read_located
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM, State, Transition
from fsmbt.model.serialize import fsm_to_dict

MAX_PRODUCT_STATES = 20_000
#: Where a concurrence child is: ``(False, flat state)`` while it runs, ``(True, outcome)`` done.
Position = tuple[bool, str]
#: A product state: every child's position, and the action that entering it runs.
Key = tuple[tuple[Position, ...], str | None]
#: ``State.attrs`` keys the SMACH writer reads back (docs/formats/smach.md).
A_CLASS = "class"
A_CONTAINER = "smach.container"
A_CHILDREN = "smach.children"
A_MAP = "smach.outcome_map"
A_DEFAULT = "smach.default_outcome"
#: A concurrence with a container child (a StateMachine, an OrthogonalState's Region): its class,
#: children, outcome map, default and each container child's machine, as one JSON object
#: (``semantics.outcome_parallel``; the smach.* keys above stay for leaf children only, which
#: the SMACH and YASMIN writers write back as a Concurrence).
A_NESTED = "smach.concurrence"
#: SMACH Concurrence callbacks (never run): name -> source text (docs/semantics.md §11).
A_CALLBACKS = "smach.callbacks"
A_BEHAVIOUR = "flexbe.behaviour"
#: An embedded behaviour whose file was not found, read as one state (docs/formats/flexbe.md).
A_OPAQUE = "flexbe.opaque"


@dataclass
class _Source:
    """One analysed file (the main one or an embedded behaviour's)."""

    path: Path | None
    name: str
    analysis: Analysis


@dataclass
class _Work:
    container: Container
    machine: FSM
    label: str
    source: _Source
    chain: tuple[str, ...]  # behaviour files on the way here (cycle check)
    path: str = ""  # label path from the file's top container ("" = top, "A/B")
    phase: int = 0  # concurrences: 0 = build the container children first, 1 = the product
    child_machines: dict[str, FSM] = field(default_factory=dict)


@dataclass
class ClassFiles:
    """State classes of other modules, found through imports in the ROS package layout
    (``fsmbt.formats.pysm.find``) and read statically, each file once."""

    files: dict[Path, dict[str, ClassDecl]] = field(default_factory=dict)

    def resolver(self, importer: Path | None) -> ClassResolver | None:
        """The class resolver for a file's imports (``None`` for a text with no file)."""
        if importer is None:
            return None

        def resolve(module: str, name: str) -> ClassDecl | None:
            path = find_module_file(importer, module)
            if path is None:
                return None
            return self.classes(path.resolve()).get(name)

        return resolve

    def classes(self, path: Path) -> dict[str, ClassDecl]:
        """The top-level classes of one module file (empty when it cannot be read)."""
        if path not in self.files:
            try:
                text = decode(read_located(path), str(path))
                _, tree, _ = parse_python(text, str(path))
            except InputError:  # a state module fsmbt cannot read: its classes stay unknown
                self.files[path] = {}
                return {}
            self.files[path] = {
                stmt.name: class_declaration(stmt)
                for stmt in tree.body
                if isinstance(stmt, ast.ClassDef)
            }
        return self.files[path]


@dataclass
class Builder:
    """Builds the FSM of one root container (and whatever it nests)."""

    ctx: ReadContext
    main: _Source
    classes: ClassFiles = field(default_factory=ClassFiles)
    loaded: dict[Path, _Source] = field(default_factory=dict)
    owners: dict[int, State] = field(default_factory=dict)  # id(region FSM) -> its state

    def warn(self, source: _Source, line: int | None, message: str) -> None:
        self.ctx.warnings.append(f"{SourceLocation(source.name, line)}: {message}")

    def loc(self, source: _Source, line: int | None) -> SourceLocation:
        return SourceLocation(source.name, line)

    def build(self, root: Container, name: str) -> FSM:
        top = FSM(name=name)
        stack = [_Work(root, top, name, self.main, (), "")]
        while stack:
            work = stack.pop()
            if work.container.blocker is not None:
                raise work.container.blocker
            kind = work.container.kind
            if kind in ("concurrence", "flexbe-concurrency"):
                if work.phase == 0:
                    pending = self.concurrence_children(work)
                    if pending:
                        work.phase = 1
                        stack.append(work)
                        stack.extend(pending)
                        continue
                self.concurrence(work)
            elif kind == "iterator":
                stack.extend(self.iterator(work))
            else:
                stack.extend(self.machine(work))
        return top

    # -- children -----------------------------------------------------------------------------
    def child_state(
        self, work: _Work, child: Child, name: str | None = None
    ) -> tuple[State, list[str] | None, _Work | None]:
        """The state for ``child``, its outcomes (None = unknown), and the work to fill it."""
        label = name or child.label
        where = self.loc(work.source, child.line)
        state = child.state
        sub_path = f"{work.path}/{label}" if work.path else label
        found = self.embedded(work, state, child) if isinstance(state, Embedded) else None
        if isinstance(state, Embedded) and found is None:
            state = child.state = self.opaque(work, state, child)
        if isinstance(state, StateRef):
            actions = work.source.analysis.extension.get("actions")
            action: str | None = state.cls
            if isinstance(actions, dict) and state.cls in actions:
                mapped = actions[state.cls]
                action = mapped if isinstance(mapped, str) else None
            attrs = {A_CLASS: "CBState"} if state.callback else {}
            if state.opaque_behaviour:
                attrs = {A_BEHAVIOUR: state.cls, A_OPAQUE: "true"}
            attrs.update(leaf_info(state, child))
            undeclared = work.source.analysis.extension.get("undeclared_outcomes")
            if isinstance(undeclared, list) and sub_path in undeclared:
                attrs.pop(state_info.OUTCOMES, None)  # stub outcomes fsmbt wrote, not declared
            return (State(label, action=action, attrs=attrs, location=where), state.outcomes, None)
        if isinstance(state, Container):
            region = FSM(name=label)
            composite = State(
                label,
                action=None,
                regions=[region],
                location=where,
                attrs=container_info(state, child),
            )
            self.owners[id(region)] = composite
            return (
                composite,
                list(state.outcomes),
                _Work(state, region, label, work.source, work.chain, sub_path),
            )
        assert found is not None
        root, source = found
        region = FSM(name=label)
        composite = State(
            label,
            action=None,
            regions=[region],
            location=where,
            attrs={A_BEHAVIOUR: state.cls, **container_info(root, child)},
        )
        self.owners[id(region)] = composite
        chain = (*work.chain, str(source.path))
        return composite, list(root.outcomes), _Work(root, region, label, source, chain, "")

    def embedded(
        self, work: _Work, ref: Embedded, child: Child
    ) -> tuple[Container, _Source] | None:
        """The embedded behaviour's machine and file; ``None`` when its file is not found
        (the caller reads the state as opaque, or refuses under option ``strict``)."""
        here = work.source
        found = here.analysis.behaviours.get(ref.cls)
        if ref.cls in here.analysis.behaviours:
            if found is None:
                raise UnsupportedError(
                    f"embedded behaviour '{ref.cls}': its create() does not "
                    "return a state machine fsmbt can read",
                    location=self.loc(here, child.line),
                )
            return found, here
        if here.path is None:
            return None  # a text with no file: nothing to look beside
        path = find_module_file(here.path, ref.module)
        if path is None and ref.module is None:
            path = self.class_beside(here, ref.cls)
        if path is None:
            return None
        path = path.resolve()
        if str(path) in work.chain or path == (
            self.main.path.resolve() if self.main.path else None
        ):
            raise InputError(
                f"embedded behaviour '{ref.cls}' ({path.name}) embeds itself "
                "(directly or through others)",
                location=self.loc(here, child.line),
            )
        source = self.load(path)
        root = source.analysis.behaviours.get(ref.cls)
        if root is None:
            raise UnsupportedError(
                f"embedded behaviour '{ref.cls}': {path.name} has no "
                f"Behavior class '{ref.cls}' whose create() returns a state "
                "machine",
                location=self.loc(here, child.line),
            )
        return root, source

    def class_beside(self, here: _Source, cls: str) -> Path | None:
        """A ``*.py`` beside ``here`` defining ``cls``, for a class with no import to follow
        (same folder = same package); the file chosen is named in a warning."""
        assert here.path is not None
        folder = here.path.parent
        marker = f"class {cls}("
        note_read(folder)  # the class may be defined in a file added later
        for path in sorted(folder.glob("*.py")):
            try:
                if path.stat().st_size <= limits.current().max_input_bytes and marker in (
                    read_bounded(path).decode("utf-8", errors="replace")
                ):
                    self.warn(
                        here,
                        None,
                        f"embedded behaviour '{cls}' is not imported; read from {path.name}, "
                        "the file beside this one that defines it",
                    )
                    return path
            except (OSError, InputError):  # unreadable, or not a regular file: not it
                continue
        return None

    def opaque(self, work: _Work, ref: Embedded, child: Child) -> StateRef:
        """An embedded behaviour whose file is not found, as one state whose outcomes are the
        ones its transitions name (a warning), or ``UnsupportedError`` under option
        ``strict`` (docs/formats/flexbe.md, "Embedded behaviours")."""
        where = self.loc(work.source, child.line)
        if work.source.path is None:
            looked = "read from a text, not a file, so no other file is looked at"
        else:
            wanted = f"module {ref.module}" if ref.module else "no import names its module"
            looked = f"{wanted}; looked in its own package and beside this file"
        if is_strict(self.ctx):
            raise UnsupportedError(
                f"embedded behaviour '{ref.cls}' not found ({looked}); strict reading "
                "refuses an opaque state",
                location=where,
            )
        outcomes = list(child.transitions)
        self.warn(
            work.source,
            child.line,
            f"embedded behaviour '{ref.cls}' not found ({looked}): read as one opaque "
            f"state '{child.label}' whose outcomes are those its transitions name "
            f"({', '.join(outcomes) or 'none'}); --strict refuses instead",
        )
        return StateRef(ref.cls, outcomes, ref.line, opaque_behaviour=True)

    def load(self, path: Path) -> _Source:
        if path in self.loaded:
            return self.loaded[path]
        text = decode(read_located(path), str(path))
        text, tree, notes = parse_python(text, str(path))
        analysis = analyze(text, tree, str(path), self.classes.resolver(path))
        source = _Source(path, str(path), analysis)
        if notes:
            self.warn(source, None, python2_warning(notes))
        for line, message in analysis.warnings:
            self.warn(source, line, message)
        self.loaded[path] = source
        return source

    # -- state machines -----------------------------------------------------------------------
    def machine(self, work: _Work) -> list[_Work]:
        container, fsm = work.container, work.machine
        children = container.children
        if not children:
            raise InputError(
                f"container '{container.name}' has no states (SMACH's consistency check fails)",
                location=self.loc(work.source, container.line),
            )
        labels = {c.label for c in children}
        for outcome in container.outcomes:
            if outcome in labels:
                raise UnsupportedError(
                    f"container outcome '{outcome}' is also a state label in '{container.name}'",
                    location=self.loc(work.source, container.line),
                )
        pending: list[_Work] = []
        outcomes_of: dict[str, list[str] | None] = {}
        for child in children:
            state, outcomes, sub = self.child_state(work, child)
            fsm.states[state.name] = state
            outcomes_of[child.label] = outcomes
            if sub is not None:
                pending.append(sub)
        finals = work.source.analysis.extension.get("final_actions")
        final_actions = finals.get(work.path, {}) if isinstance(finals, dict) else {}
        for outcome in container.outcomes:
            action = final_actions.get(outcome) if isinstance(final_actions, dict) else None
            fsm.states[outcome] = State(
                outcome,
                action=action if isinstance(action, str) else None,
                final=True,
                location=self.loc(work.source, container.line),
            )
        initial = container.initial or children[0].label
        if initial not in labels:
            raise InputError(
                f"set_initial_state names '{initial}', not a state of '{container.name}'",
                location=self.loc(work.source, container.initial_line),
            )
        fsm.initial = initial
        transitions = self.linked_transitions(container)
        reached: set[str] = set()
        for child, mapping in zip(children, transitions):
            self.add_transitions(work, child, mapping, outcomes_of[child.label], labels, reached)
        for outcome in container.outcomes:
            if outcome not in reached:
                self.warn(
                    work.source,
                    container.line,
                    f"container '{container.name}' declares outcome '{outcome}' that no "
                    "transition reaches",
                )
        return pending

    def linked_transitions(self, container: Container) -> list[dict[str, str | None]]:
        """Each child's transitions after Sequence / add_auto linking."""
        out = [dict(c.transitions) for c in container.children]
        for index, child in enumerate(container.children[:-1]):
            following = container.children[index + 1].label
            if container.kind == "sequence" and container.connector is not None:
                if out[index].get(container.connector) is None:
                    out[index][container.connector] = following
            for connector in child.connectors:
                out[index][connector] = following
        return out

    def add_transitions(
        self,
        work: _Work,
        child: Child,
        mapping: dict[str, str | None],
        outcomes: list[str] | None,
        labels: set[str],
        reached: set[str],
    ) -> None:
        container, fsm = work.container, work.machine
        where = self.loc(work.source, child.line)
        if outcomes is not None:
            for outcome in mapping:
                if outcome not in outcomes:
                    raise InputError(
                        f"state '{child.label}' maps outcome '{outcome}' it does "
                        f"not have (its outcomes: {', '.join(outcomes)}); SMACH "
                        "raises InvalidTransitionError",
                        location=where,
                    )
            for connector in child.connectors:
                if connector not in outcomes:
                    raise InputError(
                        f"add_auto connector outcome '{connector}' is not an "
                        f"outcome of '{child.label}'",
                        location=where,
                    )
        every = list(mapping) + [o for o in (outcomes or []) if o not in mapping]
        composite = not isinstance(child.state, StateRef)
        for outcome in every:
            target = mapping.get(outcome)
            if target is None:
                if outcome not in container.outcomes:
                    raise InputError(
                        f"outcome '{outcome}' of state '{child.label}' is mapped to nothing: no "
                        f"transition and no container outcome '{outcome}' in "
                        f"'{container.name}' (SMACH's consistency check fails at run time)",
                        location=where,
                    )
                target = outcome
            elif target not in labels and target not in container.outcomes:
                raise InputError(
                    f"outcome '{outcome}' of state '{child.label}' goes to "
                    f"'{target}', which is neither a state of '{container.name}' "
                    "nor one of its outcomes",
                    location=where,
                )
            if target in container.outcomes and target not in labels:
                reached.add(target)
            attrs = {"autonomy": child.autonomy[outcome]} if outcome in child.autonomy else {}
            if composite:
                fsm.add_transition(
                    child.label, None, target, exit=outcome, attrs=attrs, location=where
                )
            else:
                fsm.add_transition(child.label, outcome, target, attrs=attrs, location=where)

    # -- concurrence --------------------------------------------------------------------------
    def concurrence_children(self, work: _Work) -> list[_Work]:
        """Phase 0 of a concurrence: the machines of its container children, built first."""
        pending: list[_Work] = []
        for child in work.container.children:
            if isinstance(child.state, Container) and child.state.kind == "priority":
                self.warn(
                    work.source,
                    child.line,
                    f"PriorityContainer '{child.label}' inside a concurrency container: "
                    "FlexBE pauses its siblings while it runs; read without that "
                    "priority (siblings may return meanwhile)",
                )
            if not isinstance(child.state, StateRef):
                state, _, sub = self.child_state(work, child)
                work.child_machines[child.label] = state.regions[0]
                if sub is not None:
                    pending.append(sub)
        return pending

    def child_machine(self, work: _Work, child: Child, what: str, smach: bool) -> FSM:
        """A child as a flat machine whose final states are its outcomes."""
        container = work.container
        if not isinstance(child.state, StateRef):
            flat = flatten(work.child_machines[child.label])
            if flat.initial is None or flat.start_name is not None:
                raise UnsupportedError(
                    f"{what} child '{child.label}' has no plain initial state",
                    location=self.loc(work.source, child.line),
                )
            return flat
        known = child.state.outcomes
        if not smach and child.transitions:
            known = list(dict.fromkeys([*(known or []), *child.transitions]))
        if known is None:
            from_map = [m[child.label] for _, m in container.outcome_map if child.label in m]
            if not from_map:
                raise UnsupportedError(
                    f"outcomes of {what} child '{child.label}' (class {child.state.cls}) are "
                    "unknown: its class is not in the file and no outcome map names it",
                    location=self.loc(work.source, child.line),
                )
            known = list(dict.fromkeys(from_map))
            self.warn(
                work.source,
                child.line,
                f"outcomes of '{child.label}' (class "
                f"{child.state.cls}, defined elsewhere) read from the outcome map: "
                f"{', '.join(known)}",
            )
        leaf = FSM(name=child.label)
        leaf.add_state(State(child.label, action=child.state.cls))
        for outcome in known:
            leaf.add_state(State(outcome, action=None, final=True))
            leaf.add_transition(child.label, outcome, outcome)
        return leaf

    def concurrence(self, work: _Work) -> None:
        """Phase 1: the product of the children's machines (see the module docstring)."""
        container, fsm = work.container, work.machine
        smach = container.kind == "concurrence"
        what = "Concurrence" if smach else "ConcurrencyContainer"
        where = self.loc(work.source, container.line)
        if not container.children:
            raise InputError(f"{what} '{container.name}' has no states", location=where)
        labels = [c.label for c in container.children]
        machines = [self.child_machine(work, c, what, smach) for c in container.children]
        leaves = all(isinstance(c.state, StateRef) for c in container.children)
        outcomes = [[s.name for s in m.states.values() if s.final] for m in machines]
        self.check_outcome_map(work, what, labels, outcomes)
        for outcome in container.outcomes:
            fsm.states[outcome] = State(outcome, action=None, final=True, location=where)
        shared = _shares_outcomes([m.events() for m in machines])
        tables = [m.transition_map() for m in machines]
        start_positions = tuple((False, str(m.initial)) for m in machines)
        start_action = (
            "+".join(
                a for a in (m.states[str(m.initial)].action for m in machines) if a is not None
            )
            or None
        )
        names: dict[Key, str] = {}
        queue: deque[Key] = deque()
        reached: set[str] = set()

        def part(label: str, position: Position, machine: FSM) -> str:
            done, name = position
            if done:
                return f"{label}={name}"
            return label if name == machine.initial and name == label else f"{label}:{name}"

        def visit(key: Key) -> str:
            if key not in names:
                if len(names) >= MAX_PRODUCT_STATES:
                    raise UnsupportedError(
                        f"{what} '{container.name}' has more than "
                        f"{MAX_PRODUCT_STATES} combinations of child states",
                        location=where,
                    )
                positions, action = key
                name = ",".join(
                    part(lab, pos, m) for lab, pos, m in zip(labels, positions, machines)
                )
                if key[0] != start_positions and action is not None:
                    name = f"{name} ({action})"
                name = _product_name(name, action, key[0] == start_positions, fsm)
                names[key] = name
                fsm.states[name] = State(name, action=action, location=where)
                queue.append(key)
            return names[key]

        callback = self.outcome_callback(work, fsm) if smach else None
        if "child_termination_cb" in container.callbacks:
            self.warn(
                work.source,
                container.line,
                f"Concurrence '{container.name}': child_termination_cb "
                f"{container.callbacks['child_termination_cb']} not modelled: it only asks the "
                "running children to stop, and when a child ends with which outcome is already "
                "the environment's choice",
            )
        if callback is not None:
            reached.update(container.outcomes)
        barriers: dict[tuple[int, str], list[tuple[int, str]]] = {}
        for members in container.sync_groups:
            parties = [(labels.index(label), state) for label, state in members]
            for party in parties:
                barriers[party] = parties
        fsm.initial = visit((start_positions, start_action))
        stuck: list[str] = []
        while queue:
            key = queue.popleft()
            positions = key[0]
            source = names[key]
            for index, (done, current) in enumerate(positions):
                if done:
                    continue
                group = barriers.get((index, current))
                for event, transition in tables[index].get(current, {}).items():
                    if event is None:
                        continue
                    target_state = machines[index].states[transition.target]
                    action = None if target_state.final else target_state.action
                    if group is not None:
                        passed = self.barrier(group, index, positions, tables, machines)
                        if passed is None:
                            continue  # not every party has arrived (or another one leads)
                        after, action = passed
                    else:
                        moved: Position = (target_state.final, transition.target)
                        after = positions[:index] + (moved,) + positions[index + 1 :]
                    combo = tuple(name if is_done else None for is_done, name in after)
                    qualified = f"{labels[index]}.{event}" if shared else event
                    decided = self.decide(container, smach, labels, combo)
                    if decided is not None and callback is not None:
                        fsm.add_transition(source, qualified, callback)
                        continue
                    if decided is not None:
                        reached.add(decided)
                        fsm.add_transition(source, qualified, decided)
                        continue
                    target = visit((after, action))
                    fsm.add_transition(source, qualified, target)
                    if all(is_done for is_done, _ in after):
                        stuck.append(target)
        for name in dict.fromkeys(stuck):
            self.warn(
                work.source,
                container.line,
                f"{what} '{container.name}': when its children end as '{name}' no "
                "condition holds, so FlexBE waits there forever",
            )
        for outcome in container.outcomes:
            if outcome not in reached:
                self.warn(
                    work.source,
                    container.line,
                    f"{what} '{container.name}' declares outcome '{outcome}' that no "
                    "combination of child outcomes gives",
                )
        refs = [c.state for c in container.children if isinstance(c.state, StateRef)]
        owner = self.owner_state(work)
        attrs = owner.attrs if owner is not None else fsm.attrs
        undeclared = work.source.analysis.extension.get("undeclared_outcomes")
        children_info: dict[str, dict[str, str]] = {}
        for c in container.children:
            if not isinstance(c.state, StateRef):
                continue
            info = leaf_info(c.state, c)
            child_path = f"{work.path}/{c.label}" if work.path else c.label
            if isinstance(undeclared, list) and child_path in undeclared:
                info.pop(state_info.OUTCOMES, None)  # stub outcomes fsmbt wrote
            if info:
                children_info[c.label] = info
        if children_info:
            attrs[state_info.CHILD_STATES] = json.dumps(children_info)
        if container.callbacks:
            attrs[A_CALLBACKS] = json.dumps(container.callbacks)
        if not leaves:
            attrs[A_NESTED] = json.dumps(
                {
                    "class": container.cls,
                    "children": [
                        [lab, _child_class(c), outs]
                        for lab, c, outs in zip(labels, container.children, outcomes)
                    ],
                    "outcome_map": container.outcome_map,
                    "default": container.default_outcome,
                    "barriers": len(container.sync_groups),
                    "product": product_fingerprint(fsm),
                    "machines": {
                        c.label: fsm_to_dict(work.child_machines[c.label])
                        for c in container.children
                        if not isinstance(c.state, StateRef)
                    },
                }
            )
            return
        attrs.update(
            {
                A_CONTAINER: container.cls,
                A_CHILDREN: json.dumps(
                    [[lab, r.cls, outs] for lab, r, outs in zip(labels, refs, outcomes)]
                ),
                A_MAP: json.dumps(container.outcome_map),
            }
        )
        if container.default_outcome is not None:
            attrs[A_DEFAULT] = container.default_outcome

    def barrier(
        self,
        group: list[tuple[int, str]],
        index: int,
        positions: tuple[Position, ...],
        tables: list[dict[str, dict[str | None, Transition]]],
        machines: list[FSM],
    ) -> tuple[tuple[Position, ...], str | None] | None:
        """A YASMIN JoinState barrier: every party leaves at once, when every one has arrived.

        ``group`` lists (child index, join state) of one ``sync_id``; the step is taken from
        its first party only (one product transition per crossing). ``None`` while a party is
        elsewhere: a region that ends without reaching its join leaves the others waiting, as
        YASMIN's ``RegionBarrier`` does (docs/formats/yasmin.md). Returns the positions after
        the crossing and the actions the parties start (``+``-joined).
        """
        if group[0][0] != index:
            return None
        moved = list(positions)
        actions: list[str] = []
        for child, state in group:
            if positions[child] != (False, state):
                return None
            steps = [t for e, t in tables[child].get(state, {}).items() if e is not None]
            if not steps:
                return None
            target = machines[child].states[steps[0].target]
            moved[child] = (target.final, target.name)
            if not target.final and target.action is not None:
                actions.append(target.action)
        return tuple(moved), "+".join(actions) or None

    def outcome_callback(self, work: _Work, fsm: FSM) -> str | None:
        """A SMACH ``outcome_cb``, never run: once every child has ended, a state named after
        it returns any declared outcome of the container - the environment's choice, which
        includes what the callback returns and the map's outcome when it returns None
        (docs/semantics.md §11, "Concurrence callbacks"). Its name, or None without one."""
        container = work.container
        text = container.callbacks.get("outcome_cb")
        if text is None:
            return None
        name = _product_name(text, text, False, fsm)
        where = self.loc(work.source, container.line)
        declared = json.dumps(list(container.outcomes))
        fsm.states[name] = State(
            name, action=text, attrs={state_info.OUTCOMES: declared}, location=where
        )
        for outcome in container.outcomes:
            fsm.add_transition(name, outcome, outcome, location=where)
        container.callbacks["outcome_cb_state"] = name
        self.warn(
            work.source,
            container.line,
            f"Concurrence '{container.name}': outcome_cb {text} not modelled: its outcome is "
            f"chosen by the environment (state '{name}' returns any of "
            f"{', '.join(container.outcomes)})",
        )
        return name

    def owner_state(self, work: _Work) -> State | None:
        return self.owners.get(id(work.machine))

    def decide(
        self, container: Container, smach: bool, labels: list[str], combo: tuple[str | None, ...]
    ) -> str | None:
        """The container outcome once ``combo`` is reached, or ``None`` while it runs on."""
        done = dict(zip(labels, combo))
        if smach:
            if any(o is None for o in combo):
                return None
            outcome = container.default_outcome
            for candidate, required in container.outcome_map:
                if all(done.get(label) == o for label, o in required.items()):
                    outcome = candidate  # SMACH lets the last matching entry win
            return outcome
        for candidate, required in container.outcome_map:
            if all(done.get(label) == o for label, o in required.items()):
                return candidate
        return None

    def check_outcome_map(
        self, work: _Work, what: str, labels: list[str], outcomes: list[list[str]]
    ) -> None:
        container = work.container
        where = self.loc(work.source, container.line)
        if (
            container.default_outcome is not None
            and container.default_outcome not in container.outcomes
        ):
            raise InputError(
                f"{what} default_outcome '{container.default_outcome}' is not one "
                f"of its outcomes ({', '.join(container.outcomes)})",
                location=where,
            )
        by_label = dict(zip(labels, outcomes))
        for outcome, required in container.outcome_map:
            if outcome not in container.outcomes:
                raise InputError(
                    f"{what} maps to '{outcome}', not one of its outcomes "
                    f"({', '.join(container.outcomes)})",
                    location=where,
                )
            for label, child_outcome in required.items():
                if label not in by_label:
                    raise InputError(
                        f"{what} outcome map names '{label}', not a child "
                        f"({', '.join(labels)}); SMACH fails at run time",
                        location=where,
                    )
                if child_outcome not in by_label[label]:
                    self.warn(
                        work.source,
                        container.line,
                        f"{what} outcome map expects '{label}' to return "
                        f"'{child_outcome}', which it never does",
                    )

    # -- iterator -----------------------------------------------------------------------------
    def iterator(self, work: _Work) -> list[_Work]:
        container, fsm = work.container, work.machine
        where = self.loc(work.source, container.line)
        if not container.children:
            raise InputError(
                f"Iterator '{container.name}' has no contained state "
                "(Iterator.set_contained_state)",
                location=where,
            )
        child = container.children[0]
        state0, outcomes, _ = self.child_state(work, child)
        if outcomes is None:
            raise UnsupportedError(
                f"outcomes of the Iterator's state '{child.label}' are "
                "unknown (its class is not in the file)",
                location=self.loc(work.source, child.line),
            )
        if container.break_outcomes:
            loop = [o for o in outcomes if o not in container.break_outcomes]
        else:
            loop = list(container.loop_outcomes)
        ending = [o for o in outcomes if o not in loop]

        def final_of(outcome: str) -> str:
            mapped = container.final_outcome_map.get(outcome, outcome)
            if mapped not in container.outcomes:
                raise InputError(
                    f"Iterator '{container.name}' ends with '{mapped}' (from "
                    f"'{outcome}'), not one of its outcomes",
                    location=where,
                )
            return mapped

        for outcome in container.outcomes:
            fsm.states[outcome] = State(outcome, action=None, final=True, location=where)
        exhausted = final_of(container.exhausted_outcome)
        pending: list[_Work] = []
        composite = not isinstance(child.state, StateRef)
        static = container.items is not None and container.items <= MAX_UNROLLED_ITEMS

        def add(source: str, outcome: str, target: str) -> None:
            if composite:
                fsm.add_transition(source, None, target, exit=outcome, location=state0.location)
            else:
                fsm.add_transition(source, outcome, target, location=state0.location)

        if static:
            count = container.items or 0
            copies = (
                [f"{child.label}#{i + 1}" for i in range(count)] if count != 1 else [child.label]
            )
            for index, name in enumerate(copies):
                state, _, sub = self.child_state(work, child, name)
                fsm.states[name] = state
                if sub is not None:
                    pending.append(sub)
                following = copies[index + 1] if index + 1 < count else exhausted
                for outcome in loop:
                    add(name, outcome, following)
                for outcome in ending:
                    add(name, outcome, final_of(outcome))
            fsm.initial = copies[0] if copies else exhausted
            return pending
        state, _, sub = self.child_state(work, child)
        fsm.states[state.name] = state
        if sub is not None:
            pending.append(sub)
        choice = f"{work.label}.next?"
        fsm.states[choice] = State(choice, action=None, location=where)
        for outcome in loop:
            add(state.name, outcome, choice)
        for outcome in ending:
            add(state.name, outcome, final_of(outcome))
        fsm.add_transition(choice, f"{work.label}.next", state.name, location=where)
        fsm.add_transition(choice, f"{work.label}.exhausted", exhausted, location=where)
        fsm.initial = state.name
        self.warn(
            work.source,
            container.line,
            f"Iterator '{work.label}': its items ({container.items_text or 'it'}) are "
            "known only at run time; read with their number as an environment choice "
            f"after each loop outcome (events '{work.label}.next' / "
            f"'{work.label}.exhausted'; an empty item list is not modelled)",
        )
        return pending


def product_fingerprint(fsm: FSM) -> str:
    """A digest of a concurrence's product machine (its states, initial state and
    transitions): a writer gives the concurrence back only while the product is the one read.
    O(S + T log T)."""
    data = [
        fsm.initial,
        sorted(fsm.states),
        sorted((t.source, t.event or "", t.target, t.exit or "") for t in fsm.transitions),
    ]
    return hashlib.sha256(json.dumps(data).encode()).hexdigest()[:16]


def _child_class(child: Child) -> str:
    """A concurrence child's class (a container's: ``StateMachine``, ``Region``, ...)."""
    return child.state.cls


def _product_name(name: str, action: str | None, at_start: bool, fsm: FSM) -> str:
    """A product state's name that no other state of ``fsm`` has (outcomes included).

    Two product states can print alike - the children back at their first states with another
    action running than at the start, or a name equal to a container outcome - so a taken name
    gets the action it runs, then ``#2``, ``#3`` ... (docs/formats/flexbe.md).
    """
    if name not in fsm.states:
        return name
    base = f"{name} ({action})" if at_start and action is not None else name
    candidate, index = base, 2
    while candidate in fsm.states:
        candidate, index = f"{base} #{index}", index + 1
    return candidate


def _shares_outcomes(outcomes: list[list[str]]) -> bool:
    seen: set[str] = set()
    for outs in outcomes:
        if seen & set(outs):
            return True
        seen |= set(outs)
    return False


def leaf_info(ref: StateRef, child: Child) -> dict[str, str]:
    """A leaf state's ``state_info`` entries: declared outcomes, parameters, userdata keys,
    remapping, ROS interface, editor position (docs/formats/smach.md)."""
    config = ref.config
    return state_info.encode(
        outcomes=ref.declared,
        params=config.params,
        expression_params=config.expressions,
        inputs=config.inputs,
        outputs=config.outputs,
        remap=child.remapping,
        at=child.position,
        ros=config.ros,
    )


def container_info(container: Container, child: Child | None) -> dict[str, str]:
    """A container's ``state_info`` entries: its userdata keys and initial values, and (as a
    child) its remapping and editor position."""
    return state_info.encode(
        inputs=container.inputs,
        outputs=container.outputs,
        userdata=container.userdata,
        remap=child.remapping if child is not None else None,
        at=child.position if child is not None else None,
    )


def is_strict(ctx: ReadContext) -> bool:
    """Reader option ``strict`` (``fsmbt convert --strict``, ``-O strict=1``): refuse what
    would otherwise be read as an opaque approximation with a warning."""
    return ctx.options.get("strict") not in (None, False, "", "0", "false", "no")


def python2_warning(notes: list[str]) -> str:
    """The one warning for a file read as Python 2 (docs/formats/flexbe.md)."""
    return "read as Python 2 source (nothing run): " + "; ".join(notes)


def build_fsm(
    text: str,
    ctx: ReadContext,
    choose_root: Callable[[Analysis, ReadContext], tuple[Container, str]],
) -> FSM:
    """Parse, analyse and build (the shared path of the SMACH and FlexBE readers).

    Args:
        text: the Python source (never executed).
        ctx: the read context (file, options, warnings).
        choose_root: picks the container that is the model, and its name.

    Returns:
        The hierarchical FSM.
    """
    text, tree, notes = parse_python(text, ctx.display_name)
    classes = ClassFiles()
    path = ctx.path.resolve() if ctx.path is not None else None
    analysis = analyze(text, tree, ctx.display_name, classes.resolver(path))
    main = _Source(path, ctx.display_name, analysis)
    builder = Builder(ctx, main, classes)
    if notes:
        builder.warn(main, None, python2_warning(notes))
    for line, message in analysis.warnings:
        builder.warn(main, line, message)
    root, name = choose_root(analysis, ctx)
    extension = analysis.extension
    if isinstance(extension.get("name"), str):
        name = str(extension["name"])
    fsm = builder.build(root, name)
    fsm.attrs.update(container_info(root, None))
    start = extension.get("start")
    if (
        isinstance(start, dict)
        and isinstance(start.get("name"), str)
        and isinstance(start.get("event"), str)
    ):
        fsm.start_name, fsm.initial_event = start["name"], start["event"]
    if "data" in extension:  # written by fsmbt: userdata and decision states (smach_data)
        from fsmbt.formats.pysm.smach_data import fold_data

        fold_data(fsm, extension["data"])
    return fsm


def build_records(root: Container, name: str, ctx: ReadContext, analysis: Analysis) -> FSM:
    """The FSM of container records another reader made (YASMIN XML and Python).

    Args:
        root: the top container (its children already filled in).
        name: the machine's name.
        ctx: the read context (file, warnings).
        analysis: what the reader found (its warnings are recorded, located in ``ctx``'s file).

    Returns:
        The hierarchical FSM, built by the same rules as SMACH's (module docstring).
    """
    main = _Source(ctx.path.resolve() if ctx.path is not None else None, ctx.display_name, analysis)
    builder = Builder(ctx, main)
    for line, message in analysis.warnings:
        builder.warn(main, line, message)
    return builder.build(root, name)


def build_concurrence(container: Container, name: str) -> FSM:
    """The product FSM the reader builds from one ``Concurrence`` container, alone (the SMACH
    writer checks that a region it writes reads back as itself).

    Raises:
        InputError: the container is refused, as reading it would be.
    """
    fsm = FSM(name=name)
    source = _Source(None, "<check>", Analysis([], {}, {}))
    Builder(ReadContext(), source).concurrence(_Work(container, fsm, name, source, ()))
    return fsm
