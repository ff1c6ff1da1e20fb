"""The one writer of a region per node: it walks the region's nodes and dispatches each to its
family's rule (``registry.RULES``), keeping what the families share - the states, the
variables, the entries, the halt chains (``fsmbt.convert.pernode``; the machine's shape is in
``fsmbt.convert.bt_pernode``'s docstring).

Cost: O(N) states and O(N · d) assignments for d the nesting depth of reactive nodes (each
reactive node resets its children's subtrees once per chain); no exploration.
"""

from __future__ import annotations

from collections.abc import Callable

from fsmbt.convert.pernode.kernel import (
    END_FAILURE,
    END_SUCCESS,
    EV_FAILURE,
    EV_RUNNING,
    EV_SUCCESS,
    NODE_ATTR,
    ROLE_ATTR,
    Assign,
    Cont,
    PerNodeRegion,
    Returns,
)
from fsmbt.convert.pernode.registry import RULES
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import ASSIGN, COND
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS, CompiledNode
from fsmbt.semantics.nodes import runtime_tables


class Writer:
    """Writes one region (``build``); implements ``kernel.RegionWriter`` for the rules."""

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
            kids = [found[c] for c in node.children]
            rule = RULES.get(self.tables.handlers.get(node.type) or "")
            if node.is_env_leaf:
                found[node.id] = node.kind is NodeKind.ACTION
            elif rule is not None:
                found[node.id] = rule.can_run(self, node, kids)
            else:
                found[node.id] = any(kids)
        return found

    def variable(
        self, node: CompiledNode, field_name: str, table: dict[int, str], key: int | None = None
    ) -> str:
        var = self.new_variable(f"{node.label}_{field_name}")
        table[node.id if key is None else key] = var
        self.variables.append((var, "0"))
        return var

    def _declare(self) -> None:
        """The variables of every node, and which of them a halt resets."""
        for node in self.nodes:
            rule = RULES.get(self.tables.handlers.get(node.type) or "")
            self.halt_vars[node.id] = rule.declare(self, node) if rule is not None else []

    def halt(self, nid: int) -> list[Assign]:
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

    def go(self, source: str, event: str | None, cont: Cont, cond: str | None = None) -> None:
        attrs: dict[str, str] = {}
        if cond is not None:
            attrs[COND] = cond
            self.guarded += 1
        if cont.assigns:
            attrs[ASSIGN] = "\n".join(f"{n}={e}" for n, e in cont.assigns)
        if cont.target in (END_SUCCESS, END_FAILURE):
            self.ends.add(cont.target)
        self.fsm.add_transition(source, event, cont.target, attrs=attrs)

    def transient(self, node: CompiledNode, role: str, arms: list[tuple[str | None, Cont]]) -> Cont:
        """A transient state of ``node`` taking the first arm whose guard holds (the last arm
        has none); a single unguarded arm needs no state."""
        if len(arms) == 1 and arms[0][0] is None:
            return arms[0][1]
        name = self._state(node, f"{node.label}.{role}", "", role)
        for cond, cont in arms:
            self.go(name, None, cont, cond)
        return Cont(name)

    def chain(self, node: CompiledNode, tag: str, end: Cont, first: int = 1) -> list[Cont]:
        """``chain[k]``: halt children k.. of ``node`` (each child with memory one transient
        state), then ``end``; ``chain[n] = end`` (built from ``first`` on)."""
        kids = node.children
        chain: list[Cont] = [end] * (len(kids) + 1)
        for k in range(len(kids) - 1, first - 1, -1):
            halt = self.halt(kids[k])
            if halt:  # a state per child, so each subtree's resets are written once per chain
                name = self._state(node, f"{node.label}.halt{k}{tag}", "", f"halt{k}{tag}")
                self.go(name, None, chain[k + 1].after(halt))
                chain[k] = Cont(name)
            else:
                chain[k] = chain[k + 1]
        return chain

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

    # -- the walk -----------------------------------------------------------------------------
    def build(self) -> PerNodeRegion:
        self._declare()
        self._entries()
        finals = {SUCCESS: Cont(END_SUCCESS), FAILURE: Cont(END_FAILURE)}
        self.fsm.initial = self.entry[0]
        if 0 not in self.idx and 0 not in self.done:  # the root's entry: its first child
            self.go(self.entry[0], None, Cont(self.entry[self.nodes[0].children[0]]))
        work: list[tuple[int, Returns]] = [(0, {**finals, RUNNING: Cont(self.entry[0])})]
        while work:
            nid, returns = work.pop()
            node = self.nodes[nid]
            if node.is_env_leaf:
                self._leaf(node, returns)
                continue
            rule = RULES[self.tables.handlers.get(node.type) or ""]
            kids = rule.write(self, node, returns)
            work.extend(zip(node.children, kids, strict=True))
        for end in (END_SUCCESS, END_FAILURE):  # only the ends some transition enters
            if end in self.ends:
                self.fsm.add_state(State(end, action=None, final=True))
        return PerNodeRegion(
            self.fsm, self.ends, self.variables, len(self.nodes), self.guarded, self.node_of
        )

    def _leaf(self, node: CompiledNode, returns: Returns) -> None:
        state = self.entry[node.id]
        self.go(state, EV_SUCCESS, returns[SUCCESS])
        self.go(state, EV_FAILURE, returns[FAILURE])
        if node.kind is NodeKind.ACTION:
            self.go(state, EV_RUNNING, returns[RUNNING])
