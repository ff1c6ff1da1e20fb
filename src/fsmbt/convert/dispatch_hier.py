"""FSM -> BT, the hierarchical dispatch form: one dispatch level per composite state
(docs/semantics.md, "12a. The hierarchical dispatch form"; runs as
``fsmbt.semantics.dispatch_runtime`` says, like the flat form).

Why: the flat dispatch form of a hierarchical machine is written for its flattening, where a
composite's k outgoing transitions are copied onto each of its n descendants (n·k cases). This
form keeps the machine's own shape: every composite state is one ``BehaviorTree`` (a
``SubTree`` with ``_autoremap="true"``) holding the dispatch over its children and, once, the
composite's own transitions, tried after the active child's (W3C: a descendant's transition
takes priority over its ancestor's).

Shape (each machine level - the top machine and each composite's sub-machine - keeps the index
of its active child, base 7, in its own digit entries: ``fsm_d0..`` for the top, as in the flat
form, ``fsm_d_<composite>_0..`` for a composite):

- the main tree is the flat form's index tree over the top machine's children, its default the
  start case;
- a child's case: an atomic final child ``AlwaysSuccess`` at the top (the machine is done),
  ``AlwaysFailure`` inside a composite (a final sub-state ignores events: its ancestors'
  transitions apply); an atomic child a ``Switch`` on ``{event}`` over its transitions whose
  default is "not handled here": RUNNING (``KeepRunningUntilFailure(AlwaysSuccess)``) at the
  top, ``AlwaysFailure`` inside a composite (a child without transitions: that
  ``AlwaysFailure`` alone, named, as a final child's, by its flat path - the load-time check,
  ``fsmbt.semantics.dispatch_check``, tells a state's case from an unnamed padding case so); a
  composite child the ``SubTree`` of its tree;
- a composite's tree: ``ReactiveFallback(index tree over its children, Switch on {event} over
  its own transitions)`` (the second child's default again "not handled here"); only the index
  tree when the composite is nested and has no transition of its own;
- a transition is the flat form's: ``KeepRunningUntilFailure(DispatchEntry(state, action,
  _onSuccess))`` (RUNNING), the bare ``DispatchEntry`` (SUCCESS) when it ends in a final state
  of the top machine. Its ``state`` port is the flattened configuration's name (``A/a1``,
  ``model.flatten``'s), its ``action`` the active atomic state's action, and its post-condition
  writes the digits of every level whose value changes.

**Canonical digits.** A level that is not active holds its initial child's index, so each
configuration of the machine is one valuation of the digits: the start writes every level's
digits; a transition resets every level inside the states it exits (inside the source when
the source is composite: its active children are not known statically, so every digit of
those levels is written) and writes the levels whose active child changes (the levels on the
source's path are known statically: only the digits that differ); no digit of a composite
never entered is written (it has no tree, so no ``Switch`` reads it). Completion transitions
(``done.state``: eventless transitions out of a composite, ``exit`` naming which final
sub-state) are resolved when the tree is built: a transition whose target configuration has a
final atomic state whose parent composite completes on it goes on to that completion's target
(repeated; the configuration in between is never observed, as in ``model.flatten``).

Not kept (``hierarchy_blocker``; ``fsmbt.convert.dispatch`` flattens instead, with a warning
naming the state and the cause): parallel states, eventless transitions out of atomic states,
final composite states, a composite without initial state, data models (their states are
valuations, docs/semantics.md §6a).

Cost: O(states + transitions · (nesting + levels written)) to build; the tree has one case
per state, one transition node per transition and one ``SubTree`` per composite state.
Per macro step: the index switches of each active level plus, per level where the event is
not handled, one ``ReactiveFallback`` and its ``{event}`` switch: O(nesting · log7 children +
out-degrees / 6). BehaviorTree.CPP instantiates each ``SubTree`` once, since each composite
state has one parent case (no instantiated copies).
"""

from __future__ import annotations

import re
from collections import deque
from dataclasses import dataclass, field

from fsmbt.convert.dispatch_parts import (
    check_event,
    control,
    digits_of,
    entry_model,
    event_switch,
    index_levels,
    index_tree,
    leaf,
    never,
    running,
    size,
)
from fsmbt.convert.result import ConversionResult
from fsmbt.model import fsm_data
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.errors import InputError
from fsmbt.model.flatten import MAX_COMPLETION_CHAIN, PATH_SEPARATOR
from fsmbt.model.fsm import FSM, State, Transition
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.dispatch_runtime import DIGIT_PREFIX, ENTRY, ON_SUCCESS, level_prefix

STYLE = "dispatch"
#: ``stats["form"]`` of this form (the flat form has none).
FORM = "hierarchical"
MAIN = "MainTree"
_UNSAFE = re.compile(r"[^A-Za-z0-9_]")


def hierarchy_blocker(fsm: FSM) -> str | None:
    """Why the hierarchical form cannot keep ``fsm``'s hierarchy (the state and the cause),
    or ``None`` when it can. Cost: O(states + transitions)."""
    if fsm_data.has_data(fsm):
        return "its data model makes each state a valuation (docs/semantics.md §6a)"
    if not fsm.is_hierarchical:
        return "it has eventless transitions (no composite state to keep)"
    for path, _machine, state in fsm.walk():
        if state.is_parallel:
            return f"state '{path}' is parallel (its regions are active at once)"
        if state.is_composite and state.final:
            return f"state '{path}' is a final composite state"
        if state.is_composite:
            region = state.regions[0]
            if region.initial is None or region.initial not in region.states:
                return f"composite state '{path}' has no initial state"
    for path, machine in _machine_paths(fsm):
        for t in machine.transitions:
            where = f"{path}{t.source}"
            if t.source not in machine.states or t.target not in machine.states:
                return f"state '{where}' has a transition to an unknown state '{t.target}'"
            if t.event is None and machine.states[t.source].is_atomic:
                return f"state '{where}' has an eventless transition (it fires on entry)"
    return None


def _machine_paths(fsm: FSM) -> list[tuple[str, FSM]]:
    """Every machine with the path prefix of its states (``""``, ``A/``, ``A/B/``)."""
    out = [("", fsm)]
    for path, _machine, state in fsm.walk():
        if state.is_composite:
            out.append((f"{path}{PATH_SEPARATOR}", state.regions[0]))
    return out


@dataclass
class _Level:
    """One machine level: the top machine or a composite state's sub-machine."""

    machine: FSM
    path: str  # the owner's flat path ("" for the top)
    parent: int | None
    owner: str | None  # the owner state's name in the parent level
    key: str  # digit-entry prefix
    tree_id: str
    table: dict[str, dict[str, Transition]] = field(default_factory=dict)
    completions: dict[str, list[Transition]] = field(default_factory=dict)
    sub: dict[str, int] = field(default_factory=dict)  # composite child -> its level
    children: list[str] = field(default_factory=list)  # indexed children
    index: dict[str, int] = field(default_factory=dict)
    digits: int = 1

    def flat(self, child: str) -> str:
        return f"{self.path}{PATH_SEPARATOR}{child}" if self.path else child


@dataclass
class _Move:
    """A transition resolved statically: the levels whose value it sets, what was known of
    them before, and the configuration it ends in."""

    value: dict[int, str]
    known: dict[int, str]
    unknown: set[int]
    path: list[tuple[int, str]]


class _Builder:
    def __init__(self, fsm: FSM) -> None:
        self.fsm = fsm
        self.levels: list[_Level] = []
        self.inside: dict[tuple[int, str], list[int]] = {}
        #: the (level, child) pairs ever active (``explore``; every one until it has run)
        self.observed: set[tuple[int, str]] | None = None
        used_keys: set[str] = set()
        used_ids = {MAIN}
        stack: list[tuple[FSM, str, int | None, str | None]] = [(fsm, "", None, None)]
        while stack:
            machine, path, parent, owner = stack.pop()
            n = len(self.levels)
            if parent is None:
                key, tree_id = DIGIT_PREFIX, MAIN
            else:
                key = level_prefix(_unique(_UNSAFE.sub("_", path), used_keys, "_"))
                tree_id = _unique(path, used_ids, "#")
                self.levels[parent].sub[owner or ""] = n
            level = _Level(machine, path, parent, owner, key, tree_id)
            for t in machine.transitions:
                if t.event is None:
                    level.completions.setdefault(t.source, []).append(t)
                else:
                    level.table.setdefault(t.source, {}).setdefault(t.event, t)
            self.levels.append(level)
            for state in reversed(list(machine.states.values())):
                if state.is_composite:
                    stack.append((state.regions[0], level.flat(state.name), n, state.name))
        for n in range(len(self.levels)):  # each level is inside its ancestors' owners
            up = n
            while self.levels[up].parent is not None:
                parent_level = self.levels[up].parent
                assert parent_level is not None
                owner = self.levels[up].owner or ""
                self.inside.setdefault((parent_level, owner), []).append(n)
                up = parent_level

    def state(self, level: int, name: str) -> State:
        return self.levels[level].machine.states[name]

    def initial(self, level: int) -> str:
        initial = self.levels[level].machine.initial
        assert initial is not None
        return initial

    def dead_events(self, observed: set[tuple[int, str]] | None) -> dict[tuple[int, str], set[str]]:
        """Per composite state, the events of its own transitions that never fire: every
        child of its sub-machine that is ever active (in ``observed``; ``None``: every child)
        handles them first (an atomic non-final child by a transition, a composite one by
        its own or, again, by every such child). Inner levels first (a sub-level's index is
        larger than its parent's). Cost: O(transitions)."""
        handled: list[set[str]] = [set() for _ in self.levels]
        dead: dict[tuple[int, str], set[str]] = {}
        for n in reversed(range(len(self.levels))):
            lv = self.levels[n]
            every: set[str] | None = None
            for name, st in lv.machine.states.items():
                if observed is not None and (n, name) not in observed:
                    continue
                mine: set[str] = set() if st.final else set(lv.table.get(name, {}))
                if name in lv.sub:
                    inner = handled[lv.sub[name]]
                    dead[(n, name)] = mine & inner
                    mine |= inner
                every = mine if every is None else every & mine
            handled[n] = every or set()
        return dead

    # -- resolving a transition --------------------------------------------------------------
    def resolve(self, level: int | None, source: str | None, target: str) -> _Move:
        """The move of the transition ``source -> target`` of ``level`` (``None``: the start),
        completion transitions followed (see the module docstring)."""
        known: dict[int, str] = {}
        unknown: set[int] = set()
        value: dict[int, str] = {}
        if level is None or source is None:
            unknown = set(range(len(self.levels)))
            value = {n: self.initial(n) for n in range(len(self.levels))}
            level = 0
        else:
            up: int | None = level
            child = source
            while up is not None:
                known[up] = child
                child, up = self.levels[up].owner or "", self.levels[up].parent
            unknown.update(self.inside.get((level, source), ()))
            self._exit(level, source, value)
        value[level] = target

        def now(n: int) -> str:
            return value[n] if n in value else known.get(n, self.initial(n))

        for _ in range(MAX_COMPLETION_CHAIN):
            path = [(0, now(0))]
            while path[-1][1] in self.levels[path[-1][0]].sub:
                sub = self.levels[path[-1][0]].sub[path[-1][1]]
                path.append((sub, now(sub)))
            at, name = path[-1]
            parent = self.levels[at].parent
            done = self.state(at, name).final and parent is not None
            completion = self._completion(at, name) if done else None
            if completion is None:
                return _Move(value, known, unknown, path)
            assert parent is not None
            self._exit(parent, completion.source, value)
            value[parent] = completion.target
        raise InputError("completion transitions form a cycle", element=self.fsm.name)

    def _completion(self, level: int, final: str) -> Transition | None:
        """The completion of ``level``'s owner when its sub-machine is in ``final``."""
        lv = self.levels[level]
        parent = lv.parent
        assert parent is not None
        for t in self.levels[parent].completions.get(lv.owner or "", ()):
            if t.exit is None or t.exit == final:
                return t
        return None

    def entered(self, level: int, name: str) -> bool:
        """Whether child ``name`` of ``level`` is ever active."""
        return self.observed is None or (level, name) in self.observed

    def _exit(self, level: int, name: str, value: dict[int, str]) -> None:
        """Leaving ``name`` of ``level``: every level inside it back to its initial child."""
        for n in self.inside.get((level, name), ()):
            value[n] = self.initial(n)

    def writes(self, move: _Move) -> str:
        """The ``_onSuccess`` assignments of ``move`` (only digits that change; none of a
        level never entered: it has no tree, so no ``Switch`` reads its digits)."""
        code: list[str] = []
        for n in sorted(move.value):
            lv = self.levels[n]
            if lv.parent is not None and not self.entered(lv.parent, lv.owner or ""):
                continue
            want = digits_of(lv.index[move.value[n]], lv.digits)
            if n in move.unknown:
                have = [""] * lv.digits
            else:
                before = move.known.get(n, self.initial(n))
                have = digits_of(lv.index[before], lv.digits)
            code.extend(f"{lv.key}{j}:='{want[j]}'" for j in range(lv.digits) if want[j] != have[j])
        return "; ".join(code)

    def explore(
        self, start: _Move, dead: dict[tuple[int, str], set[str]]
    ) -> tuple[set[tuple[int, str]], dict[tuple[int, str], list[tuple[str, _Move]]], int]:
        """(the (level, child) pairs ever active, the moves of their live transitions,
        how many), breadth first from the start."""
        observed: set[tuple[int, str]] = set()
        moves: dict[tuple[int, str], list[tuple[str, _Move]]] = {}
        queue: deque[tuple[int, str]] = deque()

        def mark(path: list[tuple[int, str]]) -> None:
            for item in path:
                if item not in observed:
                    observed.add(item)
                    queue.append(item)

        mark(start.path)
        transitions = 0
        while queue:
            at, name = queue.popleft()
            if self.state(at, name).final:
                continue
            out = []
            shadowed = dead.get((at, name), set())
            for event, t in self.levels[at].table.get(name, {}).items():
                if event in shadowed:
                    continue  # every active child handles it first
                check_event(event, self.levels[at].flat(name))
                move = self.resolve(at, name, t.target)
                mark(move.path)
                out.append((event, move))
            moves[(at, name)] = out
            transitions += len(out)
        return observed, moves, transitions

    # -- building -----------------------------------------------------------------------------
    def build(self) -> ConversionResult:
        top = self.levels[0].machine
        if top.initial is None or top.initial not in top.states:
            raise InputError("the state machine has no initial state", element=self.fsm.name)
        start = self.resolve(None, None, top.initial)
        # what is ever active, and the transitions that fire: a transition of a composite
        # that every active child handles first never fires, and leaving it out can make
        # fewer children active: repeated until nothing changes (each round only removes)
        dead = self.dead_events(None)
        while True:
            observed, moves, transitions = self.explore(start, dead)
            again = self.dead_events(observed)
            if again == dead:
                break
            dead = again
        self.observed = observed
        for n, lv in enumerate(self.levels):
            initial = self.initial(n)
            lv.children = [c for c in lv.machine.states if (n, c) in observed or c == initial]
            lv.index = {c: i for i, c in enumerate(lv.children)}
            lv.digits = index_levels(len(lv.children))

        def transition(move: _Move, label: str) -> BTNode:
            at, name = move.path[-1]
            target = PATH_SEPARATOR.join(child for _n, child in move.path)
            attrs = {"state": target, "action": self.state(at, name).action or ""}
            code = self.writes(move)
            if code:
                attrs[ON_SUCCESS] = code
            node = leaf(ENTRY, target, **attrs)
            if len(move.path) == 1 and self.state(at, name).final:
                return node  # the machine is done: SUCCESS
            return BTNode(
                type="KeepRunningUntilFailure",
                kind=NodeKind.DECORATOR,
                name=label,
                children=[node],
            )

        def own(at: int, name: str) -> BTNode:
            """``name``'s own transitions; not handled: RUNNING at the top, else FAILURE."""
            flat = self.levels[at].flat(name)
            cases = [
                (event, transition(move, f"{flat}/{event}"))
                for event, move in moves.get((at, name), [])
            ]
            if not cases and at != 0:
                # named by the state: the load-time check tells it from a padding case
                return leaf("AlwaysFailure", flat)
            return event_switch(flat, cases, running if at == 0 else never)

        trees: dict[str, BTNode] = {}
        subtrees = 0
        for n in reversed(range(len(self.levels))):  # inner levels first
            lv = self.levels[n]
            cases: list[BTNode] = []
            for name in lv.children:
                st = self.state(n, name)
                flat = lv.flat(name)
                if (n, name) not in observed:
                    cases.append(never())
                elif st.is_composite:
                    sub = self.levels[lv.sub[name]]
                    subtrees += 1
                    cases.append(
                        BTNode(
                            type="SubTree",
                            kind=NodeKind.SUBTREE,
                            name=flat,
                            attrs={"ID": sub.tree_id, "_autoremap": "true"},
                        )
                    )
                elif st.final:
                    cases.append(leaf("AlwaysSuccess" if n == 0 else "AlwaysFailure", flat))
                else:
                    cases.append(own(n, name))
            if n == 0:
                if top.initial_event is not None:
                    check_event(top.initial_event, top.start_name or "start")
                    first = transition(start, "start")
                    begin = event_switch("start", [(top.initial_event, first)], running)
                else:
                    begin = transition(start, "start")
                trees[lv.tree_id] = index_tree(
                    cases, lv.key, lv.digits, begin, ("dispatch", "digit")
                )
                continue
            parent = lv.parent
            assert parent is not None and lv.owner is not None
            if (parent, lv.owner) not in observed:
                continue  # never entered: no tree
            body = index_tree(cases, lv.key, lv.digits, never(), (lv.path, f"{lv.path}_digit"))
            handled = moves.get((parent, lv.owner), [])
            if handled or parent == 0:
                body = control(
                    "ReactiveFallback",
                    f"{lv.path}_then_own",
                    [body, own(parent, lv.owner)],
                )
            trees[lv.tree_id] = body
        doc = BTDocument(main_tree=MAIN)
        doc.trees[MAIN] = BehaviorTree(MAIN, trees[MAIN])
        nodes, depth = 0, 0
        for lv in self.levels:
            if lv.tree_id != MAIN and lv.tree_id in trees:
                doc.trees[lv.tree_id] = BehaviorTree(lv.tree_id, trees[lv.tree_id])
        for root in trees.values():
            count, d = size(root)
            nodes += count
            depth = max(depth, d)
        doc.node_models[ENTRY] = entry_model()
        stats: dict[str, object] = {
            "states": sum(1 for _ in self.fsm.walk()),
            "transitions": transitions,
            "nodes": nodes,
            "depth": depth,
            "style": STYLE,
            "form": FORM,
            "subtrees": subtrees,
            "levels": 1 + max(_nesting(self.levels, n) for n in range(len(self.levels))),
        }
        return ConversionResult(doc, "rules", "fsm->bt", stats, [])


def _nesting(levels: list[_Level], n: int) -> int:
    depth = 0
    up = levels[n].parent
    while up is not None:
        depth += 1
        up = levels[up].parent
    return depth


def _unique(base: str, used: set[str], sep: str) -> str:
    """``base``, else ``base<sep>2``, ``base<sep>3`` ... whichever ``used`` lacks (added)."""
    name, k = base, 2
    while name in used:
        name = f"{base}{sep}{k}"
        k += 1
    used.add(name)
    return name


def fsm_to_hier_dispatch(fsm: FSM) -> ConversionResult:
    """The hierarchical dispatch form of ``fsm`` (see the module docstring); call
    ``hierarchy_blocker`` first.

    Raises:
        InputError: no initial state; a cycle of completion transitions.
        UnsupportedError: an event a ``Switch`` cannot compare (the state named).
    """
    return _Builder(fsm).build()
