"""Structured control flow for one region of an outcome-driven machine (docs/conversion.md,
"The structured style"): the way a decompiler structures a control-flow graph.

``T(s, ctx)`` is the fragment that runs from unit ``s`` until the region reaches one of the
*terminals* in ``ctx`` (the region's exits, plus join points and loop heads added on the way),
and returns that terminal's status. The invariant that makes the composition exact: in every
context, terminals with the same status are interchangeable for the construct that owns the
context. Rules, tried in this order at ``s``:

1. Loop: ``s`` is reached again from its successors (not through a terminal). Its body is
   every unit on a cycle through ``s``. If every way out of the body is a terminal with status
   FAILURE: ``KeepRunningUntilFailure(T(s, ctx + {s: SUCCESS}))``; all SUCCESS:
   ``RetryUntilSuccessful(num_attempts=-1, T(s, ctx + {s: FAILURE}))``; one unit ``m``:
   ``Sequence(RetryUntilSuccessful(-1, T(s, ctx + {s: FAILURE, m: SUCCESS})), T(m, ctx))``.
2. Join: ``s`` leads to two or more units, and a unit ``m`` is the immediate post-dominator of
   ``s`` once the FAILURE terminals are removed: ``Sequence(T(s, ctx + {m: SUCCESS}), T(m))``;
   with the SUCCESS terminals removed: ``Fallback(T(s, ctx + {m: FAILURE}), T(m))``.
3. Compose: a binary unit's two fragments by ``shapes.branch`` (``Sequence``, ``Fallback``,
   ``IfThenElse``, ``Inverter``, ``Force*``); a dispatch unit
   ``Sequence(leaf, Switch(outcome) -> fragments)``.

Every unit is emitted once; a unit reached from two places no rule joins (an irreducible
region, a loop with several exits) raises ``Unstructured`` and the region gets the flag form
(``flags``). The structuring is written as generators driven by an explicit stack
(``_drive``): no recursion on the machine, however deep. Costs: a reachability walk per unit on
a cycle and a dominator computation per branching unit: O(units x region) at worst, O(units)
for chains.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Generator
from typing import Any

import networkx as nx

from fsmbt.convert.structured.builder import always, control, decorator, script, type_id
from fsmbt.convert.structured.shapes import (
    Fragment,
    Term,
    as_node,
    branch,
    fallback,
    forced,
    sequence,
    switch_chain,
    then,
)
from fsmbt.model.bt import BTNode
from fsmbt.semantics.outcome_rules import FAILURE, SUCCESS
from fsmbt.semantics.outcome_view import Region, Unit

Context = dict[str, Term]
#: A request to the driver: (unit name, context, entry: compile the unit even if a terminal).
Request = tuple[str, Context, bool]
Task = Generator[Request, Fragment, Fragment]
_END = "\x00end"
#: A flag value that is a literal as written (else the way out's index is used).
_LITERAL = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


class Unstructured(Exception):
    """The region has no structured form (the message names the state and why)."""


class RegionStructurer:
    """Structures one region; ``emit`` makes a unit's node (leaf or SubTree)."""

    def __init__(
        self,
        region: Region,
        emit: Callable[[Unit], BTNode],
        exits: dict[str, Term],
        *,
        yielding_loops: bool = False,
    ) -> None:
        self.region = region
        #: Under a Parallel (a Concurrence's container child) every loop returns RUNNING when
        #: it goes round (``Inverter(KeepRunningUntilFailure(Inverter(body)))`` for the retry
        #: loop, whose ``RetryUntilSuccessful`` would go round in the same tick after a body
        #: that had run on): the round reading then knows where the turn passes
        #: (docs/semantics.md §11, "Container children").
        self.yielding_loops = yielding_loops
        #: The (unit path, outcome) transitions that go round a loop (back to its head).
        self.round_trips: set[tuple[str, str]] = set()
        self.units = region.units
        self.emit = emit
        self.exits = exits
        self.emitted: set[str] = set()
        self.order = {name: index for index, name in enumerate(self.units)}
        #: The blackboard flags the structuring needed (each named: where and why).
        self.flags: list[str] = []
        graph: nx.DiGraph[str] = nx.DiGraph()
        for name, unit in self.units.items():
            graph.add_node(name)
            for target in unit.targets.values():
                if target in self.units:
                    graph.add_edge(name, target)
        self.cyclic: set[str] = set()
        for component in nx.strongly_connected_components(graph):
            if len(component) > 1:
                self.cyclic |= component
        self.cyclic |= {n for n in graph if graph.has_edge(n, n)}

    def structure(self) -> BTNode:
        """The region's tree. Raises ``Unstructured``."""
        return as_node(self._drive(self._fragment(self.region.initial, self.exits, False)))

    # -- the driver: an explicit stack of generator frames ------------------------------------
    def _drive(self, task: Task) -> Fragment:
        stack: list[Task] = [task]
        value: Any = None
        while stack:
            try:
                name, ctx, entry = stack[-1].send(value)
            except StopIteration as done:
                stack.pop()
                value = done.value
                continue
            stack.append(self._fragment(name, ctx, entry))
            value = None
        return value  # type: ignore[no-any-return]

    # -- the rules ---------------------------------------------------------------------------
    def _fragment(self, name: str, ctx: Context, entry: bool) -> Task:
        if not entry and name in ctx:
            return ctx[name]
        if name not in self.units:  # a final state no context names: cannot happen
            raise Unstructured(f"state '{name}' is no state of the region")
        unit = self.units[name]
        if not entry and name in self.cyclic and self._reaches_itself(name, ctx):
            return (yield from self._loop(name, ctx))
        if len({t for t in unit.targets.values() if t not in ctx}) >= 2:
            joined = yield from self._join(name, ctx)
            if joined is not None:
                return joined
        return (yield from self._compose(unit, ctx))

    def _loop(self, head: str, ctx: Context) -> Task:
        forward = self._reach(head, ctx)
        back: dict[str, list[str]] = {}
        for x in forward:
            for t in self._open_targets(x, ctx):
                back.setdefault(t, []).append(x)
        body = {head}
        todo = [head]
        while todo:
            for p in back.get(todo.pop(), ()):
                if p not in body:
                    body.add(p)
                    todo.append(p)
        outs = {t for x in body for t in self.units[x].targets.values() if t not in body}
        for x in body:
            for outcome, target in self.units[x].targets.items():
                if target == head:
                    self.round_trips.add((self.units[x].path, outcome))
        terminals = [t for t in outs if t in ctx]
        units = [t for t in outs if t not in ctx]
        statuses = {ctx[t].status for t in terminals}
        if not units and statuses <= {FAILURE}:
            inner = yield (head, {**ctx, head: Term(SUCCESS)}, True)
            return decorator("KeepRunningUntilFailure", as_node(inner))
        if not units and statuses == {SUCCESS}:
            inner = yield (head, {**ctx, head: Term(FAILURE)}, True)
            return self._retry(as_node(inner))
        if len(units) == 1 and not terminals:
            (m,) = units
            inner = yield (head, {**ctx, head: Term(FAILURE), m: Term(SUCCESS)}, True)
            rest = yield (m, ctx, False)
            return sequence(self._retry(as_node(inner)), as_node(rest))
        ordered = [t for x in sorted(body, key=self.order.__getitem__)
                   for t in self.units[x].targets.values() if t in outs]  # fmt: skip
        return (yield from self._flag_loop(head, ctx, list(dict.fromkeys(ordered))))

    def _retry(self, body: BTNode) -> BTNode:
        """Run ``body`` again while it fails: ``RetryUntilSuccessful num_attempts=-1``, or its
        form that returns RUNNING each time it goes round (``yielding_loops``)."""
        if not self.yielding_loops:
            return decorator("RetryUntilSuccessful", body, num_attempts="-1")
        again = decorator("KeepRunningUntilFailure", decorator("Inverter", body))
        return decorator("Inverter", again)

    def _flag_loop(self, head: str, ctx: Context, outs: list[str]) -> Task:
        """A loop with several ways out: ``Sequence(Script flag:='', Fallback(
        KeepRunningUntilFailure(body), Switch(flag) -> each way out))``. Inside the body the
        loop head is SUCCESS (go round again) and every way out writes its name to the flag and
        fails, except the pure FAILURE terminals (the usual abort), which fail as they are and
        reach the Switch's default. One blackboard flag, named in the summary."""
        flag = f"loop_{type_id(head)}"
        inner_ctx = {**ctx, head: Term(SUCCESS)}
        named: list[tuple[str, str]] = []
        for index, t in enumerate(outs):
            if t in ctx and ctx[t].pure and ctx[t].status == FAILURE:
                continue
            value = t if _LITERAL.fullmatch(t) else f"exit{index}"
            inner_ctx[t] = Term(FAILURE, (flag, value))
            named.append((t, value))
        inner = yield (head, inner_ctx, True)
        cases: list[tuple[str, BTNode]] = []
        for t, value in named:
            fragment = ctx[t] if t in ctx else (yield (t, ctx, False))
            cases.append((value, as_node(fragment)))
        self.flags.append(
            f"state '{self.units[head].path}': a loop with {len(outs)} ways out (flag '{flag}')"
        )
        loop = decorator("KeepRunningUntilFailure", as_node(inner))
        ways_out = switch_chain(flag, cases, always(False))
        return control("Sequence", script(flag, ""), fallback(loop, ways_out))

    def _join(self, name: str, ctx: Context) -> Generator[Request, Fragment, Fragment | None]:
        region = self._reach(name, ctx)
        for status in (SUCCESS, FAILURE):
            m = self._post_dominator(name, region, ctx, status)
            if m is None:
                continue
            inner = yield (name, {**ctx, m: Term(status)}, True)
            rest = yield (m, ctx, False)
            combine = sequence if status == SUCCESS else fallback
            return combine(as_node(inner), as_node(rest))
        m = self._join_point(name, region, ctx)
        if m is None:
            return None
        # a join left early with SUCCESS: those ways out write a flag and fail instead
        flag = f"join_{type_id(m)}"
        inner_ctx = {**ctx, m: Term(SUCCESS)}
        cases: list[tuple[str, BTNode]] = []
        exits = self._exits_of(region, ctx)
        for index, t in enumerate(t for t in ctx if t in exits):
            if ctx[t].status == SUCCESS:
                value = t if _LITERAL.fullmatch(t) else f"exit{index}"
                inner_ctx[t] = Term(FAILURE, (flag, value))
                cases.append((value, ctx[t].node()))
        inner = yield (name, inner_ctx, True)
        rest = yield (m, ctx, False)
        self.flags.append(
            f"state '{self.units[name].path}': ways out before the join at '{m}' (flag '{flag}')"
        )
        joined = sequence(as_node(inner), as_node(rest))
        early = switch_chain(flag, cases, always(False))
        return control("Sequence", script(flag, ""), fallback(joined, early))

    def _compose(self, unit: Unit, ctx: Context) -> Task:
        if unit.name in self.emitted:
            raise Unstructured(
                f"state '{unit.path}' is reached from two places that no structured form joins"
            )
        self.emitted.add(unit.name)
        x = self.emit(unit)
        if unit.dispatch:
            return (yield from self._dispatch(unit, x, ctx))
        statuses = [
            s for s in (SUCCESS, FAILURE) if any(unit.status[o] == s for o in unit.outcomes)
        ]
        targets = {s: unit.target_of(s) for s in statuses}
        if len(set(targets.values())) == 1:
            rest = yield (next(iter(targets.values())), ctx, False)  # type: ignore[misc]
            if isinstance(rest, Term) and rest.pure:
                return x if statuses == [rest.status] else forced(x, rest.status)
            if len(statuses) == 2:
                return then(decorator("ForceSuccess", x), SUCCESS, rest)
            return then(x, statuses[0], rest)
        on_success = yield (targets[SUCCESS], ctx, False)  # type: ignore[misc]
        on_failure = yield (targets[FAILURE], ctx, False)  # type: ignore[misc]
        return branch(x, on_success, on_failure)

    def _dispatch(self, unit: Unit, x: BTNode, ctx: Context) -> Task:
        groups: dict[str, list[str]] = {}
        for outcome in unit.outcomes:
            groups.setdefault(unit.targets[outcome], []).append(outcome)
        default = max(groups, key=lambda t: (len(groups[t]), t not in ctx))
        cases: list[tuple[str, BTNode]] = []
        for target, outcomes in groups.items():
            if target == default:
                continue
            if target in ctx:
                cases.extend((o, ctx[target].node()) for o in outcomes)
                continue
            if len(outcomes) > 1:
                raise Unstructured(
                    f"state '{unit.path}': outcomes {', '.join(outcomes)} all lead to "
                    f"'{target}', which a Switch can reach from one case only"
                )
            fragment = yield (target, ctx, False)
            cases.append((outcomes[0], as_node(fragment)))
        rest = yield (default, ctx, False)
        return sequence(x, switch_chain(unit.key, cases, as_node(rest)))

    # -- graph helpers -----------------------------------------------------------------------
    def _open_targets(self, name: str, ctx: Context) -> list[str]:
        return [t for t in self.units[name].targets.values() if t not in ctx]

    def _reach(self, start: str, ctx: Context) -> set[str]:
        """Units reachable from ``start`` (included) without passing a terminal."""
        seen = {start}
        todo = [start]
        while todo:
            for t in self._open_targets(todo.pop(), ctx):
                if t not in seen:
                    seen.add(t)
                    todo.append(t)
        return seen

    def _reaches_itself(self, name: str, ctx: Context) -> bool:
        seen: set[str] = set()
        todo = self._open_targets(name, ctx)
        while todo:
            x = todo.pop()
            if x == name:
                return True
            if x not in seen:
                seen.add(x)
                todo.extend(self._open_targets(x, ctx))
        return False

    def _join_point(self, name: str, region: set[str], ctx: Context) -> str | None:
        """The first unit (in declaration order) that two ways from ``name`` reach and that
        splits the region in two: nothing before it is reached again after it."""
        preds: dict[str, int] = {}
        for x in region:
            for t in set(self._open_targets(x, ctx)):
                preds[t] = preds.get(t, 0) + 1
        for m in sorted(region, key=self.order.__getitem__):
            if m == name or preds.get(m, 0) < 2:
                continue
            before = self._reach(name, {**ctx, m: Term(SUCCESS)})
            after = self._reach(m, ctx)
            if m in before:
                before.discard(m)
            if not before & after and name not in after:
                return m
        return None

    def _exits_of(self, region: set[str], ctx: Context) -> set[str]:
        return {t for x in region for t in self.units[x].targets.values() if t in ctx}

    def _post_dominator(
        self, name: str, region: set[str], ctx: Context, status: str | None
    ) -> str | None:
        """The unit every path from ``name`` passes before a terminal with ``status``
        (``None``: before any terminal)."""
        reverse: nx.DiGraph[str] = nx.DiGraph()
        reverse.add_node(_END)
        for x in region:
            for t in self.units[x].targets.values():
                if t not in ctx:
                    reverse.add_edge(t, x)
                elif status is None or ctx[t].status == status:
                    reverse.add_edge(_END, x)
        if name not in reverse or not nx.has_path(reverse, _END, name):
            return None
        dominators = nx.immediate_dominators(reverse, _END)
        m = dominators.get(name)
        if m is None or m == _END or m == name or m in ctx:
            return None
        return m
