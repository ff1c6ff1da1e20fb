"""One local problem of the per-node decomposition as a self-contained SMV module (docs/nusmv.md,
"Trees node by node"; the problem: ``fsmbt.verify.pernode``, docs/semantics.md §4d).

Why: NuSMV's whole-tree encoding (``encode_bt``) gives up past a few dozen leaves; a tree
converted per node is proven by the native checker one node at a time. Here NuSMV decides the
same local problems, and its tree side is its own: the node's tick rules come from
``encode_bt.BTCore`` and the rule families (``families/``), run micro-step by micro-step over
abstract leaf children - never fsmbt's interpreter.

A unit module ``MODULE u<k>(inp)`` holds both sides and their comparison:

- *tree side*: the node N (its type and ports) over leaves ``c0..cn-1`` (an action when child
  i may return RUNNING, else a condition), encoded by ``BTCore``. Between ticks (``cur = TOP``)
  the input ``tick`` calls N; ``halt`` (when σ was settled with it) is N's parent resetting it
  from outside (``BTCore.build(root_reset=...)``: ``clr_0``, so ``hlt_0`` when N is RUNNING
  and the halt closure clears its children); at a leaf request of ``ci`` the input is one of
  the statuses child i may return. As the interpreter's ``tickOnce`` with ``exactly_once``,
  N's RUNNING is returned to the parent (its wake-up dropped) and a completed N has its
  status reset (``Tree::tickRoot``). Outputs of a step (input to the next stable point): the
  leaf requested (``t<i>``) or N's result mapped through σ to an exit token (``unp`` for a
  status σ does not pair), and per child the RUNNING halts (``th<i>``, the ``hlt`` defines
  summed over the step's micro-steps);
- *machine side*: N's fragment with each child replaced by its interface σ_i (the *result* of
  the conversion, so an explicit table is enough: ``pernode.LocalFragmentMachine`` explored
  breadth first, at most ``FRAGMENT_LIMIT`` configurations), its outputs per step: the child
  entered or the exit token, the halts of halting children that returned RUNNING last, and a
  flag for a halt of a child whose own halt was not proven;
- ``ok``: at every stable point the two steps' outputs agree - the event, the halts of the
  children whose subtree keeps values (``halting``) and the "unproven halt" flag (the tree's:
  a RUNNING halt of such a child). One ``INVARSPEC u<k>.ok`` per unit.

Offered inputs: the tree's position decides (between ticks, or child i's statuses); the two
sides are at the same position whenever their outputs agreed so far (a position changes only
with a ``t<i>`` output or a return). Cost: the tree side is O(children) rules; the table is
O(configurations · inputs) rows.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics.compiled import FAILURE, RUNNING, SUCCESS
from fsmbt.verify.abstract_node import abstract_tree as pernode_shape
from fsmbt.verify.nusmv.encode_bt import BTCore
from fsmbt.verify.nusmv.families.common import ST
from fsmbt.verify.nusmv.smv import Symbols, all_of, any_of, case, enum_type
from fsmbt.verify.pernode import (
    EVENTS,
    FSM_UNPROVEN_HALT,
    LocalFragmentMachine,
    LocalUnit,
    NotPerNode,
    exit_token,
)

#: Most configurations of one fragment's explicit table before the unit is refused: NuSMV
#: builds one BDD row per table step, and a 2 554-configuration table (a mutant's counter
#: without its guard) took ~100 s; the units of unmutated trees have a few dozen
#: (benchmarks/bench_nusmv_pernode.py counts the refusals).
FRAGMENT_LIMIT = 500
#: The shared input of every unit (``main``'s IVAR), by the local machines' input names:
#: between ticks, then a child's status (``pernode.EVENTS``).
INPUTS = {"tick": "tick", "halt": "halt", "success": "cS", "failure": "cF", "running": "cR"}
INPUT_ENUM = enum_type(list(INPUTS.values()), "in_pad")
_STATUS_SMV = {SUCCESS: ST["SUCCESS"], FAILURE: ST["FAILURE"], RUNNING: ST["RUNNING"]}


class UnitRefused(Exception):
    """A local problem NuSMV's per-node check does not encode (the message says why)."""


@dataclass
class UnitModule:
    """One unit's SMV module and what decoding its counterexample needs."""

    name: str
    text: str
    events: Symbols  # the event tokens (``t<i>``, ``e<k>``, ``none``, ``unp``) both ways
    leaf_ids: list[int]  # the abstract tree's node id of child i
    positions: dict[str, int | None] = field(default_factory=dict)  # cur value -> position


def abstract_tree(unit: LocalUnit) -> BTDocument:
    """The node over abstract leaves ``c0..`` (an action when child i may return RUNNING)."""
    allowed = unit.problem.allowed
    return pernode_shape(
        unit.problem.node, [RUNNING in a for a in allowed], [f"c{i}" for i in range(len(allowed))]
    )


def _fragment_table(
    unit: LocalUnit,
) -> tuple[list[tuple[int, str, int, tuple[str, ...]]], int]:
    """The fragment's steps ``(state, input, next state, outputs)`` from its start (state 0),
    breadth first, and the number of states.

    Raises:
        UnitRefused: past ``FRAGMENT_LIMIT`` configurations, or the fragment is not a
            machine (an eventless cycle).
    """
    machine = LocalFragmentMachine(unit.problem, unit.can_halt)
    start, _outputs = machine.start()
    ids: dict[Any, int] = {start: 0}
    order = [start]
    rows: list[tuple[int, str, int, tuple[str, ...]]] = []
    at = 0
    while at < len(order):
        state = order[at]
        for symbol in machine.inputs(state):
            try:
                nxt, outputs = machine.step(state, symbol)
            except NotPerNode as exc:
                raise UnitRefused(f"the fragment is not a machine: {exc}") from None
            if nxt not in ids:
                if len(ids) >= FRAGMENT_LIMIT:
                    raise UnitRefused(f"the fragment has more than {FRAGMENT_LIMIT} states")
                ids[nxt] = len(order)
                order.append(nxt)
            rows.append((at, symbol, ids[nxt], outputs))
        at += 1
    return rows, len(order)


def encode_unit(unit: LocalUnit, name: str) -> UnitModule:
    """``unit`` as ``MODULE name(inp)`` (the module docstring).

    Raises:
        UnitRefused: the node's kind is not encoded, it may return SKIPPED, or the fragment
            is refused (``_fragment_table``).
    """
    problem = unit.problem
    try:
        core = BTCore(abstract_tree(unit), loop=False)
    except UnsupportedError as exc:
        raise UnitRefused(str(exc)) from None
    if core.may_skip[0]:
        raise UnitRefused(f"{problem.node.type} may return SKIPPED")
    leaf_ids = [c for c in core.nodes[0].children]
    kids = len(leaf_ids)
    halting = problem.local.halting
    never = problem.never
    events = Symbols("ev")
    none, unpaired = events.id("none"), events.id("unp")
    for i in range(kids):
        events.id(f"tick {i}")

    core.declare(["TOP"], "TOP")
    top = "cur = TOP"
    offered: list[str] = []
    between = ["tick", "halt"] if unit.can_halt else ["tick"]
    offered.append(f"({top} & {any_of(f'inp = {INPUTS[s]}' for s in between)})")
    requests = [core.leaf_request(nid) for nid in leaf_ids]
    for i, req in enumerate(requests):
        allowed = problem.allowed[i]
        offered.append(f"({req} & {any_of(f'inp = {INPUTS[EVENTS[s]]}' for s in allowed)})")
    go = "go"
    ticked = f"{go} & {top} & inp = tick"
    halted = f"{go} & {top} & inp = halt"
    # a completed N had its status reset when it returned (``Tree::tickRoot``): done at the
    # next input, before anything reads it; the wake-up is the parent's business
    completed = f"{go} & {top} & (res = S | res = F)"
    core.rules.setdefault(core.st(0), []).append((completed, "I"))
    core.rule("wake", top, "FALSE")
    core.call(ticked, 0)
    core.rule("res", halted, "NONE")
    for i, (nid, req) in enumerate(zip(leaf_ids, requests)):
        for status in problem.allowed[i]:
            symbol = INPUTS[EVENTS[status]]
            core.ret(f"{go} & {req} & inp = {symbol}", nid, _STATUS_SMV[status])
    core.build(root_reset=halted if unit.can_halt else None)
    # the tree side's step outputs
    for i, nid in enumerate(leaf_ids):
        var = f"th{i}"
        core.var_types[var] = "boolean"
        core.init[var] = "FALSE"
        core.rules[var] = [(go, f"hlt_{nid}"), ("TRUE", f"({var} | hlt_{nid})")]
    tree_event = [(req, events.id(f"tick {i}")) for i, req in enumerate(requests)]
    for status, smv in _STATUS_SMV.items():
        token = exit_token(unit.sigma[status]) if status in unit.sigma else None
        value = events.id(token) if token is not None else unpaired
        tree_event.append((f"{top} & res = {smv}", value))
    # the machine side: the fragment's explicit table
    rows, states = _fragment_table(unit)
    frag_q: list[tuple[str, str]] = []
    frag_e: list[tuple[str, str]] = []
    frag_h: list[list[tuple[str, str]]] = [[] for _ in range(kids)]
    frag_b: list[tuple[str, str]] = []
    for source, symbol, target, outputs in rows:
        guard = f"{go} & q = {source} & inp = {INPUTS[symbol]}"
        frag_q.append((guard, str(target)))
        event = none
        for item in outputs:
            if item.startswith("tick "):
                event = events.id(item)
            elif item.startswith("exit "):
                event = events.id(item)
        frag_e.append((guard, event))
        halts = {int(item.split()[1]) for item in outputs if item.startswith("halt ")}
        for i in range(kids):
            frag_h[i].append((guard, "TRUE" if i in halts else "FALSE"))
        frag_b.append((guard, "TRUE" if FSM_UNPROVEN_HALT in outputs else "FALSE"))
    core.var_types["q"] = f"0..{max(states - 1, 1)}"
    core.init["q"] = "0"
    core.rules["q"] = frag_q
    event_enum = events.enum()
    core.var_types["fe"] = event_enum
    core.init["fe"] = none
    core.rules["fe"] = frag_e + [(go, none)]
    for i in range(kids):
        core.var_types[f"fh{i}"] = "boolean"
        core.init[f"fh{i}"] = "FALSE"
        core.rules[f"fh{i}"] = frag_h[i] + [(go, "FALSE")]
    core.var_types["fb"] = "boolean"
    core.init["fb"] = "FALSE"
    core.rules["fb"] = frag_b + [(go, "FALSE")]
    tree_bad = any_of(f"th{i}" for i in range(kids) if i in never)
    agree = all_of(
        [
            "te = fe",
            *(f"(th{i} <-> fh{i})" for i in range(kids) if i in halting),
            f"({tree_bad} <-> fb)",
        ]
    )
    stable = any_of([top, *requests])
    defines = [
        ("stable", stable),
        ("go", f"(stable & {any_of(offered)})"),
        ("te", case(tree_event, none)),
        ("ok", f"(stable -> {agree})"),
    ]
    text = core.emit(name, "inp", defines)
    # decode: the position a stable ``cur`` stands for
    positions: dict[str, int | None] = {"TOP": None}
    for i, nid in enumerate(leaf_ids):
        positions[core.n(nid)] = i
    return UnitModule(name, text, events, leaf_ids, positions)


def event_word(unit: LocalUnit, token: str) -> str:
    """An event token in the user's words: the child entered, or the exit σ pairs it with
    (the statuses of N that σ maps to it)."""
    if token == "none":
        return "nothing"
    if token == "unp":
        return "a status of the node that σ does not pair (unpaired when the walk failed)"
    if token.startswith("tick "):
        i = int(token.split()[1])
        return f"child {i} ('{unit.child_labels[i]}') is ticked"
    statuses = [EVENTS[s] for s, e in sorted(unit.sigma.items()) if exit_token(e) == token]
    named = "/".join(statuses) if statuses else "no status of the tree"
    return f"the node exits ({token}; σ: {named})"


def input_word(unit: LocalUnit, position: int | None, symbol: str) -> str:
    """An input in the user's words: ``tick``/``halt`` between ticks, a child's status."""
    if position is None:
        return symbol
    return f"child {position} ('{unit.child_labels[position]}') returns {symbol}"
