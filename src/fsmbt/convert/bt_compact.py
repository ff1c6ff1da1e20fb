"""A BT region with memory as a compact state machine: one state per leaf, memory as data
(docs/conversion.md, "Compact conversion: memory as data"; docs/semantics.md, "Data in state
machines").

The leaf-execution machine of a region (``fsmbt.semantics.leaf_machine``) has one state per
interpreter configuration: the leaf about to be ticked *and* everything the tree remembers
(node statuses, memories such as a RecoveryNode's retry count or a PipelineSequence's running
index, the frames of the nodes on the call stack, the pending wake-up). The unrolled conversion
keeps the product as states. Here the configuration is split into a *control* part, the leaf
(one state per leaf of the region, action = the leaf's label), and a *data* part, the rest,
decomposed into one feature per node status, per memory field and per stack frame.

Rules:

1. **Variables** (partition refinement): start with no variable; while two explored states at
   the same leaf, equal on the chosen variables, lead on the same input to outcomes that differ
   (another next leaf, another output, or other values of the chosen variables), add the
   feature that tells the most such pairs apart (ties: feature order). At the fixpoint the
   chosen variables ``T`` make (leaf, values of T) a congruence of the explored machine: its
   quotient is the explored machine up to merging states with the same future, so it has the
   same leaf traces and results.
2. **Transitions** (per leaf and input): the fewest variables ``V`` of ``T`` (greedy) whose
   values decide the outcome: the next leaf (or end), the outputs and the updates of T - each
   updated variable gets one constant, or is incremented (``x + 1``: counters). Valuations with
   the same outcome become one transition; the most frequent outcome is written last without a
   guard (W3C: the first enabled transition in document order is taken), the others with a
   guard over V.
3. Only the variables some guard reads are kept (declared, assigned); the others cannot
   change a decision.

Proof obligation: the machine's flat meaning (the W3C expansion, ``fsmbt.model.fsm_data``) is
equivalent to the region's leaf-execution machine; the checker proves it for every conversion.

Costs: exploration as before (O(S·3) interpreter steps); refinement O(|T| · E) for E explored
transitions; the per-leaf choice O(|T|^2 · E) in the worst case, much less in practice.
"""

from __future__ import annotations

import math
import operator
import re
from collections import Counter
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from typing import Any

from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import ASSIGN, COND
from fsmbt.model.nodes import canonical_type, node_semantics
from fsmbt.semantics.bt_interpreter import STATUS_NAMES
from fsmbt.semantics.leaf_machine import TICK_END, ExploredMachine, LeafMachine, RootResult
from fsmbt.semantics.nodes import runtime_tables

_NOT_NAME = re.compile(r"[^A-Za-z0-9_]+")
#: Feature kinds: node status, memory field, stack frame, pending wake-up.
_STATUS, _MEMORY, _FRAME, _WAKE = "status", "memory", "frame", "wake"

Feature = tuple[Any, ...]
#: Conflicting pairs looked at per refinement round (enough to rank the features).
_MAX_PAIRS = 400
#: Transition attribute of a ``tick_marks`` region: the step ended a tick of the region's root
#: (RUNNING) before reaching its target (``fsmbt.convert.bt_parallel`` reads and removes it).
TICK_MARK = "fsmbt:tick-end"


@dataclass
class Namer:
    """Unique, readable variable names across every region of one conversion.

    Rule: ``name(base)`` is ``base`` when free, else ``base_n`` for the smallest free n >= 2.
    ``taken`` only grows, so a suffix found taken stays taken: the search for a base resumes
    where its last one stopped (``_next``) and gives the same name as a search from 2. Cost:
    O(1) amortised per name (a search from 2 each time made k names of one base cost O(k^2):
    1.2 s of the 1.8 s conversion of the 15 560-node ``memory`` tree, whose variables are
    nearly all ``SequenceWithMemory_idx_<n>``).
    """

    taken: set[str] = field(default_factory=set)
    _next: dict[str, int] = field(default_factory=dict, repr=False)

    def name(self, base: str) -> str:
        base = _NOT_NAME.sub("_", base).strip("_") or "v"
        if not (base[0].isalpha() or base[0] == "_"):
            base = "n_" + base
        unique = base
        if unique in self.taken:
            n = self._next.get(base, 2)
            unique = f"{base}_{n}"
            while unique in self.taken:
                n += 1
                unique = f"{base}_{n}"
            self._next[base] = n + 1
        self.taken.add(unique)
        return unique


@dataclass
class CompactRegion:
    """A region as one state per leaf with data.

    Attributes:
        fsm: the sub-machine (leaf states, final ``SUCCESS``/``FAILURE``), transitions with
            ``cond``/``assign`` attributes (``fsmbt.model.fsm_data``).
        ends: the final states it reaches.
        variables: ``(name, initial expression)`` of the variables its guards read.
        explored_states: states of the region's leaf-execution machine.
        guarded: transitions with a guard.
    """

    fsm: FSM
    ends: set[str]
    variables: list[tuple[str, str]]
    explored_states: int
    guarded: int = 0


def compact_region(
    machine: LeafMachine,
    explored: ExploredMachine[Any],
    *,
    name: str,
    top: bool,
    namer: Namer,
    unique: Callable[[FSM, str], str],
    tick_marks: bool = False,
) -> CompactRegion:
    """The compact machine of an explored region (see the module docstring).

    Args:
        machine: the region's leaf machine (its tree names the nodes).
        explored: its exploration.
        name: the sub-machine's name.
        top: the region is the whole tree (final states carry the result as action).
        namer: names the variables (shared by the regions of one conversion).
        unique: makes a state name unique in a machine (the converter's rule).
        tick_marks: the machine marks its ticks' ends (``LeafMachine(mark_ticks=True)``): a
            step with outputs ``(TICK_END, leaf)`` is a transition with ``TICK_MARK``.

    Raises:
        InputError: a step outputs more than one label inside a composite (as unrolled).
    """
    compactor = _Compactor(machine, explored, name, top, namer, unique)
    compactor.tick_marks = tick_marks
    return compactor.build()


class _Compactor:
    def __init__(
        self,
        machine: LeafMachine,
        explored: ExploredMachine[Any],
        name: str,
        top: bool,
        namer: Namer,
        unique: Callable[[FSM, str], str],
    ) -> None:
        self.machine = machine
        self.explored = explored
        self.nodes = machine.tree.nodes
        self.top = top
        self.tick_marks = False
        self.namer = namer
        self.unique = unique
        self.fsm = FSM(name=name)
        self.changed: dict[int, frozenset[int]] = {}  # id(explored transition) -> _changes
        self.head_of: dict[int, Hashable] = {}  # id(explored transition) -> (next, outputs)
        self.default_memory = runtime_tables().default_memory
        live = [s for s in explored.states if not isinstance(s, RootResult)]
        # states as numbers from here on (a snapshot is a nested tuple: hashing it is costly)
        index = {s: n for n, s in enumerate(live)}
        self.start: int | RootResult = index.get(explored.start, explored.start)
        self.leaf: list[int] = [self._leaf_id(s) for s in live]
        features = [self._features(s) for s in live]
        keys: set[Feature] = set()
        for found in features:
            keys.update(found)
        self.keys: list[Feature] = sorted(keys, key=lambda k: (k[0], k[1:]))
        defaults = [self._default(k) for k in self.keys]
        self.vec: list[tuple[Any, ...]] = [  # f.get(key, default) per key, in C
            tuple(map(f.get, self.keys, defaults)) for f in features
        ]
        self.edges: list[tuple[int, str, int | RootResult, tuple[str, ...]]] = []
        for n, s in enumerate(live):
            for symbol, (target, outs) in explored.transitions[s].items():
                if len(outs) == 2 and top:
                    target, outs = self._looped(target, outs)
                elif top and len(outs) != 1:  # never drop an output (as unrolled)
                    raise UnsupportedError(
                        f"cannot express the outputs {outs} of one step as one state's action",
                        element=self.fsm.name,
                    )
                self.edges.append(
                    (n, symbol, target if isinstance(target, RootResult) else index[target], outs)
                )

    def _looped(self, target: Any, outputs: tuple[str, ...]) -> tuple[RootResult, tuple[str]]:
        """With ``loop`` a step can end the tick and start the next one: ``(result, first
        leaf)``. As unrolled (``bt_to_hfsm._looped_result``): it enters the final state named
        after the result, exact when the new tick starts in the start configuration."""
        result, _leaf = outputs
        if target != self.explored.start or result not in ("SUCCESS", "FAILURE"):
            raise UnsupportedError(
                f"cannot express the outputs {outputs} of one step as one state's action",
                element=self.fsm.name,
            )
        return RootResult(result), (result,)

    # -- features --------------------------------------------------------------------------
    @staticmethod
    def _leaf_id(state: Any) -> int:
        if isinstance(state, int):  # fast path: the state is the leaf
            return state
        return int(state[2][-1][0])

    @staticmethod
    def _features(state: Any) -> dict[Feature, Any]:
        if isinstance(state, int):
            return {}
        statuses, memories, frames, wake = state
        found: dict[Feature, Any] = {(_STATUS, nid): st for nid, st in statuses}
        for nid, memory in memories:
            for i, value in enumerate(memory):
                found[(_MEMORY, nid, i)] = value
        for frame in frames[:-1]:  # the leaf's own frame is the control part
            found[(_FRAME, frame[0])] = tuple(frame[1:])
        if wake:
            found[(_WAKE,)] = True
        return found

    def _default(self, key: Feature) -> Any:
        if key[0] == _STATUS:
            return 0  # IDLE: the interpreter stores no status for an idle node
        if key[0] == _MEMORY:
            return self.default_memory[self.nodes[key[1]].type][key[2]]
        if key[0] == _FRAME:
            return None  # not on the stack
        return False

    def _target(self, state: int | RootResult) -> Hashable:
        return ("end", state.result) if isinstance(state, RootResult) else self.leaf[state]

    # -- rule 1: the variables -------------------------------------------------------------
    def refine(self) -> list[int]:
        """Rule 1. Each live state carries a class number: equal numbers = equal values of the
        chosen variables (refined in place when a variable is added: O(S) per variable)."""
        chosen: list[int] = []
        taken: set[int] = set()
        width = len(self.keys)
        cls = [0] * len(self.vec)
        inputs: dict[Hashable, int] = {}
        heads: dict[Hashable, int] = {}
        edges = [
            (
                inputs.setdefault((self.leaf[s], symbol), len(inputs)),
                s,
                heads.setdefault((self._target(t), outs), len(heads)),
                None if isinstance(t, RootResult) else t,
            )
            for s, symbol, t, outs in self.edges
        ]
        while True:
            first: dict[tuple[int, int], tuple[tuple[int, int], int]] = {}
            tally: Counter[int] = Counter()
            pairs = 0
            for at, source, head, live_target in edges:
                outcome = (head, -1 if live_target is None else cls[live_target])
                seen = first.setdefault((at, cls[source]), (outcome, source))
                if seen[0] != outcome:
                    pairs += 1
                    vs, other = self.vec[source], self.vec[seen[1]]
                    for i in range(width):
                        if i not in taken and vs[i] != other[i]:
                            tally[i] += 1
                    if pairs == _MAX_PAIRS:
                        break  # the ranking is made: later pairs were not counted anyway
            if not tally:
                return chosen
            best = max(tally, key=lambda i: (tally[i], -i))
            chosen.append(best)
            taken.add(best)
            numbers: dict[tuple[int, Any], int] = {}
            for s, vs in enumerate(self.vec):
                cls[s] = numbers.setdefault((cls[s], vs[best]), len(numbers))

    # -- rule 2: the transitions -------------------------------------------------------------
    def _changes(self, item: tuple[Any, Any, Any], chosen: list[int]) -> frozenset[int]:
        """The chosen variables one explored transition changes (cached per transition)."""
        found = self.changed.get(id(item))
        if found is None:
            source, target, _outs = item
            if isinstance(target, RootResult):
                found = frozenset()
            else:
                vs, vt = self.vec[source], self.vec[target]
                found = frozenset(i for i in chosen if vs[i] != vt[i])
            self.changed[id(item)] = found
        return found

    def _spec(self, group: list[Any], chosen: list[int]) -> Any:
        """The outcome of a group of explored transitions as one compact transition: (next,
        outputs, updates), or ``None`` when the members disagree. Only the variables some
        member changes are looked at (O(|group| · changed))."""
        head_of = self.head_of
        heads = {head_of[id(item)] for item in group}
        if len(heads) != 1:
            return None
        head = heads.pop()
        target = group[0][1]
        if isinstance(target, RootResult):
            return (head, ())
        changed: set[int] = set()
        for item in group:
            changed |= self._changes(item, chosen)
        updates = []
        for i in chosen:
            if i not in changed:
                continue
            pairs = [(self.vec[s][i], self.vec[t][i]) for s, t, _o in group]
            news = {b for _a, b in pairs}
            if len(news) == 1:
                updates.append((i, "=", news.pop()))
            elif all(_is_int(a) and _is_int(b) and b == a + 1 for a, b in pairs):
                updates.append((i, "+", 1))
            else:
                return None
        return (head, tuple(updates))

    def _signature(self, item: tuple[Any, Any, Any], chosen: list[int]) -> Hashable:
        """What one explored transition does, for ranking variables: next, outputs, and
        each changed variable's new value (``+`` for an increment)."""
        source, target, outs = item
        if isinstance(target, RootResult):
            return (target.result, outs)
        vs, vt = self.vec[source], self.vec[target]
        changes = tuple(
            (i, "+" if _is_int(vs[i]) and vt[i] == vs[i] + 1 else vt[i])
            for i in chosen
            if vs[i] != vt[i]
        )
        return (self.leaf[target], outs, changes)

    def _specs(self, items: list, reads: list[int], chosen: list[int]):
        """({valuation of ``reads``: spec}, the valuations whose items have no one spec)."""
        project = _projector(reads)
        vec = self.vec
        groups: dict[Hashable, list] = {}
        for item in items:
            key = project(vec[item[0]])
            group = groups.get(key)
            if group is None:
                groups[key] = [item]
            else:
                group.append(item)
        specs, undecided = {}, set()
        for key, group in groups.items():
            spec = self._spec(group, chosen)
            if spec is None:
                undecided.add(key)
            else:
                specs[key] = spec
        return specs, undecided

    def _consistent(self, items: list, reads: list[int], chosen: list[int]):
        """{valuation of ``reads``: spec}, or ``None`` when some valuation has no one spec
        (found at the first such valuation)."""
        project = _projector(reads)
        vec = self.vec
        groups: dict[Hashable, list] = {}
        for item in items:
            key = project(vec[item[0]])
            group = groups.get(key)
            if group is None:
                groups[key] = [item]
            else:
                group.append(item)
        specs = {}
        for key, group in groups.items():
            spec = self._spec(group, chosen)
            if spec is None:
                return None
            specs[key] = spec
        return specs

    def decide(self, items, chosen: list[int]):
        """For one (leaf, input): the deciding variables and {outcome: valuations}. Greedy:
        add the variable that leaves the least uncertainty (conditional entropy) about what
        the transitions do, until every valuation has one outcome; then drop the variables
        the others make redundant (last added first).

        Only the transitions of still undecided valuations are looked at again when a variable
        is added: a valuation with one outcome splits into valuations with that one outcome.
        """
        signature = {id(item): self._signature(item, chosen) for item in items}
        reads: list[int] = []
        pending = items  # the transitions of the valuations not decided yet
        while True:
            _decided, undecided = self._specs(pending, reads, chosen)
            if not undecided:
                break
            project = _projector(reads)
            rows = []
            still = []
            for it in pending:
                prefix = project(self.vec[it[0]])
                if prefix in undecided:
                    rows.append((prefix, self.vec[it[0]], signature[id(it)]))
                    still.append(it)
            pending = still
            best, best_key = None, None
            prefixes = [prefix for prefix, _vs, _sig in rows]
            signatures = [sig for _p, _vs, sig in rows]
            for i in chosen:
                if i in reads:
                    continue
                column = [vs[i] for _p, vs, _s in rows]
                if len(set(column)) < 2:
                    continue  # a variable constant where it matters tells nothing apart
                cells = list(zip(prefixes, column))
                totals = Counter(cells)
                counts = Counter(zip(cells, signatures))
                entropy = sum(c * math.log(totals[cs[0]] / c) for cs, c in counts.items())
                key = (round(entropy, 9), len(totals))
                if best_key is None or key < best_key:
                    best, best_key = i, key
            assert best is not None  # all of ``chosen`` decides every outcome (rule 1)
            reads.append(best)
        specs = None
        for i in reversed(list(reads)):
            fewer = [r for r in reads if r != i]
            smaller = self._consistent(items, fewer, chosen)
            if smaller is not None:
                reads, specs = fewer, smaller
        if specs is None:
            specs = self._consistent(items, reads, chosen)
            assert specs is not None  # every valuation of ``reads`` was decided above
        outcomes: dict[Hashable, list[tuple[Any, ...]]] = {}
        for valuation, spec in specs.items():
            outcomes.setdefault(spec, []).append(_as_tuple(valuation, len(reads)))
        return reads, outcomes

    # -- assembly ----------------------------------------------------------------------------
    def build(self) -> CompactRegion:
        chosen = self.refine()
        by_input: dict[tuple[int, str], list] = {}
        for source, symbol, target, outs in self.edges:
            by_input.setdefault((self.leaf[source], symbol), []).append((source, target, outs))
        self.head_of = {
            id(item): (self._target(item[1]), item[2])
            for items in by_input.values()
            for item in items
        }
        decided = {k: self.decide(items, chosen) for k, items in by_input.items()}
        used = sorted({i for reads, _o in decided.values() for i in reads})
        names = {i: self._variable_name(self.keys[i]) for i in used}
        values = {i: self._encoder(i) for i in used}
        # states: one per leaf, in order of first visit; the ends
        fsm = self.fsm
        state_of: dict[Hashable, str] = {}
        ends: set[str] = set()

        def state_for(target: Any) -> str:
            known = state_of.get(target)
            if known is not None:
                return known
            if isinstance(target, tuple):  # ("end", result)
                result = target[1]
                ends.add(result)
                fsm.add_state(State(result, action=result if self.top else None, final=True))
                state_of[target] = result
                return result
            label = self.nodes[target].label
            name = self.unique(fsm, label)
            fsm.add_state(State(name, action=label))
            state_of[target] = name
            return name

        start = self.start
        fsm.initial = state_for(self._target(start))
        for leaf in self.leaf:
            state_for(leaf)
        guarded = 0
        for (at_leaf, symbol), (reads, outcomes) in decided.items():
            from_state = state_of[at_leaf]
            ordered = sorted(outcomes.items(), key=lambda kv: -len(kv[1]))
            default = ordered[0][0]
            ordered = ordered[1:] + ordered[:1]
            for n, (spec, valuations) in enumerate(ordered):
                (target, outs), updates = spec
                marked = self.tick_marks and len(outs) == 2 and outs[0] == TICK_END
                if marked:
                    outs = outs[1:]
                if len(outs) != 1 and not self.top:
                    raise InputError(
                        f"cannot express the outputs {outs} of one step as one state's action",
                        element=fsm.name,
                    )
                attrs: dict[str, str] = {TICK_MARK: "true"} if marked else {}
                if spec != default:
                    later = [v for _spec, vs in ordered[n + 1 :] for v in vs]
                    attrs[COND] = _guard(
                        [names[i] for i in reads], [values[i] for i in reads], valuations, later
                    )
                    guarded += 1
                assigns = [
                    (names[i], f"{names[i]} + 1" if op == "+" else values[i](new))
                    for i, op, new in updates
                    if i in names
                ]
                if assigns:
                    attrs[ASSIGN] = "\n".join(f"{n}={e}" for n, e in assigns)
                fsm.add_transition(from_state, symbol, state_for(target), attrs=attrs)
        variables: list[tuple[str, str]] = []
        if not isinstance(start, RootResult):
            variables = [(names[i], values[i](self.vec[start][i])) for i in used]
        return CompactRegion(fsm, ends, variables, len(self.explored.states), guarded)

    def _variable_name(self, key: Feature) -> str:
        if key[0] == _WAKE:
            return self.namer.name("wake_up")
        node = self.nodes[key[1]]
        base = node.label
        if key[0] == _STATUS:
            return self.namer.name(f"{base}_status")
        if key[0] == _FRAME:
            return self.namer.name(f"{base}_frame")
        declared = node_semantics(canonical_type(node.type))
        fields = declared.memory if declared is not None else ()
        suffix = fields[key[2]] if key[2] < len(fields) else f"m{key[2]}"
        return self.namer.name(f"{base}_{suffix}")

    def _encoder(self, index: int) -> Callable[[Any], str]:
        """How the values of one feature are written: statuses by name, integers as numbers,
        anything else as a distinct string literal."""
        key = self.keys[index]
        domain = {v[index] for v in self.vec}
        if key[0] == _STATUS:
            return lambda v: f"'{STATUS_NAMES[v]}'"
        if all(_is_int(v) for v in domain):
            return str
        texts: dict[Any, str] = {}
        for value in sorted(domain, key=repr):
            text = re.sub(r"[^\w,()\[\].:-]+", "", repr(value)) or "v"
            while text in texts.values():
                text += "_"
            texts[value] = text
        return lambda v: f"'{texts[v]}'"


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _projector(indices: Sequence[int]) -> Callable[[tuple[Any, ...]], Hashable]:
    if not indices:
        return lambda _v: ()
    if len(indices) == 1:
        only = indices[0]
        return lambda v: (v[only],)
    return operator.itemgetter(*indices)  # a tuple for two or more indices


def _as_tuple(valuation: Hashable, width: int) -> tuple[Any, ...]:
    assert isinstance(valuation, tuple) and len(valuation) == width
    return valuation


def _guard(
    names: list[str],
    encoders: list[Callable[[Any], str]],
    valuations: list[tuple[Any, ...]],
    later: list[tuple[Any, ...]],
) -> str:
    """A cond that holds for every valuation in ``valuations`` and for none in ``later`` (the
    valuations the transitions written after this one take; the ones before it have taken
    theirs, and no other valuation is reachable here).

    Cubes (conjunctions of ``x == v``), each grown from one uncovered valuation by dropping
    the literals it does not need (in variable order), then merged where two cubes differ in
    one variable: O(V^2 · (on + off)) per cube.
    """
    width = len(names)
    cubes: list[dict[int, set[Any]]] = []
    uncovered = list(dict.fromkeys(valuations))
    while uncovered:
        seed = uncovered[0]
        kept = list(range(width))
        for j in range(width):
            trial = [k for k in kept if k != j]
            if not any(all(v[k] == seed[k] for k in trial) for v in later):
                kept = trial
        cubes.append({k: {seed[k]} for k in kept})
        uncovered = [v for v in uncovered if not all(v[k] == seed[k] for k in kept)]
    merged = True
    while merged:
        merged = False
        for a in range(len(cubes)):
            for b in range(a + 1, len(cubes)):
                x, y = cubes[a], cubes[b]
                if x.keys() != y.keys():
                    continue
                differ = [k for k in x if x[k] != y[k]]
                if len(differ) == 1:
                    x[differ[0]] |= y[differ[0]]
                    del cubes[b]
                    merged = True
                    break
            if merged:
                break
    terms = []
    for cube in cubes:
        if not cube:
            return "True"
        parts = [
            _one(names[k], encoders[k], sorted(cube[k], key=_order), wrap=len(cube) > 1)
            for k in sorted(cube)
        ]
        terms.append(" and ".join(parts))
    if len(terms) == 1:
        return terms[0]
    return " or ".join(f"({t})" for t in terms)


def _one(name: str, encode: Callable[[Any], str], values: list[Any], wrap: bool = False) -> str:
    if len(values) == 1:
        return f"{name} == {encode(values[0])}"
    numbers = all(_is_int(v) and encode(v) == str(v) for v in values)  # written as numbers
    if numbers and values == list(range(values[0], values[-1] + 1)):
        return f"{name} >= {values[0]} and {name} <= {values[-1]}"
    text = " or ".join(f"{name} == {encode(v)}" for v in values)
    return f"({text})" if wrap else text


def _order(value: object) -> tuple[int, int, str]:
    return (0, value, "") if isinstance(value, int) and _is_int(value) else (1, 0, repr(value))
