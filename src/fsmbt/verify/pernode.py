"""The per-node check of a region: each node of a BT region against its fragment of the
region's state machine, children abstracted by their interfaces (docs/semantics.md §4d;
docs/verification.md §5, "Compositional check (per node)"; issue 27 item 2).

Why: a region written one sub-machine per node (``convert/bt_pernode``) has a flat meaning
that is the product of its nodes' memories, so checking the region whole costs that product.
Here each node is checked alone, on a few dozen states, and equal local problems are checked
once (memoized by a canonical form), so the proof grows with the number of *distinct* node
shapes, not with the product.

What is checked is the *result*: the machine's states are grouped by their ``fsmbt:node`` tag
(the node's path in the region, ``CompiledNode.path``), but a tag is only a hint - every side
condition that makes the grouping a valid decomposition is checked here, and when one fails
the check refuses (``NotPerNode``), so the caller checks the region whole as before:

1. *states*: every state but the finals ``SUCCESS``/``FAILURE`` is atomic and tagged with a
   node of the region; a leaf's one state has the leaf's label as action and exactly one
   transition on each outcome the leaf may return (``running`` for an action only), without
   guard; every other state has no action and only eventless transitions, the last unguarded;
2. *entries*: every transition entering ``sub(x)`` (the states tagged with ``x`` or a
   descendant) from outside enters one state, ``E(x)``;
3. *data*: each variable a guard reads is read by the guards of one node only, its *owner*;
   an assignment to an owned variable is a literal or ``v + 1``; from outside the owner's
   subtree a variable is only ever set to one literal, its *halt value*; a transition of a
   node's fragment that sets variables of a child's subtree sets exactly that subtree's halt
   values (a halt of that child); variables owned outside a node's subtree are assigned by its
   fragment only on the way out of it (an exit), never on a path that ticks one of its children.
   Variables no guard reads cannot change a decision: ignored.

Conditions 2 and 3 are asked of *live* transitions only: a transition leaving a state of a node
the tree never ticks (``tickable.never_ticked``) never fires, since the live checks prove that
the machine never enters such a state (docs/semantics.md §4d, "Transitions out of dead states").

The local problem of a node ``N`` with children ``c1..cn`` (docs/semantics.md §4d):

- *tree side*: ``N`` itself (type and ports) over abstract leaves ``⟪i⟫`` (an action when child
  i may return RUNNING, else a condition), run by fsmbt's interpreter one tick at a time
  (``exactly_once``: a RUNNING with a wake-up is returned to the parent, as N's parent sees it),
  with two inputs between ticks: ``tick`` and ``halt`` (the interpreter's ``haltChild``:
  ``halt()`` when RUNNING, the status reset otherwise), and the abstract children's outcomes
  restricted to what each child may return; outputs: the child ticked, the halts of RUNNING
  abstract children, N's result;
- *machine side*: N's fragment (its transient states and the halt values of its variables),
  each child's exits replaced by its interface ``σ_i``: status -> (target, assignments outside
  the child's subtree), found by the child's own local check; outputs: the child whose entry
  is reached, the halts of children whose subtree has halt values and that returned RUNNING
  last, and N's exit (target, assignments outside N's subtree);
- the two are explored in lockstep (a product of at most ``LOCAL_LIMIT`` pairs); N's statuses
  and its exits are paired as they first meet (``σ_N``); a second, different partner fails.

The region's root must pair SUCCESS with the final ``SUCCESS``, FAILURE with ``FAILURE`` and
RUNNING with its own entry (the next tick), each without assignment. Then (the congruence of
§4d) the region's machine is equivalent to the region's leaf-execution machine.

Cost: O(states + transitions · depth) to group and canonicalize, plus one local product per
distinct canonical problem (a few hundred pairs each).

For a certificate (``fsmbt.verify.certificate``, docs/verification.md §6) the proof and the
checker share two public pieces: ``NodeWalk`` (which local checks exist, children first, and
the interfaces they settle) and ``local_machines`` (one local problem as two
``semantics.machine.Machine`` objects for the native checker, σ fixed). With ``keep``,
``check_region`` keeps, per distinct local problem that held, the tables of those two machines
and the relation, numbered from the lockstep product's own steps (``_witness_of``,
``verify/table_witness.py``: no second search; the same tables the native checker would list).
"""

from __future__ import annotations

import itertools
import re
from collections import deque
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from fsmbt.convert.compress import inline_and_compress
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM, Transition
from fsmbt.model.fsm_data import ASSIGN, COND, parse_lines
from fsmbt.semantics.bt_interpreter import (
    BTInterpreter,
    CompiledNode,
    CompiledTree,
    LeafRequest,
)
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, Work
from fsmbt.verify.abstract_node import abstract_tree
from fsmbt.verify.subset_expr import ForeignName, OutsideSubset, compile_subset
from fsmbt.verify.table_witness import Rows, Side, witness_from_rows
from fsmbt.verify.tickable import never_ticked

#: The tag the per-node conversion writes (``convert.bt_pernode.NODE_ATTR``; the SCXML
#: writer's fsmbt namespace in Clark notation).
NODE_ATTR = "{https://fsmbt.dev/ns/scxml}node"
END_SUCCESS, END_FAILURE = "SUCCESS", "FAILURE"
EVENTS = {SUCCESS: "success", FAILURE: "failure", RUNNING: "running"}
#: Most pairs one local product may hold before the check refuses.
LOCAL_LIMIT = 20_000
#: Most failing nodes one region's check collects for the lift.
MAX_FAILURES = 8
#: Most eventless steps one resolution may take before the check refuses (a cycle).
STEP_LIMIT = 10_000
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_NUMBER = re.compile(r"-?\d+")


class NotPerNode(Exception):
    """The region's machine is not a valid per-node decomposition (the reason is the message):
    the caller checks the region whole."""


@dataclass
class PerNodeOutcome:
    """A region proven per node (or one local check that failed).

    Attributes:
        equivalent: every local check held and the root's interface is the finals'.
        results: the results the region may return (``SUCCESS``/``FAILURE``).
        nodes: nodes checked; ``distinct``: local problems actually explored (the rest
            memoized); ``local_states``: their product states summed; ``unticked``: nodes the
            machine enters but the tree never ticks, skipped (docs/semantics.md §4d).
        failed: the node whose local check failed (its path and type), else ``None``.
    """

    equivalent: bool
    results: frozenset[str] = frozenset()
    nodes: int = 0
    distinct: int = 0
    local_states: int = 0
    #: live nodes of the machine the tree never ticks (``tickable.never_ticked``): not checked
    unticked: int = 0
    #: live transitions no local check follows, left out of the entry condition
    #: (``_past_unfired``; 0: the rule was not needed)
    unfired: int = 0
    failed: str | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    #: the failing node's id in ``tree`` (the region after the same-type merge), and the local
    #: counterexample: the inputs from the fresh node, each ``(position, symbol)`` with
    #: position ``None`` between ticks (symbol ``"tick"``/``"halt"``) or the child ticked
    #: (symbol its status); ``verify/lift.py`` lifts it to the whole tree
    failed_id: int | None = None
    trace: list[tuple[int | None, Any]] = field(default_factory=list)
    tree: CompiledTree | None = None
    #: the next nodes whose local check fails, as (description, id, local counterexample),
    #: found only when asked (the walk resumed past the first failure, ``_failures``; at most
    #: ``MAX_FAILURES`` in all): a mutant can break several local checks (a wrong exit fails
    #: the parent's), and the first found is not always one the whole tree reaches
    more: Iterator[tuple[str, int, list[tuple[int | None, Any]]]] = field(
        default_factory=lambda: iter(())
    )
    #: the failures met so far: the first, then each ``more`` gave
    seen: list[tuple[str, int, list[tuple[int | None, Any]]]] = field(default_factory=list)
    #: the entry side condition the region broke when the check ran with ``tolerate`` and
    #: failed (a stray jump into a subtree): the failure is then only a candidate, which
    #: the caller must confirm by the lift's replay or check the region whole
    tolerated: str | None = None


# -- expressions (fsmbt's subset: literals, names, ==, !=, <, <=, >, >=, and, or, x + 1) -------


_COMPILED: dict[tuple[str, tuple[tuple[str, str], ...]], Any] = {}


def _compile(text: str, names: dict[str, str]) -> tuple[str, Callable[[dict[str, Any]], Any]]:
    """An expression with its variables renamed (``names``; the canonical text) and a function
    evaluating it over an environment (cached by text and renaming). Refuses anything outside
    the subset."""
    used = tuple(sorted((w, names[w]) for w in set(_IDENT.findall(text)) if w in names))
    key = (text, used)
    found = _COMPILED.get(key)
    if found is None:
        found = _COMPILED[key] = _compile_new(text, names)
    return found


def _compile_new(text: str, names: dict[str, str]) -> tuple[str, Callable[[dict[str, Any]], Any]]:
    try:
        return compile_subset(text, rename=names)
    except OutsideSubset:
        raise NotPerNode(f"expression {text!r} is not in fsmbt's subset") from None
    except ForeignName as exc:
        raise NotPerNode(f"expression {text!r} reads {exc.name}, not the node's own") from None


def _literal(text: str) -> Any:
    """A literal's value (an int or a quoted string), else ``None``."""
    text = text.strip()
    if _NUMBER.fullmatch(text):
        return int(text)
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        return text[1:-1]
    return None


# -- the grouping ------------------------------------------------------------------------------
@dataclass
class _Hop:
    """One transition as a node's fragment reads it: its guard, the updates of the node's own
    variables, the halts of its children (by index), the assignments outside its subtree (in
    order) and its target."""

    cond: Callable[[dict[str, Any]], Any] | None
    cond_text: str
    updates: tuple[tuple[str, str], ...]
    update_fns: tuple[tuple[str, Callable[[dict[str, Any]], Any]], ...]
    halts: frozenset[int]
    outside: tuple[int, ...]  # canonical id of the hop's assignments outside the subtree
    target: tuple[str, Any]


class _Region:
    """The region's machine grouped by node (side conditions 1-3 of the module docstring).

    With ``tolerate``, a broken entry condition (2) is recorded in ``broken`` instead of
    refused: each node's entry is the state most transitions from outside enter (the first met
    on a tie), and a transition entering a subtree elsewhere is a *stray* jump that each
    fragment reading it outputs as an exit no status pairs with (``_Local.strays``), so the
    local check that reaches it fails; only a candidate (``check_region``).

    ``unticked``: the nodes the tree never ticks (``tickable.never_ticked``). A transition
    whose source is a state of one is *dead*: conditions 2 and 3 are not asked of it (the live
    checks prove that the machine never enters such a state, docs/semantics.md §4d, "Dead
    nodes", so a dead transition never fires; a one-transition change there, even a jump into
    the middle of another subtree, is no difference).

    ``unfired``: transitions (``id``) that no local check of an earlier walk followed
    (``check_region``'s second walk, docs/semantics.md §4d, "Transitions no local check
    fires"): condition 2 is not asked of them, and a stray jump of one is not recorded as
    broken (the walk checks again that none of them is followed)."""

    def __init__(
        self,
        tree: CompiledTree,
        machine: FSM,
        declared: dict[str, str],
        tolerate: bool = False,
        unticked: frozenset[int] = frozenset(),
        unfired: frozenset[int] = frozenset(),
    ) -> None:
        self.tree = tree
        self.tolerate = tolerate
        self.unticked = unticked
        self.unfired = unfired
        self.broken: list[str] = []
        self.nodes = tree.nodes
        self.machine = machine
        by_path = {node.path: node.id for node in self.nodes}
        self.tag: dict[str, int] = {}
        for name, state in machine.states.items():
            if state.final and name in (END_SUCCESS, END_FAILURE) and not state.regions:
                continue
            path = state.attrs.get(NODE_ATTR)
            if path is None or path not in by_path or state.regions or state.final:
                raise NotPerNode(f"state {name} is not an atomic state tagged with a node")
            self.tag[name] = by_path[path]
        # ancestors: pre-order ids, so x in sub(y) iff y <= x < end[y]
        self.end = [0] * len(self.nodes)
        for node in reversed(self.nodes):
            self.end[node.id] = max([node.id + 1, *(self.end[c] for c in node.children)])
        self.out: dict[str, list[Any]] = {name: [] for name in machine.states}
        for t in machine.transitions:
            if t.source not in self.out or t.target not in machine.states:
                raise NotPerNode(f"transition {t.source} -> {t.target} leaves the region")
            self.out[t.source].append(t)
        self._leaf_states()
        self._variables(declared)
        self._entries()

    def dead(self, t: Transition) -> bool:
        """Whether ``t`` leaves a state of a node the tree never ticks (the class docstring)."""
        return self.tag.get(t.source) in self.unticked

    def inside(self, state: str, nid: int) -> bool:
        x = self.tag.get(state)
        return x is not None and nid <= x < self.end[nid]

    def _leaf_states(self) -> None:
        self.leaf_state: dict[int, str] = {}
        for name, nid in self.tag.items():
            node = self.nodes[nid]
            state = self.machine.states[name]
            if node.is_env_leaf and not node.children:
                if nid in self.leaf_state or state.action != node.label:
                    raise NotPerNode(f"leaf {node.label} has no one state with its label")
                self.leaf_state[nid] = name
                events = [t.event for t in self.out[name]]
                wanted = ["success", "failure"] + (
                    ["running"] if node.kind is NodeKind.ACTION else []
                )
                if sorted(events) != sorted(wanted) or any(COND in t.attrs for t in self.out[name]):
                    raise NotPerNode(f"leaf {node.label}'s state has other transitions")
            else:
                if state.action not in (None, ""):
                    raise NotPerNode(f"state {name} of a control node has an action")
                arms = self.out[name]
                if not arms or any(t.event is not None for t in arms) or COND in arms[-1].attrs:
                    raise NotPerNode(f"state {name} is not a transient state")
        for node in self.nodes:
            if node.is_env_leaf and node.id not in self.leaf_state:
                raise NotPerNode(f"leaf {node.label} has no state")

    def _variables(self, declared: dict[str, str]) -> None:
        self.owner: dict[str, int] = {}
        for name, transitions in self.out.items():
            for t in transitions:
                if self.dead(t):
                    continue
                for word in _IDENT.findall(t.attrs.get(COND, "")):
                    if word in ("and", "or", "not", "True", "False"):
                        continue
                    if self.owner.setdefault(word, self.tag[name]) != self.tag[name]:
                        raise NotPerNode(f"variable {word} is read by two nodes")
        self.own: dict[int, set[str]] = {}
        for var, x in self.owner.items():
            self.own.setdefault(x, set()).add(var)
        self._halts: list[dict[str, Any]] = []
        self._below: list[list[str]] = []
        self.initial: dict[str, Any] = {}
        for var in self.owner:
            value = _literal(declared.get(var, ""))
            if value is None:
                raise NotPerNode(f"variable {var} has no literal initial value")
            self.initial[var] = value
        self.halt_value: dict[str, Any] = {}
        self.assigns: dict[int, list[tuple[str, str]]] = {}
        for transitions in self.out.values():
            for t in transitions:
                pairs = parse_lines(t.attrs.get(ASSIGN, ""))
                live = [(v, e) for v, e in pairs if v in self.owner]
                if len({v for v, _e in live}) != len(live):
                    raise NotPerNode(f"a transition of {t.source} assigns a variable twice")
                self.assigns[id(t)] = live
                if self.dead(t):
                    continue
                for var, expr in live:
                    value = _literal(expr)
                    if value is None and expr.replace(" ", "") != f"{var}+1":
                        raise NotPerNode(f"assignment {var}={expr} is not a literal or +1")
                    if not self.inside(t.source, self.owner[var]):
                        if value is None or self.halt_value.setdefault(var, value) != value:
                            raise NotPerNode(f"variable {var} is reset to two values")

    def _entries(self) -> None:
        self.entry: dict[int, str] = {}
        initial = self.machine.initial
        if initial is None or initial not in self.tag:
            raise NotPerNode("the region's initial state is not a node's")
        self.entry[0] = initial
        met: dict[int, dict[str, int]] = {}  # node -> state entered from outside -> times
        for transitions in self.out.values():
            for t in transitions:
                if t.target not in self.tag or self.dead(t) or id(t) in self.unfired:
                    continue
                x: int | None = self.tag[t.target]
                while x is not None:  # every node whose subtree the transition enters
                    if self.inside(t.source, x):
                        break
                    counts = met.setdefault(x, {})
                    counts[t.target] = counts.get(t.target, 0) + 1
                    x = self.nodes[x].parent
        for x, counts in met.items():
            entry = self.entry.get(x)  # only the region root's is fixed: the initial state
            if entry is None:  # the most entered (``max`` keeps the first met on a tie)
                entry = self.entry[x] = max(counts, key=counts.__getitem__)
            if set(counts) != {entry}:
                message = f"node {self.nodes[x].label} is entered twice"
                if not self.tolerate:
                    raise NotPerNode(message)
                self.broken.append(message)
        # a node no transition enters is dead (its siblings before it never let the tick
        # through): nothing of it is checked, and its parent's check fails if the tree ticks it

    def halt_vars(self, nid: int) -> dict[str, Any]:
        """The halt values of the variables owned in ``nid``'s subtree (bottom-up once)."""
        if not self._halts:
            own: dict[int, dict[str, Any]] = {}
            for v, h in self.halt_value.items():
                own.setdefault(self.owner[v], {})[v] = h
            self._halts = [{} for _ in self.nodes]
            for node in reversed(self.nodes):
                found = dict(own.get(node.id, {}))
                for c in node.children:
                    found.update(self._halts[c])
                self._halts[node.id] = found
        return self._halts[nid]

    def owned_below(self, nid: int) -> list[str]:
        """The variables owned in ``nid``'s subtree (bottom-up once)."""
        if not self._below:
            self._below = [[] for _ in self.nodes]
            for node in reversed(self.nodes):
                found = sorted(self.own.get(node.id, ()))
                for c in node.children:
                    found.extend(self._below[c])
                self._below[node.id] = found
        return self._below[nid]


# -- one node's local problem ------------------------------------------------------------------
Interface = dict[int, tuple[str, tuple[tuple[str, str], ...]]]


@dataclass
class _Local:
    """A node's fragment over abstract children, canonically named (``key`` is the memo key;
    exits are canonical ids, ``exits`` maps them back to the machine's names)."""

    key: tuple[Any, ...]
    entry: _Hop
    states: list[list[_Hop]]
    children: list[dict[int, _Hop]]
    halt: tuple[tuple[str, Any], ...]
    initial: tuple[tuple[str, Any], ...]
    halting: frozenset[int]  # children whose subtree has halt values
    exits: dict[int, Any]  # canonical id -> ("t", target) or ("a", (var, expr))
    #: exits that are stray jumps into the node's subtree (``_Region``'s ``tolerate``): no
    #: status pairs with one, so a local check reaching one fails
    strays: frozenset[int] = frozenset()
    #: the machine's name of each state of ``states`` (not in the key: equal problems of two
    #: nodes differ only in names), to map a followed arm back to its transition
    state_names: tuple[str, ...] = ()


def _local(region: _Region, node: CompiledNode, interfaces: dict[int, Interface]) -> _Local:
    """``node``'s fragment (see the module docstring), canonically named: its states in
    discovery order, its variables ``v0, v1 ...`` in order of first use, the targets and
    assignments outside its subtree numbered in order of first use."""
    own = region.own.get(node.id, set())
    names: dict[str, str] = {}
    outside_ids: dict[Any, int] = {}
    state_ids: dict[str, int] = {}
    order: list[str] = []
    kids = node.children
    child_of_entry = {region.entry[c]: i for i, c in enumerate(kids) if c in region.entry}
    halts_of = [region.halt_vars(c) for c in kids]
    owner_child: dict[str, int] = {}
    for i, c in enumerate(kids):
        for var in region.owned_below(c):
            owner_child[var] = i
    root_entry = region.entry[0] if node.id == 0 else None

    def outside_id(value: Any) -> int:
        return outside_ids.setdefault(value, len(outside_ids))

    def target_of(name: str, entering: bool = False, unfired: bool = False) -> tuple[str, int]:
        if name == root_entry and not entering:
            return ("exit", outside_id(("t", name)))  # the root's RUNNING: the next tick
        if name in child_of_entry:
            return ("child", child_of_entry[name])
        if region.tag.get(name) == node.id:
            if name not in state_ids:
                state_ids[name] = len(order)
                order.append(name)
            return ("state", state_ids[name])
        if region.inside(name, node.id):
            if unfired:  # proven not followed by the walk itself (``_Region.unfired``)
                return ("exit", outside_id(("stray", name)))
            message = f"a transition of {node.label} enters a child not at its entry"
            if not region.tolerate:
                raise NotPerNode(message)
            region.broken.append(message)
            return ("exit", outside_id(("stray", name)))
        return ("exit", outside_id(("t", name)))

    def hop(
        cond_text: str,
        pairs: list[tuple[str, str]],
        target: str,
        entering: bool = False,
        unfired: bool = False,
    ) -> _Hop:
        for word in _IDENT.findall(cond_text):
            if word in own:
                names.setdefault(word, f"v{len(names)}")
        for var, _expr in pairs:
            if var in own:
                names.setdefault(var, f"v{len(names)}")
        cond_fn, canonical = None, ""
        if cond_text:
            canonical, cond_fn = _compile(cond_text, names)
        updates: list[tuple[str, str]] = []
        fns: list[tuple[str, Callable[[dict[str, Any]], Any]]] = []
        outside: list[tuple[str, str]] = []
        halted: dict[int, dict[str, Any]] = {}
        for var, expr in pairs:
            if var in own:
                text, fn = _compile(expr, {var: names[var]})
                updates.append((names[var], text))
                fns.append((names[var], fn))
            elif var in owner_child:
                halted.setdefault(owner_child[var], {})[var] = _literal(expr)
            elif node.id <= region.owner[var] < region.end[node.id]:
                raise NotPerNode(f"{node.label} assigns {var} of a descendant")
            else:
                outside.append((var, expr))
        for i, values in halted.items():
            if values != halts_of[i]:
                raise NotPerNode(f"{node.label} halts child {i} partly")
        return _Hop(
            cond_fn,
            canonical,
            tuple(updates),
            tuple(fns),
            frozenset(halted),
            (outside_id(("a", tuple(outside))),) if outside else (),
            target_of(target, entering, unfired),
        )

    def shape(h: _Hop) -> tuple[Any, ...]:
        return (h.cond_text, h.updates, tuple(sorted(h.halts)), h.outside, h.target)

    entry = hop("", [], region.entry[node.id], entering=True)
    children: list[dict[int, _Hop]] = []
    for c in kids:
        children.append(
            {
                status: hop("", list(interfaces[c][status][1]), interfaces[c][status][0])
                for status in sorted(interfaces[c])
            }
        )
    states: list[list[_Hop]] = []
    while len(states) < len(order):
        name = order[len(states)]
        states.append(
            [
                hop(
                    t.attrs.get(COND, ""),
                    region.assigns[id(t)],
                    t.target,
                    unfired=id(t) in region.unfired,
                )
                for t in region.out[name]
            ]
        )
    for var in sorted(own):  # read by a guard, so named above; kept total for safety
        names.setdefault(var, f"v{len(names)}")
    halt = tuple(sorted((names[v], region.halt_value[v]) for v in own if v in region.halt_value))
    initial = tuple(sorted((names[v], region.initial[v]) for v in own))
    halting = frozenset(i for i, values in enumerate(halts_of) if values)
    strays = frozenset(cid for value, cid in outside_ids.items() if value[0] == "stray")
    key = (
        node.type,
        node.params,
        len(kids),
        shape(entry),
        tuple(tuple((s, shape(h)) for s, h in arms.items()) for arms in children),
        tuple(tuple(shape(h) for h in arms) for arms in states),
        halt,
        initial,
        tuple(sorted(halting)),
        tuple(sorted(strays)),
    )
    exits = {cid: value for value, cid in outside_ids.items()}
    return _Local(key, entry, states, children, halt, initial, halting, exits, strays, tuple(order))


# -- the local product ---------------------------------------------------------------------------
class _FsmSide:
    """The fragment as a machine: configuration = (position, own values, children that
    returned RUNNING last); position ``None`` between ticks, ``i`` at child i. With ``fired``,
    each arm followed is added to it as ``("state", state index, arm index)`` (what
    ``check_region``'s second walk maps back to transitions)."""

    def __init__(self, local: _Local, fired: set[tuple[Any, ...]] | None = None) -> None:
        self.local = local
        self.fired = fired

    def resolve(self, hop: _Hop, values: dict[str, Any], running: set[int]) -> tuple[Any, Any]:
        """Follow ``hop`` and the eventless hops after it (updating ``values`` and
        ``running``): (new position, outputs = (halts, ("tick", i) or ("exit", exit)))."""
        outside: list[int] = []
        halted: set[int] = set()
        touched: set[int] = set()  # every child halted, running or not
        for _step in range(STEP_LIMIT):
            env = dict(values)
            for var, fn in hop.update_fns:
                values[var] = fn(env)
            touched |= hop.halts
            for i in hop.halts:
                if i in running and i in self.local.halting:
                    halted.add(i)
                running.discard(i)
            outside.extend(hop.outside)
            kind, where = hop.target
            if kind == "child":
                if outside:  # an ancestor's variable written where the tick does not return
                    raise NotPerNode("a variable outside the node is assigned inside its tick")
                return where, (frozenset(halted), ("tick", where), frozenset(touched))
            if kind == "exit":
                exit_ = ("exit", (where, tuple(outside)))
                return None, (frozenset(halted), exit_, frozenset(touched))
            env = dict(values)
            for index, arm in enumerate(self.local.states[where]):
                if arm.cond is None or arm.cond(env):
                    hop = arm
                    if self.fired is not None:
                        self.fired.add(("state", where, index))
                    break
            else:  # the last arm is unguarded (checked when grouping)
                raise NotPerNode("a transient state has no enabled transition")
        raise NotPerNode("an eventless cycle without a leaf")


class _BtSide:
    """The interpreter on the node over abstract leaves, one tick at a time, halts visible."""

    def __init__(self, doc: BTDocument) -> None:
        self.interp = BTInterpreter(doc, exactly_once=True)
        self.leaf_index = {
            n.id: int(n.label[1:-1]) for n in self.interp.tree.nodes if n.is_env_leaf
        }

    def run(self, snap: Any, outcome: int | None) -> tuple[Any, Any]:
        halted: set[int] = set()

        def hook(leaf: CompiledNode) -> None:
            halted.add(self.leaf_index[leaf.id])

        snap, event = self.interp.advance(snap, outcome, hook)
        if isinstance(event, LeafRequest):
            index = self.leaf_index[event.node.id]
            return (snap, index), (frozenset(halted), ("tick", index))
        snap = (snap[0], snap[1], snap[2], False)  # the wake-up is the parent's business
        return (snap, None), (frozenset(halted), ("exit", event.status))

    def halt(self, snap: Any) -> tuple[Any, frozenset[int]]:
        halted: set[int] = set()

        def hook(leaf: CompiledNode) -> None:
            halted.add(self.leaf_index[leaf.id])

        w = Work(snap)
        self.interp.reset_child(w, 0, hook)
        return w.snapshot(), frozenset(halted)


def _check_local(
    local: _Local,
    node: CompiledNode,
    allowed: list[list[int]],
    haltable: frozenset[int],
    with_halt: bool,
    rows: tuple[Rows, Rows] | None = None,
    dead: frozenset[int] = frozenset(),
    fired: set[tuple[Any, ...]] | None = None,
) -> tuple[bool, dict[int, Any], int, list[tuple[int | None, Any]], list[Any]]:
    """The lockstep product of the two sides (module docstring). ``haltable``: the children
    whose own check held with ``halt`` offered (any halt of another child fails this one);
    ``with_halt``: offer ``halt`` between ticks. Returns (equivalent, σ: status -> canonical
    exit, product states, the local counterexample, the product's pairs).

    With ``rows``, each side's steps are recorded there (state -> input -> (next state, raw
    outputs), the input named as ``local_machines`` name it), once per side state: the
    transitions a certificate lists (``_witness_of``), so no second search is needed.

    With ``fired``, every hop the fragment follows is added to it: ``("state", s, a)`` for
    arm ``a`` of state ``s``, ``("child", i, status)`` for child i's interface hop."""
    bt = _BtSide(abstract_tree(node, [RUNNING in a for a in allowed]))
    fsm = _FsmSide(local, fired)
    never = frozenset(range(len(allowed))) - haltable
    pairing: dict[int, Any] = {}
    start: tuple[Any, Any] = ((bt.interp.initial(), None), (None, local.initial, frozenset()))
    seen: dict[Any, tuple[Any, tuple[int | None, Any]] | None] = {start: None}
    queue = deque([start])

    def trace(pair: Any, last: tuple[int | None, Any] | None = None) -> list[Any]:
        found: list[tuple[int | None, Any]] = [] if last is None else [last]
        link = seen[pair]
        while link is not None:  # parent links: iterative
            pair, step = link
            found.append(step)
            link = seen[pair]
        return found[::-1]

    def same(bt_out: Any, fsm_out: Any) -> bool:
        if bt_out[0] & never or fsm_out[2] & never:
            return False  # a child whose halt was not proven is halted
        if frozenset(i for i in bt_out[0] if i in local.halting) != fsm_out[0]:
            return False
        (b_kind, b_what), (f_kind, f_what) = bt_out[1], fsm_out[1]
        if b_kind != f_kind:
            return False
        if b_kind == "tick":
            return bool(b_what == f_what)
        if f_what[0] in local.strays:
            return False  # a stray jump into the subtree: no status of the node goes there
        # two statuses may share an exit (a parent that treats them alike): σ is a function
        return bool(pairing.setdefault(b_what, f_what) == f_what)

    bt_row: dict[str, Any] | None = None
    fsm_row: dict[str, Any] | None = None
    while queue:
        current = queue.popleft()
        (snap, position), (fpos, fvalues, frunning) = current
        if position != fpos:
            return False, pairing, len(seen), trace(current), []
        if position is None:
            inputs: list[Any] = ["tick", "halt"] if with_halt else ["tick"]
        else:
            inputs = allowed[position]
            if position in dead:  # ticked on both sides: not what was proven
                raise NotPerNode(f"{node.label} ticks child {position}, proven never ticked")
        if rows is not None:  # each side state's row once, from the first pair holding it
            bt_row = None if current[0] in rows[0] else rows[0].setdefault(current[0], {})
            fsm_row = None if current[1] in rows[1] else rows[1].setdefault(current[1], {})
        for symbol in inputs:
            values = dict(fvalues)
            running = set(frunning)
            if symbol == "halt":
                new_snap, halted = bt.halt(snap)
                bt_next: Any = (new_snap, None)
                values.update(local.halt)
                fsm_halts = frozenset(i for i in running if i in local.halting)
                if halted & never or any(i in never for i in running):
                    return False, pairing, len(seen), trace(current, (position, symbol)), []
                running.clear()
                bt_halts = frozenset(i for i in halted if i in local.halting)
                if bt_halts != fsm_halts:
                    return False, pairing, len(seen), trace(current, (position, symbol)), []
                fpos_next = None
                bt_raw: Any = (bt_halts, ("none", None))
                fsm_raw: Any = (fsm_halts, ("none", None))
            else:
                if symbol == "tick":
                    bt_next, bt_out = bt.run(bt.interp.begin_tick(snap), None)
                    hop = local.entry
                else:
                    bt_next, bt_out = bt.run(snap, symbol)
                    assert position is not None
                    hop = local.children[position][symbol]
                    if fired is not None:
                        fired.add(("child", position, symbol))
                    running.discard(position)
                    if symbol == RUNNING:
                        running.add(position)
                fpos_next, fsm_out = fsm.resolve(hop, values, running)
                if not same(bt_out, fsm_out):
                    return False, pairing, len(seen), trace(current, (position, symbol)), []
                bt_raw, fsm_raw = (bt_out[0] & local.halting, bt_out[1]), fsm_out[:2]
            pair = (bt_next, (fpos_next, tuple(sorted(values.items())), frozenset(running)))
            if bt_row is not None:
                bt_row[symbol if isinstance(symbol, str) else EVENTS[symbol]] = (bt_next, bt_raw)
            if fsm_row is not None:
                fsm_row[symbol if isinstance(symbol, str) else EVENTS[symbol]] = (pair[1], fsm_raw)
            if pair not in seen:
                if len(seen) >= LOCAL_LIMIT:
                    raise NotPerNode(f"the local problem of {node.label} passes {LOCAL_LIMIT}")
                seen[pair] = (current, (position, symbol))
                queue.append(pair)
    return True, pairing, len(seen), [], list(seen) if rows is not None else []


# -- the local machines (for a certificate: the same problem as ``_check_local``) ------------
#: Tokens only one side can output: a halt of a child whose halt was not proven (on the tree
#: side, on the fragment's side) and a tree status without a partner in σ. Each makes the
#: outputs differ, as ``_check_local`` fails there.
BT_UNPROVEN_HALT = "⟪tree halts an unproven child⟫"
FSM_UNPROVEN_HALT = "⟪fragment halts an unproven child⟫"
UNPAIRED = "⟪status without an exit⟫ {}"
STATUS_OF = {name: status for status, name in EVENTS.items()}
#: σ as plain data: status (``compiled.SUCCESS``...) -> (canonical exit target id, canonical
#: assignment ids), the ids of ``_Local.exits``.
Sigma = dict[int, tuple[int, tuple[int, ...]]]


def exit_token(exit_: Any) -> str:
    """The output token of an exit (canonical target and assignment ids), as both local
    machines print it (``fsmbt.verify.nusmv.encode_local`` maps σ through it too)."""
    target, assigns = exit_
    return "exit " + " ".join(str(x) for x in (target, *assigns))


def _local_outputs(
    halts: frozenset[int], bad: str | None, event: tuple[str, Any]
) -> tuple[str, ...]:
    found = [f"halt {i}" for i in sorted(halts)]
    if bad is not None:
        found.append(bad)
    kind, what = event
    if kind == "tick":
        found.append(f"tick {what}")
    elif kind == "exit":
        found.append(what)
    return tuple(found)


class _LocalInputs:
    """The inputs both local machines offer: ``tick`` (and ``halt``) between ticks, child
    i's statuses (as leaf outcomes) while child i runs; one tuple per position (shared)."""

    def __init__(self, allowed: list[list[int]], with_halt: bool) -> None:
        self.between: tuple[str, ...] = ("tick", "halt") if with_halt else ("tick",)
        self.at = [tuple(EVENTS[s] for s in a) for a in allowed]

    def of(self, position: int | None) -> tuple[str, ...]:
        return self.between if position is None else self.at[position]


class LocalTreeMachine:
    """The tree side of one local problem as a ``semantics.machine.Machine``: fsmbt's
    interpreter on the node over abstract children (``_BtSide``), statuses mapped to exits by
    a given σ. ``exited``: the statuses its steps have returned (what σ must cover)."""

    def __init__(self, problem: LocalProblem, sigma: Sigma, with_halt: bool) -> None:
        self.name = f"node {problem.node.label}"
        self.bt = _BtSide(abstract_tree(problem.node, [RUNNING in a for a in problem.allowed]))
        self.halting = problem.local.halting
        self.never = problem.never
        self.sigma = {s: exit_token(e) for s, e in sigma.items()}
        self.offered = _LocalInputs(problem.allowed, with_halt)
        self.exited: set[int] = set()

    def start(self) -> tuple[Any, tuple[str, ...]]:
        return (self.bt.interp.initial(), None), ()

    def inputs(self, state: Any) -> tuple[str, ...]:
        return self.offered.of(state[1])

    def step(self, state: Any, symbol: str) -> tuple[Any, tuple[str, ...]]:
        snap, _position = state
        if symbol == "halt":
            new_snap, halted = self.bt.halt(snap)
            bad = BT_UNPROVEN_HALT if halted & self.never else None
            return (new_snap, None), _local_outputs(halted & self.halting, bad, ("none", None))
        if symbol == "tick":
            nxt, out = self.bt.run(self.bt.interp.begin_tick(snap), None)
        else:
            nxt, out = self.bt.run(snap, STATUS_OF[symbol])
        halted, (kind, what) = out
        bad = BT_UNPROVEN_HALT if halted & self.never else None
        if kind == "exit":
            self.exited.add(what)
            event: tuple[str, Any] = ("exit", self.sigma.get(what, UNPAIRED.format(what)))
        else:
            event = ("tick", what)
        return nxt, _local_outputs(halted & self.halting, bad, event)

    def status(self, state: Any) -> str:
        return "running"

    def describe(self, state: Any) -> str:
        return "between ticks" if state[1] is None else f"at child {state[1]}"


class LocalFragmentMachine:
    """The machine side of one local problem as a ``semantics.machine.Machine``: the node's
    fragment with each child replaced by its interface (``_FsmSide``); a configuration is
    (position, own values, children that returned RUNNING last)."""

    def __init__(self, problem: LocalProblem, with_halt: bool) -> None:
        self.name = f"fragment of {problem.node.label}"
        self.local = problem.local
        self.fsm = _FsmSide(problem.local)
        self.never = problem.never
        self.offered = _LocalInputs(problem.allowed, with_halt)

    def start(self) -> tuple[Any, tuple[str, ...]]:
        return (None, self.local.initial, frozenset()), ()

    def inputs(self, state: Any) -> tuple[str, ...]:
        return self.offered.of(state[0])

    def step(self, state: Any, symbol: str) -> tuple[Any, tuple[str, ...]]:
        position, fvalues, frunning = state
        values = dict(fvalues)
        running = set(frunning)
        local = self.local
        if symbol == "halt":
            values.update(local.halt)
            bad = FSM_UNPROVEN_HALT if running & self.never else None
            halts = frozenset(i for i in running if i in local.halting)
            cleared: tuple[Any, ...] = (None, tuple(sorted(values.items())), frozenset())
            return cleared, _local_outputs(halts, bad, ("none", None))
        if symbol == "tick":
            hop = local.entry
        else:
            status = STATUS_OF[symbol]
            hop = local.children[position][status]
            running.discard(position)
            if status == RUNNING:
                running.add(position)
        fpos, (halted, (kind, what), touched) = self.fsm.resolve(hop, values, running)
        bad = FSM_UNPROVEN_HALT if touched & self.never else None
        event = ("exit", exit_token(what)) if kind == "exit" else ("tick", what)
        nxt = (fpos, tuple(sorted(values.items())), frozenset(running))
        return nxt, _local_outputs(halted, bad, event)

    def status(self, state: Any) -> str:
        return "running"

    def describe(self, state: Any) -> str:
        return "between ticks" if state[0] is None else f"at child {state[0]}"


def local_machines(
    problem: LocalProblem, sigma: Sigma, with_halt: bool
) -> tuple[LocalTreeMachine, LocalFragmentMachine]:
    """The two machines of ``problem`` (tree side first) for the native checker: equivalent
    exactly when ``_check_local`` holds with this ``with_halt`` and pairs statuses as ``sigma``
    does (outputs: the halts of halting children, the child ticked or the exit; a halt of an
    unproven child or an unpaired status is a token only one side outputs). Cost: one
    interpreter step or one fragment resolution per machine step."""
    return LocalTreeMachine(problem, sigma, with_halt), LocalFragmentMachine(problem, with_halt)


def sigma_exits(local: _Local, pairing: dict[int, Any]) -> Sigma:
    """σ as ``local_machines`` takes it (canonical exits) from ``_check_local``'s pairing."""
    return {status: (int(t), tuple(int(a) for a in ids)) for status, (t, ids) in pairing.items()}


# -- which local checks exist: the bottom-up walk -----------------------------------------------
@dataclass
class LocalProblem:
    """One node's local check: the node, its fragment over abstract children (canonically
    named), the statuses each child may return, the children whose halt was proven and the
    memo key (equal keys, equal problems: checked once)."""

    node: CompiledNode
    local: _Local
    allowed: list[list[int]]
    halts: frozenset[int]
    key: tuple[Any, ...]
    #: the children the tree never ticks (``NodeWalk.unticked``): ticking one refuses
    dead: frozenset[int] = frozenset()

    @property
    def never(self) -> frozenset[int]:
        """The children whose halt was not proven (a halt of one fails the check)."""
        return frozenset(range(len(self.allowed))) - self.halts


class NodeWalk:
    """The local checks of a region written per node, in the order they must be decided
    (children first): ``problems()`` yields each live control node's ``LocalProblem``; the
    caller settles it (``settle``: its σ and whether it held with ``halt`` offered) before
    the next. Leaves and dead nodes (never entered) are settled from the machine alone.
    ``verify`` (``check_region``) and ``fsmbt.verify.certificate`` both walk it, so both
    decide the same local checks. Cost: O(states + transitions · depth) to group, plus the
    canonicalization of each node's fragment. With ``tolerate`` (``check_region``'s, never a
    certificate's) a broken entry condition is recorded in ``region.broken`` and its stray
    jumps fail the local checks that reach them (``_Region``).

    Raises:
        NotPerNode: the machine is not a valid per-node decomposition of the region.
    """

    def __init__(
        self,
        region_root: BTNode,
        machine: FSM,
        declared: dict[str, str],
        tolerate: bool = False,
        unfired: frozenset[int] = frozenset(),
        never: Mapping[int, frozenset[int]] | None = None,
    ) -> None:
        try:
            # the same-type merge of plain Sequence/Fallback children (docs/semantics.md §4d,
            # lemma M: it keeps the leaf-execution machine), so that the nodes are the machine's
            merged = inline_and_compress(BTDocument.single(region_root)).compression.root
            self.tree = CompiledTree(BTDocument.single(merged))
        except FsmbtError as exc:
            raise NotPerNode(str(exc)) from None
        #: statuses nodes of ``tree`` (ids) are proven never to return (``narrow.py``): their
        #: parents' checks are offered only the others, and what those never tick is dead
        self.never: Mapping[int, frozenset[int]] = never or {}
        #: the nodes no run of the tree ticks (``tickable.never_ticked``: from the tree alone)
        self.unticked = never_ticked(self.tree, self.never)
        self.region = _Region(self.tree, machine, declared, tolerate, self.unticked, unfired)
        self.interfaces: dict[int, Interface] = {}
        self.haltable: set[int] = set()
        #: the transitions (``id``) a local check decided so far followed (``followed``)
        self.fired: set[int] = set()

    def followed(self, problem: LocalProblem, hops: set[tuple[Any, ...]]) -> None:
        """Record the transitions ``problem``'s check followed, from its canonical hops
        (``_check_local``'s ``fired``; equal problems share them): an arm of one of the
        node's states, or a leaf child's transition on the status it returned (a control
        child's interface is its own fragment's, recorded by its own check)."""
        region, node = self.region, problem.node
        for kind, at, which in hops:
            if kind == "state":
                self.fired.add(id(region.out[problem.local.state_names[at]][which]))
                continue
            leaf = region.leaf_state.get(node.children[at])
            if leaf is not None:
                self.fired.update(id(t) for t in region.out[leaf] if t.event == EVENTS[which])

    def problems(self) -> Iterator[LocalProblem]:
        region, interfaces = self.region, self.interfaces
        for node in reversed(self.tree.nodes):
            # dead: never ticked by the machine (no entry) or by the tree (docs/semantics.md
            # §4d, "Dead nodes": its parent's check, which holds or fails on its own, then
            # proves the machine never enters it either)
            if node.id not in region.entry or node.id in self.unticked:
                interfaces[node.id] = {}
                self.haltable.add(node.id)
                continue
            if node.is_env_leaf and not node.children:
                state = region.leaf_state[node.id]
                interface: Interface = {}
                for t in region.out[state]:
                    status = STATUS_OF[t.event]
                    interface[status] = (t.target, tuple(region.assigns[id(t)]))
                interfaces[node.id] = interface
                self.haltable.add(node.id)  # a leaf's halt is its halt hook: nothing is kept
                continue
            local = _local(region, node, interfaces)
            allowed = [
                sorted(s for s in interfaces[c] if s not in self.never.get(c, ()))
                for c in node.children
            ]
            halts = frozenset(i for i, c in enumerate(node.children) if c in self.haltable)
            dead = frozenset(i for i, c in enumerate(node.children) if c in self.unticked)
            key = (
                local.key,
                tuple(tuple(a) for a in allowed),
                tuple(sorted(halts)),
                tuple(sorted(dead)),
            )
            yield LocalProblem(node, local, allowed, halts, key, dead)
            if node.id not in interfaces:
                raise NotPerNode(f"the local check of {node.label} was not settled")

    def settle(self, problem: LocalProblem, sigma: Sigma, can_halt: bool) -> None:
        """Record ``problem``'s node as proven with interface σ (canonical exits)."""
        if can_halt:
            self.haltable.add(problem.node.id)
        self.interfaces[problem.node.id] = _real_exits(problem.local, sigma)

    def root_results(self) -> frozenset[str]:
        """The region's results, once every node is settled; the root's interface must be the
        finals' (SUCCESS, FAILURE) and its own entry (RUNNING), without assignment.

        Raises:
            NotPerNode: the root returns a status elsewhere.
        """
        root = self.interfaces[0]
        wanted = {
            SUCCESS: (END_SUCCESS, ()),
            FAILURE: (END_FAILURE, ()),
            RUNNING: (self.region.entry[0], ()),
        }
        for status, exit_ in root.items():
            if wanted[status] != exit_:
                raise NotPerNode(f"the region's root returns {EVENTS[status]} elsewhere")
        return frozenset(
            {SUCCESS: END_SUCCESS, FAILURE: END_FAILURE}[s] for s in root if s != RUNNING
        )


@dataclass
class LocalUnit:
    """One distinct local check as the walk decided it, for another engine to decide again
    (``fsmbt.verify.nusmv.pernode``): the problem, σ (canonical; partial when the check
    failed: the statuses paired before the failure), whether ``halt`` was offered, the
    native verdict, the nodes it stands for (paths in the merged region) and the labels of
    the node's children (how a counterexample names them)."""

    problem: LocalProblem
    sigma: Sigma
    can_halt: bool
    held: bool
    nodes: list[str]
    child_labels: list[str]


@dataclass
class LocalWitness:
    """One distinct local check kept for a certificate: the nodes it stands for (their paths
    in the merged region), σ (canonical), whether it held with ``halt`` offered, and the
    native checker's witness on ``local_machines``."""

    nodes: list[str]
    sigma: Sigma
    can_halt: bool
    witness: Any


# -- the whole region ----------------------------------------------------------------------------
def check_region(
    region_root: BTNode,
    machine: FSM,
    declared: dict[str, str],
    keep: list[LocalWitness] | None = None,
    units: list[LocalUnit] | None = None,
    tolerate: bool = False,
    never: Mapping[int, frozenset[int]] | None = None,
) -> PerNodeOutcome:
    """Check ``machine`` (a region state's sub-machine, tagged per node) against the region
    headed by ``region_root``, node by node (the module docstring). With ``keep``, each
    distinct local check that held is kept with its witness: the tables of
    ``local_machines`` and the relation, numbered from the steps the check itself made
    (``_witness_of``; no second search). With ``units``, each distinct local check decided
    up to the first failure is appended as a ``LocalUnit`` (what NuSMV checks again; no extra
    cost here), the failing one last.

    With ``tolerate``, a region that breaks the entry condition (2) - a transition jumping
    into a subtree elsewhere than its entry, as a retargeted transition does - is still walked:
    each fragment reading a stray jump outputs it as an exit no status of the node pairs with,
    so the local check that reaches it fails, and the outcome's ``tolerated`` names the broken
    condition. Such a failure is only a candidate: the composition theorem (docs/semantics.md
    §4d) needs the side conditions, so it says nothing about the region; the lift's replay on
    the two whole machines decides (``verify/lift.py``), else the region is checked whole. A
    region that breaks it and where no local check fails is refused (``NotPerNode``), as
    without ``tolerate``: no equivalence is ever concluded from a broken decomposition.

    Raises:
        NotPerNode: the machine is not a valid per-node decomposition of this region.
    """
    walk = NodeWalk(region_root, machine, declared, tolerate, never=never)
    outcome = PerNodeOutcome(equivalent=True, nodes=len(walk.tree.nodes))
    outcome.unticked = sum(1 for n in walk.unticked if n in walk.region.entry)
    failures = _failures(walk, outcome, keep, units)
    first = next(failures, None)
    if first is not None:
        outcome.equivalent = False
        outcome.failed, outcome.failed_id, outcome.trace = first
        outcome.seen = [first]
        outcome.tree = walk.tree
        outcome.more = _remembered(itertools.islice(failures, MAX_FAILURES - 1), outcome.seen)
        outcome.tolerated = walk.region.broken[0] if walk.region.broken else None
        return outcome
    if walk.region.broken:
        if keep is not None or units is not None:  # a certificate or a plan: not this rule
            raise NotPerNode(walk.region.broken[0])
        walk = _past_unfired(region_root, machine, declared, walk, outcome)
    outcome.results = walk.root_results()
    return outcome


#: Most walks ``_past_unfired`` makes before it refuses (each one grows the followed set).
UNFIRED_WALKS = 4


def _past_unfired(
    region_root: BTNode,
    machine: FSM,
    declared: dict[str, str],
    walk: NodeWalk,
    outcome: PerNodeOutcome,
) -> NodeWalk:
    """A region that broke the entry condition (2) while no local check failed: walk again
    with condition 2 not asked of the live transitions no local check followed
    (``_Region.unfired``), until the walk follows none of them; that walk, its local checks
    all held, is the proof (docs/semantics.md §4d, "Transitions no local check fires"). A
    one-transition change guarded by a value its node never reaches, or out of a state its
    node's fragment never reaches, jumps nowhere. Each walk may pick other entries, so it is
    checked again whole; the followed set only grows, so the walks end. Cost: one walk
    (``check_region``'s) per round, at most ``UNFIRED_WALKS``.

    Raises:
        NotPerNode: a walk fails a local check, breaks condition 2 with a followed
            transition, or follows a transition it was told no check follows.
    """
    first = walk.region.broken[0]
    followed = set(walk.fired)
    live = {id(t) for t in machine.transitions if not walk.region.dead(t)}
    for _round in range(UNFIRED_WALKS):
        unfired = frozenset(live - followed)
        again = NodeWalk(region_root, machine, declared, unfired=unfired, never=walk.never)
        tally = PerNodeOutcome(equivalent=True)
        if next(_failures(again, tally, None), None) is not None:
            raise NotPerNode(f"{first}; walked again past what no check follows, a check fails")
        if again.fired <= followed:
            outcome.unfired = len(unfired)
            outcome.distinct += tally.distinct
            outcome.local_states += tally.local_states
            return again
        followed |= again.fired
    raise NotPerNode(f"{first}; what no check follows did not settle in {UNFIRED_WALKS} walks")


Failure = tuple[str, int, list[tuple[int | None, Any]]]


def _remembered(items: Iterator[Failure], into: list[Failure]) -> Iterator[Failure]:
    """``items``, each also appended to ``into`` as it is met (what a rule after the lift
    reads: the failures the lift already asked for)."""
    for item in items:
        into.append(item)
        yield item


def _failures(
    walk: NodeWalk,
    outcome: PerNodeOutcome,
    keep: list[LocalWitness] | None,
    units: list[LocalUnit] | None = None,
) -> Iterator[Failure]:
    """Decide ``walk``'s local checks children first (equal problems once), counting them in
    ``outcome``; yield each node whose check fails (description, id, local counterexample).
    Resumed past a failure (only when the lift asks: ``PerNodeOutcome.more``), a failed node
    is settled with the σ its check had paired when it failed - a guess that only finds more
    candidates, each confirmed by replay - and a node above it that no longer groups ends the
    walk. With ``keep``, the witnesses of the checks that held before any failure; with
    ``units``, the distinct checks up to the first failure, the failing one last.

    Raises:
        NotPerNode: before any failure, the machine is not a valid per-node decomposition."""
    memo: dict[tuple[Any, ...], tuple[bool, dict[int, Any], int, list[Any], bool]] = {}
    kept: dict[tuple[Any, ...], LocalWitness] = {}
    recorded: dict[tuple[Any, ...], LocalUnit] = {}
    followed: dict[tuple[Any, ...], set[tuple[Any, ...]]] = {}
    failed = False
    try:
        for problem in walk.problems():
            node = problem.node
            found = memo.get(problem.key)
            if found is None:
                hops = followed[problem.key] = set()
                found, witness = _decide(problem, keep is not None and not failed, hops)
                memo[problem.key] = found
                outcome.distinct += 1
                outcome.local_states += found[2]
                if witness is not None:
                    kept[problem.key] = witness
                    assert keep is not None
                    keep.append(witness)
            equivalent, pairing, _states, local_trace, can_halt = found
            if units is not None and not failed:
                unit = recorded.get(problem.key)
                if unit is None:
                    labels = [walk.tree.nodes[c].label for c in node.children]
                    sigma = sigma_exits(problem.local, pairing)
                    unit = LocalUnit(problem, sigma, can_halt, equivalent, [], labels)
                    recorded[problem.key] = unit
                    units.append(unit)
                unit.nodes.append(node.path)
            if not equivalent:
                failed = True
                yield (
                    f"{node.type} '{node.label}' at {node.path or 'the root'}",
                    node.id,
                    local_trace,
                )
            if keep is not None and problem.key in kept:
                kept[problem.key].nodes.append(node.path)
            walk.followed(problem, followed[problem.key])
            walk.settle(problem, sigma_exits(problem.local, pairing), can_halt)
    except NotPerNode:
        if not failed:
            raise


@dataclass
class FailedUnit:
    """A node whose local check failed, as the complete walk settled it: the problem, σ
    (canonical; the statuses its check paired before failing) and whether ``halt`` was
    offered when it was settled (what ``local_machines`` needs to run it again)."""

    problem: LocalProblem
    sigma: Sigma
    can_halt: bool


@dataclass
class CompleteWalk:
    """Every live node's local check decided, none skipped: the walk (its merged tree) and the
    failing nodes, children first. ``verify/lower_bound.py`` reads it."""

    walk: NodeWalk
    failed: list[FailedUnit]
    results: frozenset[str]


def complete_walk(region_root: BTNode, machine: FSM, declared: dict[str, str]) -> CompleteWalk:
    """Decide every local check of the region (equal problems once) as ``check_region`` does
    - with ``halt`` offered, else without (then the node is not haltable) - but go past
    failures, and never tolerate a broken side condition: the failing set is then *complete*
    (no early stop, no cap on failures, no stray jump). A failing node is settled haltable,
    with the σ its check paired with ``halt`` offered: its local pair is the one run with
    ``halt`` (``FailedUnit.can_halt``), so its parent's check does not fail merely because it
    halts it (a failure would otherwise climb to the root). Cost: the walk of
    ``check_region`` to its end, failing problems checked twice.

    Raises:
        NotPerNode: a side condition fails anywhere (also past a failure), a local problem
            passes ``LOCAL_LIMIT``, or the root's interface is not the finals': the failing
            set is not known complete, so the caller claims nothing from it.
    """
    walk = NodeWalk(region_root, machine, declared)
    memo: dict[tuple[Any, ...], tuple[bool, dict[int, Any], bool]] = {}
    failed: list[FailedUnit] = []
    for problem in walk.problems():
        found = memo.get(problem.key)
        if found is None:
            args = (problem.local, problem.node, problem.allowed, problem.halts)
            held, pairing, _states, _trace, _pairs = _check_local(*args, True, dead=problem.dead)
            found = (held, pairing, True)
            if not held:
                alone = _check_local(*args, False, dead=problem.dead)
                if alone[0]:  # proven for a node nobody halts
                    found = (True, alone[1], False)
            memo[problem.key] = found
        held, pairing, can_halt = found
        sigma = sigma_exits(problem.local, pairing)
        if not held:
            failed.append(FailedUnit(problem, sigma, can_halt))
        walk.settle(problem, sigma, can_halt)
    return CompleteWalk(walk, failed, walk.root_results())


def _decide(
    problem: LocalProblem, keeping: bool, fired: set[tuple[Any, ...]] | None = None
) -> tuple[tuple[bool, dict[int, Any], int, list[Any], bool], LocalWitness | None]:
    """One distinct local check: with ``halt`` offered, else (proven for a node nobody halts,
    or not at all) without; (equivalent, σ, product states, local counterexample, with halt),
    and, when ``keeping`` and it held, its witness built from the check's own steps. With
    ``fired``, the hops the deciding run followed are added to it (``_check_local``)."""
    node, local = problem.node, problem.local
    for with_halt in (True, False):
        rows: tuple[Rows, Rows] | None = ({}, {}) if keeping else None
        hops: set[tuple[Any, ...]] | None = set() if fired is not None else None
        equivalent, pairing, states, trace, pairs = _check_local(
            local, node, problem.allowed, problem.halts, with_halt, rows, problem.dead, hops
        )
        if equivalent or not with_halt:
            break
    if fired is not None and hops is not None:
        fired.update(hops)
    found = (equivalent, pairing, states, trace, with_halt)
    if rows is None or not equivalent:
        return found, None
    return found, _witness_of(problem, pairing, with_halt, rows, pairs)


def _witness_of(
    problem: LocalProblem,
    pairing: dict[int, Any],
    can_halt: bool,
    rows: tuple[Rows, Rows],
    pairs: list[Any],
) -> LocalWitness:
    """A local check that held as a certificate unit: ``local_machines``'s two tables (their
    outputs the tokens those machines give: halts of halting children, the child ticked, the
    exit - a tree status named by σ's exit) and the product's pairs as the relation."""
    sigma = sigma_exits(problem.local, pairing)
    tokens: dict[Any, tuple[str, ...]] = {}

    def named(raw: Any, tree_side: bool) -> tuple[str, ...]:
        key = (tree_side, raw)
        found = tokens.get(key)
        if found is None:
            halts, (kind, what) = raw
            if kind == "exit":
                what = exit_token(sigma[what] if tree_side else what)
            found = tokens[key] = _local_outputs(halts, None, (kind, what))
        return found

    named_rows = tuple(
        {
            state: {symbol: (nxt, named(raw, side == 0)) for symbol, (nxt, raw) in row.items()}
            for state, row in rows[side].items()
        }
        for side in (0, 1)
    )
    offered = _LocalInputs(problem.allowed, can_halt)
    witness = witness_from_rows(
        pairs[0],  # the product's start pair (its pairs in the order it met them)
        (named_rows[0], named_rows[1]),
        (
            Side(_describe_at(1), _running, lambda state: offered.of(state[1])),
            Side(_describe_at(0), _running, lambda state: offered.of(state[0])),
        ),
        pairs,
    )
    return LocalWitness([], sigma, can_halt, witness)


def _running(_state: Any) -> str:
    return "running"


def _describe_at(position: int) -> Callable[[Any], str]:
    """``describe`` of a local machine whose position is item ``position`` of its state."""

    def describe(state: Any) -> str:
        return "between ticks" if state[position] is None else f"at child {state[position]}"

    return describe


def _real_exits(local: _Local, pairing: Sigma) -> Interface:
    """σ_N in the machine's names: each status's exit target and outside assignments."""
    found: Interface = {}
    for status, (target_id, assign_ids) in pairing.items():
        target = local.exits[target_id][1]
        assigns = tuple(pair for a in assign_ids for pair in local.exits[a][1])
        found[status] = (target, assigns)
    return found
