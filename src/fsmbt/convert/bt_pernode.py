"""A BT region as one small sub-machine per node, built from each node's own tick rule, never
by exploring (docs/conversion.md, "Per-node conversion"; docs/semantics.md §4d; issue 27).

Why: the compact form (``bt_compact``) and the unrolled form explore the region's
leaf-execution machine first, whose states are the *product* of the memories of its nodes (a
running index per plain control under a reactive one, a WithMemory index, retry counts ...):
a mixed tree of a few hundred nodes already has more configurations than any limit. Here the
memory of each node is its own SCXML variable and each node's rule is written once, so the
machine is linear in the region: its W3C meaning (configurations x valuations) is the product,
but it is never built by the converter.

The machine (one flat SCXML state list; every state tagged ``fsmbt:node`` (the SCXML writer's fsmbt
namespace, Clark notation in ``attrs``) = the node's path as
``CompiledNode.path`` names it, ``""`` for the region's root):

- a *leaf* is one state whose action is the leaf's label (as the other forms); its events
  ``success``/``failure`` (and ``running`` for an action) lead to where its parent's rule says;
- every other node has an *entry* (the state its tick starts in: a transient state with no
  action whose eventless guarded transitions pick the child to tick from the node's memory, or,
  when the node always starts at its first child, that child's entry) and receives three
  *returns* from its parent: where its SUCCESS, FAILURE and RUNNING lead, each a target state
  plus the assignments to run on the way (``Cont``). A return that depends on data (a wake-up
  test, a retry count) is a transient state of the node with guarded eventless transitions;
- a RUNNING that reaches the region's root ends the tick: the next tick enters the root again
  at its own entry state (the root always has one, so that the next tick is told apart from
  a child's entry: ``fsmbt.verify.pernode`` reads it as the root's RUNNING exit)
  (the region heads its part of the tree: its plain ancestors resume straight into it;
  docs/semantics.md §4c). A tick ending RUNNING and a wake-up's re-tick are not observable
  (§4), so they are the same eventless step back to the root's entry;
- halting a child (a reactive node halting the children after the one that returned) assigns
  the declared memory at rest to every variable of that child's subtree whose kind forgets it
  on halt (``halt_resets_memory``; a SequenceWithMemory keeps its index, as BehaviorTree.CPP
  4.8.2 does), and clears the "child was RUNNING" flags. A subtree that was not running already
  holds those values, so resetting it unconditionally is the interpreter's ``haltChild``.

Per rule (the handler names and flags of ``fsmbt.semantics.nodes.runtime_tables``; the
reference is each family's tick function in ``fsmbt.semantics.families``):

- ``sequence`` (Sequence, Fallback, SequenceWithMemory, Async*): ``idx`` (running child), and
  ``cr`` (the child at ``idx`` was RUNNING before this tick: the wake-up test reads it). Entry:
  ``[idx == i] -> child i``. Child i's go-on: ``idx = i + 1`` then the next child, or - for an
  asynchronous / with-memory kind whose child completed in this tick (``cr == 0``) - RUNNING
  (the wake-up); the last child's go-on resets ``idx``. The stop result resets ``idx`` (kept by
  a kind with memory). RUNNING sets ``cr``;
- ``reactive``: no memory; entry = child 0; a stop result or RUNNING halts the later children
  (a chain of transient states, one per child with memory, so that the size stays linear);
- ``simple_decorator``: rewires the child's results (``result_map``; none: SUCCESS becomes
  RUNNING, KeepRunningUntilFailure);
- ``repeat`` / ``retry``: ``count`` and ``cr``; the repeated result goes on while
  ``count + 1 < limit``: again at once after a child that was RUNNING, else RUNNING (wake-up).

Anything else in the region (Parallel, SubTree, RunOnce, a gate, a built-in leaf, a
pre-condition, ``num_cycles="0"``) is refused with the reason: the caller keeps today's explored
form. Costs: O(N) states, O(N · d) assignments for d the nesting depth of reactive nodes (each
reactive node resets its children's subtrees once per chain), no exploration.

Proof obligation: the region's W3C meaning equals its leaf-execution machine (§4). The checker
discharges it on every conversion whose whole product it can build (every small tree of the
tests, ``tests/convert/test_conv_bt_pernode.py``), and ``fsmbt.verify.pernode`` per node.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import ASSIGN, COND
from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import canonical_type
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, CompiledNode
from fsmbt.semantics.families.parallel import parallel_threshold
from fsmbt.semantics.nodes import runtime_tables

#: State attribute naming the node a state belongs to (its ``CompiledNode.path`` in the region).
NODE_ATTR = "{https://fsmbt.dev/ns/scxml}node"
#: State attribute naming the part of the node's rule a transient state is (entry, a return).
ROLE_ATTR = "{https://fsmbt.dev/ns/scxml}role"
EV_SUCCESS, EV_FAILURE, EV_RUNNING = "success", "failure", "running"
EVENTS_BY_STATUS = {SUCCESS: "S", FAILURE: "F"}
END_SUCCESS, END_FAILURE = "SUCCESS", "FAILURE"
#: Handlers of the loop family and the result they repeat on (``loops.loop_decorator``).
LOOP_AGAIN_ON = {"repeat": SUCCESS, "retry": FAILURE}
#: The tick rules this module writes (``FamilyRule`` handler names).
#: Handlers of the counting parallels (``families.parallel``): Parallel, ParallelAll.
PARALLEL_HANDLERS = frozenset({"parallel", "parallel_all"})
SUPPORTED_HANDLERS = frozenset(
    {"sequence", "reactive", "simple_decorator", *LOOP_AGAIN_ON, *PARALLEL_HANDLERS}
)

Assign = tuple[str, str]


@dataclass(frozen=True)
class Cont:
    """Where a result leads: a state, and the assignments run on the way (in order)."""

    target: str
    assigns: tuple[Assign, ...] = ()

    def after(self, assigns: list[Assign] | tuple[Assign, ...]) -> Cont:
        """This continuation with ``assigns`` run first."""
        return Cont(self.target, tuple(assigns) + self.assigns) if assigns else self


@dataclass
class PerNodeRegion:
    """A region written per node.

    Attributes:
        fsm: the sub-machine (leaf states, transient states, ``SUCCESS``/``FAILURE`` finals).
        ends: the final states some transition enters.
        variables: ``(name, initial)`` of every variable (the memory at rest).
        nodes: nodes of the region; ``guarded``: transitions with a guard.
        node_of: state name -> the node path it belongs to.
    """

    fsm: FSM
    ends: set[str]
    variables: list[tuple[str, str]]
    nodes: int
    guarded: int = 0
    node_of: dict[str, str] = field(default_factory=dict)


def _rule(node: CompiledNode) -> str | None:
    return runtime_tables().handlers.get(node.type)


def refusal(tree: CompiledTree) -> str | None:
    """Why the region ``tree`` cannot be written per node (``None``: it can). O(N)."""
    for node in tree.nodes:
        if any(key.startswith("_") for key in node.source.attrs):
            return f"{node.type} '{node.label}' has a pre-condition or an internal port"
        if node.is_env_leaf and not node.children:
            continue
        if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
            return f"{node.type} '{node.label}' is a built-in leaf"
        rule = _rule(node)
        if rule not in SUPPORTED_HANDLERS:
            return f"{node.type} '{node.label}' has no per-node rule"
        if rule in LOOP_AGAIN_ON and node.params[0] is not None and node.params[0] == 0:
            return f"{node.type} '{node.label}' returns at once (a count of 0)"
        if rule in PARALLEL_HANDLERS and 0 in _thresholds(node):
            return f"{node.type} '{node.label}' has a threshold of 0"
        if not node.children:
            return f"{node.type} '{node.label}' has no children"
    return None


def _thresholds(node: CompiledNode) -> tuple[int, int]:
    """(successes, failures) needed, resolved (``families.parallel``); ParallelAll:
    (children, max_failures)."""
    n = len(node.children)
    if _rule(node) == "parallel":
        succ, fail = node.params
        return parallel_threshold(succ, n), parallel_threshold(fail, n)
    return n, node.params[0]


def memory_log2(tree: CompiledTree) -> float:
    """A cheap upper estimate (log2) of the explored region's configurations: the product of
    the index and count ranges of its nodes, and of its leaves (O(N)); the caller writes the
    region per node past a threshold."""
    tables = runtime_tables()
    total = math.log2(max(1, sum(1 for n in tree.nodes if n.is_env_leaf)))
    for node in tree.nodes:
        rule = tables.handlers.get(node.type)
        if rule == "sequence" and len(node.children) > 1:
            total += math.log2(len(node.children)) + 1
        elif rule in LOOP_AGAIN_ON and node.params and isinstance(node.params[0], int):
            total += math.log2(max(2, node.params[0])) + 1
    return total


def pernode_region(
    node: BTNode,
    *,
    name: str,
    new_variable: Callable[[str], str],
    unique: Callable[[FSM, str], str],
) -> PerNodeRegion | str:
    """``node``'s subtree written per node (the module docstring), or why it cannot be.

    Args:
        node: the region's root (its ancestors plain: they resume straight into it).
        name: the sub-machine's name.
        new_variable: a unique variable name from a base (shared by one conversion).
        unique: a unique state name in a machine (the converter's rule).
    """
    try:
        tree = CompiledTree(BTDocument.single(node))
    except FsmbtError as exc:
        return str(exc)
    why = refusal(tree)
    if why is not None:
        return why
    return _Writer(tree, name, new_variable, unique).build()


class _Writer:
    def __init__(
        self,
        tree: CompiledTree,
        name: str,
        new_variable: Callable[[str], str],
        unique: Callable[[FSM, str], str],
    ) -> None:
        self.tree = tree
        self.nodes = tree.nodes
        self.tables = runtime_tables()
        self.fsm = FSM(name=name)
        self.fsm.initial = None
        self.new_variable = new_variable
        self.unique = unique
        self.variables: list[tuple[str, str]] = []
        self.halt_vars: dict[int, list[Assign]] = {}  # node -> its own variables reset by halt
        self.idx: dict[int, str] = {}
        self.cr: dict[int, str] = {}
        self.count: dict[int, str] = {}
        self.done: dict[int, dict[int, str]] = {}  # parallel -> child index -> completed flag
        self.successes: dict[int, str] = {}
        self.failures: dict[int, str] = {}
        self.entry: dict[int, str] = {}
        self.node_of: dict[str, str] = {}
        self.guarded = 0
        self.ends: set[str] = set()
        self.can_run = self._can_run()

    # -- static facts -------------------------------------------------------------------------
    def _can_run(self) -> list[bool]:
        """Whether each node may return RUNNING (bottom-up over pre-order ids, reversed)."""
        found = [False] * len(self.nodes)
        for node in reversed(self.nodes):
            rule = _rule(node)
            kids = [found[c] for c in node.children]
            if node.is_env_leaf:
                found[node.id] = node.kind is NodeKind.ACTION
            elif rule == "sequence":
                _fb, asynch, memory = self.tables.sequence_flags[node.type]
                found[node.id] = any(kids) or ((asynch or memory) and len(kids) > 1)
            elif rule == "simple_decorator":
                found[node.id] = kids[0] or node.type not in self.tables.result_maps
            elif rule in LOOP_AGAIN_ON:
                limit = node.params[0]
                found[node.id] = kids[0] or limit != 1
            elif rule in PARALLEL_HANDLERS:
                found[node.id] = len(kids) > 1 or kids[0]  # waits for the others
            else:
                found[node.id] = any(kids)
        return found

    def _variable(
        self, node: CompiledNode, field_name: str, table: dict[int, str], key: int | None = None
    ) -> str:
        var = self.new_variable(f"{node.label}_{field_name}")
        table[node.id if key is None else key] = var
        self.variables.append((var, "0"))
        return var

    def _declare(self) -> None:
        """The variables of every node, and which of them a halt resets."""
        resets = self.tables.halt_resets_memory
        for node in self.nodes:
            rule = _rule(node)
            own: list[Assign] = []
            if rule == "sequence":
                _fb, asynch, memory = self.tables.sequence_flags[node.type]
                n = len(node.children)
                wakes = (asynch or memory) and n > 1
                if memory and n > 1 or self.can_run[node.id]:
                    var = self._variable(node, "idx", self.idx)
                    if node.type in resets:
                        own.append((var, "0"))
                if wakes and any(self.can_run[c] for c in node.children[:-1]):
                    own.append((self._variable(node, "cr", self.cr), "0"))
            elif rule in LOOP_AGAIN_ON:
                limit = node.params[0]
                if limit is not None and limit > 1:
                    own.append((self._variable(node, "count", self.count), "0"))
                if limit != 1 and self.can_run[node.children[0]]:
                    own.append((self._variable(node, "cr", self.cr), "0"))
            elif rule in PARALLEL_HANDLERS:  # (both kinds forget their memory on halt)
                for i in range(len(node.children)):
                    own.append(
                        (
                            self._variable(node, f"done{i}", self.done.setdefault(node.id, {}), i),
                            "0",
                        )
                    )
                own.append((self._variable(node, "successes", self.successes), "0"))
                own.append((self._variable(node, "failures", self.failures), "0"))
            self.halt_vars[node.id] = own

    def _halt(self, nid: int) -> list[Assign]:
        """The assignments of halting ``nid``'s subtree (pre-order; O(subtree))."""
        found: list[Assign] = []
        stack = [nid]
        while stack:
            x = stack.pop()
            found.extend(self.halt_vars[x])
            stack.extend(reversed(self.nodes[x].children))
        return found

    # -- states -------------------------------------------------------------------------------
    def _state(self, node: CompiledNode, base: str, action: str, role: str) -> str:
        name = self.unique(self.fsm, base)
        state = self.fsm.add_state(State(name, action=action))
        state.attrs[NODE_ATTR] = node.path
        if role:
            state.attrs[ROLE_ATTR] = role
        self.node_of[name] = node.path
        return name

    def _go(self, source: str, event: str | None, cont: Cont, cond: str | None = None) -> None:
        attrs: dict[str, str] = {}
        if cond is not None:
            attrs[COND] = cond
            self.guarded += 1
        if cont.assigns:
            attrs[ASSIGN] = "\n".join(f"{n}={e}" for n, e in cont.assigns)
        if cont.target in (END_SUCCESS, END_FAILURE):
            self.ends.add(cont.target)
        self.fsm.add_transition(source, event, cont.target, attrs=attrs)

    def _transient(
        self, node: CompiledNode, role: str, arms: list[tuple[str | None, Cont]]
    ) -> Cont:
        """A transient state of ``node`` taking the first arm whose guard holds (the last arm
        has none); a single unguarded arm needs no state."""
        if len(arms) == 1 and arms[0][0] is None:
            return arms[0][1]
        name = self._state(node, f"{node.label}.{role}", "", role)
        for cond, cont in arms:
            self._go(name, None, cont, cond)
        return Cont(name)

    def _entries(self) -> None:
        """Each node's entry state (bottom-up: a node that always starts at its first child
        enters where that child does)."""
        for node in reversed(self.nodes):
            if node.is_env_leaf:
                self.entry[node.id] = self._state(node, node.label, node.label, "")
            elif node.id in self.idx or node.id == 0 or node.id in self.done:
                # the root: the next tick's target; a parallel: its first visit
                self.entry[node.id] = self._state(node, f"{node.label}.tick", "", "tick")
            else:
                self.entry[node.id] = self.entry[node.children[0]]

    # -- rules --------------------------------------------------------------------------------
    def build(self) -> PerNodeRegion:
        self._declare()
        self._entries()
        finals = {SUCCESS: Cont(END_SUCCESS), FAILURE: Cont(END_FAILURE)}
        self.fsm.initial = self.entry[0]
        if 0 not in self.idx and 0 not in self.done:  # the root's entry: its first child
            self._go(self.entry[0], None, Cont(self.entry[self.nodes[0].children[0]]))
        work: list[tuple[int, dict[int, Cont]]] = [(0, {**finals, RUNNING: Cont(self.entry[0])})]
        while work:
            nid, returns = work.pop()
            node = self.nodes[nid]
            if node.is_env_leaf:
                self._leaf(node, returns)
                continue
            rule = _rule(node)
            if rule == "sequence":
                kids = self._sequence(node, returns)
            elif rule == "reactive":
                kids = self._reactive(node, returns)
            elif rule == "simple_decorator":
                kids = [self._status_map(node, returns)]
            elif rule in PARALLEL_HANDLERS:
                kids = self._parallel(node, returns)
            else:
                kids = [self._loop(node, returns)]
            work.extend(zip(node.children, kids, strict=True))
        for end in (END_SUCCESS, END_FAILURE):  # only the ends some transition enters
            if end in self.ends:
                self.fsm.add_state(State(end, action=None, final=True))
        return PerNodeRegion(
            self.fsm, self.ends, self.variables, len(self.nodes), self.guarded, self.node_of
        )

    def _leaf(self, node: CompiledNode, returns: dict[int, Cont]) -> None:
        state = self.entry[node.id]
        self._go(state, EV_SUCCESS, returns[SUCCESS])
        self._go(state, EV_FAILURE, returns[FAILURE])
        if node.kind is NodeKind.ACTION:
            self._go(state, EV_RUNNING, returns[RUNNING])

    def _sequence(self, node: CompiledNode, returns: dict[int, Cont]) -> list[dict[int, Cont]]:
        """``families.sequence.tick_sequence`` per child."""
        is_fallback, asynch, memory = self.tables.sequence_flags[node.type]
        stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
        kids = node.children
        n = len(kids)
        idx, cr = self.idx.get(node.id), self.cr.get(node.id)
        if idx is not None:  # the entry: resume at the running (or kept) child
            entry = self.entry[node.id]
            for i in range(1, n):
                self._go(entry, None, Cont(self.entry[kids[i]]), f"{idx} == {i}")
            self._go(entry, None, Cont(self.entry[kids[0]]))
        done: list[Assign] = [(v, "0") for v in (idx, cr) if v is not None]
        out: list[dict[int, Cont]] = []
        for i in range(n):
            conts: dict[int, Cont] = {}
            if i == n - 1:
                conts[go_on] = returns[go_on].after(done)
            else:
                step = [(idx, str(i + 1))] if idx is not None else []
                onward = Cont(self.entry[kids[i + 1]], tuple(step))
                if asynch or memory:  # a child that completed in this tick: wake-up, RUNNING
                    wake = returns[RUNNING].after(step)
                    if cr is not None:
                        resumed = Cont(onward.target, (*step, (cr, "0")))
                        conts[go_on] = self._transient(
                            node, f"next{i}", [(f"{cr} == 1", resumed), (None, wake)]
                        )
                    else:
                        conts[go_on] = wake
                else:
                    conts[go_on] = onward
            kept = [(cr, "0")] if cr is not None else []
            if not memory and idx is not None:
                kept = [(idx, "0"), *kept]
            conts[stop] = returns[stop].after(kept)
            conts[RUNNING] = returns[RUNNING].after([(cr, "1")] if cr is not None else [])
            out.append(conts)
        return out

    def _chain(self, node: CompiledNode, tag: str, end: Cont, first: int = 1) -> list[Cont]:
        """``chain[k]``: halt children k.. of ``node`` (each child with memory one transient
        state), then ``end``; ``chain[n] = end`` (built from ``first`` on)."""
        kids = node.children
        chain: list[Cont] = [end] * (len(kids) + 1)
        for k in range(len(kids) - 1, first - 1, -1):
            halt = self._halt(kids[k])
            if halt:  # a state per child, so each subtree's resets are written once per chain
                chain[k] = self._halt_state(node, f"halt{k}{tag}", chain[k + 1].after(halt))
            else:
                chain[k] = chain[k + 1]
        return chain

    def _halt_state(self, node: CompiledNode, role: str, cont: Cont) -> Cont:
        name = self._state(node, f"{node.label}.{role}", "", role)
        self._go(name, None, cont)
        return Cont(name)

    def _reactive(self, node: CompiledNode, returns: dict[int, Cont]) -> list[dict[int, Cont]]:
        """``families.reactive.tick_reactive`` per child."""
        is_fallback = node.type in self.tables.reactive_fallbacks
        stop, go_on = (SUCCESS, FAILURE) if is_fallback else (FAILURE, SUCCESS)
        kids = node.children
        n = len(kids)
        stops = self._chain(node, "stop", returns[stop])
        runs = self._chain(node, "run", returns[RUNNING])
        out: list[dict[int, Cont]] = []
        for i in range(n):
            conts = {
                go_on: returns[go_on] if i == n - 1 else Cont(self.entry[kids[i + 1]]),
                stop: stops[i + 1],
                RUNNING: runs[i + 1],
            }
            out.append(conts)
        return out

    def _parallel(self, node: CompiledNode, returns: dict[int, Cont]) -> list[dict[int, Cont]]:
        """``families.parallel.tick_parallel`` / ``tick_parallel_all`` per child: every child
        not completed is ticked in order (``visit i``: ``[done_i == 1]`` skips it); Parallel
        checks its thresholds after each child's result (success first), ParallelAll once
        every child completed; ending halts every child and forgets the memory."""
        kids = node.children
        n = len(kids)
        done = self.done[node.id]
        sc, fc = self.successes[node.id], self.failures[node.id]
        need_s, need_f = _thresholds(node)
        waits_for_all = _rule(node) == "parallel_all"
        forget = [(done[i], "0") for i in range(n)] + [(sc, "0"), (fc, "0")]
        halt_s = self._chain(node, "S", returns[SUCCESS].after(forget), first=0)
        halt_f = self._chain(node, "F", returns[FAILURE].after(forget), first=0)
        # visit i, from the last: skip a completed child, else tick it
        visits: list[Cont] = [Cont("")] * (n + 1)
        if waits_for_all:
            all_done = " and ".join(f"{done[i]} == 1" for i in range(n))
            visits[n] = self._transient(
                node,
                "end",
                [
                    (f"({all_done}) and {fc} >= {need_f}", halt_f[0]),
                    (f"{all_done}", halt_s[0]),
                    (None, returns[RUNNING]),
                ],
            )
        else:
            visits[n] = returns[RUNNING]
        for i in range(n - 1, -1, -1):
            if i == 0:
                visits[i] = Cont(self.entry[node.id])
                self._go(self.entry[node.id], None, visits[i + 1], f"{done[i]} == 1")
                self._go(self.entry[node.id], None, Cont(self.entry[kids[i]]))
            else:
                visits[i] = self._transient(
                    node,
                    f"visit{i}",
                    [(f"{done[i]} == 1", visits[i + 1]), (None, Cont(self.entry[kids[i]]))],
                )
        out: list[dict[int, Cont]] = []
        for i in range(n):
            conts: dict[int, Cont] = {RUNNING: visits[i + 1]}
            for status, count in ((SUCCESS, sc), (FAILURE, fc)):
                mark = [(done[i], "1"), (count, f"{count} + 1")]
                if waits_for_all:
                    conts[status] = visits[i + 1].after(mark)
                    continue
                check = self._transient(
                    node,
                    f"check{i}{EVENTS_BY_STATUS[status]}",
                    [
                        (f"{sc} >= {need_s}", halt_s[0]),
                        (f"{fc} > {n - need_s} or {fc} == {need_f}", halt_f[0]),
                        (None, visits[i + 1]),
                    ],
                )
                conts[status] = check.after(mark)
            out.append(conts)
        return out

    def _status_map(self, node: CompiledNode, returns: dict[int, Cont]) -> dict[int, Cont]:
        """``families.status_map.tick_simple_decorator``."""
        mapped = self.tables.result_maps.get(node.type)
        if mapped is None:  # KeepRunningUntilFailure
            return {SUCCESS: returns[RUNNING], FAILURE: returns[FAILURE], RUNNING: returns[RUNNING]}
        return {SUCCESS: returns[mapped[0]], FAILURE: returns[mapped[1]], RUNNING: returns[RUNNING]}

    def _loop(self, node: CompiledNode, returns: dict[int, Cont]) -> dict[int, Cont]:
        """``families.loops.loop_decorator``."""
        again_on = LOOP_AGAIN_ON[_rule(node) or ""]
        stop_on = FAILURE if again_on == SUCCESS else SUCCESS
        limit = node.params[0]
        count, cr = self.count.get(node.id), self.cr.get(node.id)
        child_entry = self.entry[node.children[0]]
        rest: list[Assign] = [(v, "0") for v in (count, cr) if v is not None]
        if limit == 1:
            again = returns[again_on]
        else:
            arms: list[tuple[str | None, Cont]] = []
            bump = [(count, f"{count} + 1")] if count is not None else []
            if count is not None:
                arms.append((f"{count} >= {limit - 1}", returns[again_on].after(rest)))
            if cr is not None:
                arms.append((f"{cr} == 1", Cont(child_entry, (*bump, (cr, "0")))))
            arms.append((None, returns[RUNNING].after(bump)))
            again = self._transient(node, "again", arms)
        return {
            again_on: again,
            stop_on: returns[stop_on].after(rest),
            RUNNING: returns[RUNNING].after([(cr, "1")] if cr is not None else []),
        }


#: The default form of a region (``bt_to_hfsm``): below this estimate (bits, ``pernode_estimate``,
#: a loose upper bound of the explored configurations) the compact form, as before; at or above
#: it, per node when the region has ``PERNODE_SURE_NODES`` nodes or more, or when exploring it
#: passes ``PERNODE_TRY_STATES`` states (a region that fits keeps the compact form, byte for
#: byte: every tree of the tests and examples that converted before converts the same).
PERNODE_MIN_LOG2 = 12.0
PERNODE_SURE_NODES = 150
PERNODE_TRY_STATES = 4_000


def region_size(node: BTNode) -> int:
    """Nodes of ``node``'s subtree (iterative)."""
    count, stack = 0, [node]
    while stack:
        x = stack.pop()
        count += 1
        stack.extend(x.children)
    return count


def pernode_estimate(node: BTNode) -> float:
    """``memory_log2`` of ``node``'s subtree without compiling it (O(N), iterative): the
    converter's cheap test before choosing the form."""
    tables = runtime_tables()
    total, leaves = 0.0, 0
    stack = [node]
    while stack:
        x = stack.pop()
        stack.extend(x.children)
        if not x.children:
            leaves += 1
            continue
        rule = tables.handlers.get(x.semantics or canonical_type(x.type))
        if rule == "sequence" and len(x.children) > 1:
            total += math.log2(len(x.children)) + 1
        elif rule in LOOP_AGAIN_ON:
            total += 2.0
        elif rule in PARALLEL_HANDLERS:
            total += len(x.children) + 2 * math.log2(len(x.children) + 1)
        elif rule is not None and rule not in SUPPORTED_HANDLERS:
            total += math.log2(len(x.children) + 1) + 1
    return total + math.log2(max(1, leaves))
