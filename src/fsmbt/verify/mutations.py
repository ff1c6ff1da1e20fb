"""Single mutations of FSMs and BTs, to show the checker is not vacuous (issue 3, item 6).

Each operator makes one small change a buggy converter (or LLM) could make; ``mutants(model)``
enumerates them deterministically (a seeded sample of at most ``per_operator`` per operator).
A mutant need not behave differently (swapping two children that never run is harmless): the
mutation tests decide that by random simulation and check the checker agrees.

FSM operators: ``retarget_transition``, ``drop_transition``, ``change_action``, ``flip_final``.
BT operators: ``swap_children``, ``sequence_to_fallback`` (and ``fallback_to_sequence``),
``invert_condition`` (wrap a condition in an ``Inverter``), ``drop_leaf``, ``change_action``
(a leaf's label, or an LEBT state leaf's action), and for LEBTs ``drop_guard_pair``,
``retarget_transition`` (move a guard pair to another state's guard) and ``flip_final``.

Every BT mutant is a valid tree: a kind is read from its declaration (``fsmbt.model.nodes``,
``NodeSemantics``: family, result map, arity), never from a type-name literal, and a child is
dropped only where the parent's declared arity (``allows_children``) admits one child fewer -
the arity ``fsmbt.model.validate`` and the verifier's own Switch check read (a ``Switch``'s
count is fixed: its cases and a default).

Complexity: O(M · N) for M mutants of a model of size N (each mutant is a deep copy).
"""

from __future__ import annotations

import copy
import random
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE, GuardSpec, StateSpec
from fsmbt.semantics.nodes import (
    FALLBACK_TYPES,
    PLAIN_CONTROLS,
    RESULT_MAP_DECORATORS,
    node_semantics,
)
from fsmbt.semantics.status import RootResult

Model = FSM | BTDocument


@dataclass
class Mutant:
    operator: str
    description: str
    model: Model


# -- FSM ------------------------------------------------------------------------------------------
def _fsm_candidates(fsm: FSM) -> Iterator[tuple[str, str, Callable[[FSM], None]]]:
    names = list(fsm.states)
    for index, t in enumerate(fsm.transitions):
        for target in names:
            if target != t.target:

                def retarget(m: FSM, i: int = index, to: str = target) -> None:
                    m.transitions[i].target = to

                yield (
                    "retarget_transition",
                    f"{t.source} -{t.event}-> {t.target} now goes to {target}",
                    retarget,
                )

        def drop(m: FSM, i: int = index) -> None:
            del m.transitions[i]

        yield "drop_transition", f"dropped {t.source} -{t.event}-> {t.target}", drop
    for name, state in fsm.states.items():

        def relabel(m: FSM, n: str = name) -> None:
            m.states[n].action = f"{m.states[n].action}_mutated"

        yield "change_action", f"action of {name} changed", relabel

        def flip(m: FSM, n: str = name) -> None:
            m.states[n].final = not m.states[n].final

        yield "flip_final", f"final flag of {name} flipped to {not state.final}", flip


# -- BT -------------------------------------------------------------------------------------------
def _bt_candidates(doc: BTDocument) -> Iterator[tuple[str, str, Callable[[list[BTNode]], None]]]:
    nodes = [node for _tree, node in doc.nodes()]
    # pre-order positions are the same in a deep copy: parents are found by position
    position = {id(node): i for i, node in enumerate(nodes)}
    parent_at: dict[int, int] = {}
    for i, node in enumerate(nodes):
        for child in node.children:
            parent_at[position[id(child)]] = i
    guards = [i for i, n in enumerate(nodes) if n.type == GUARD_TYPE]
    for i, node in enumerate(nodes):
        label = node.label
        if node.kind is NodeKind.CONTROL and len(node.children) >= 2:
            for a in range(len(node.children) - 1):

                def swap(ns: list[BTNode], i: int = i, a: int = a) -> None:
                    kids = ns[i].children
                    kids[a], kids[a + 1] = kids[a + 1], kids[a]

                yield "swap_children", f"children {a} and {a + 1} of {label} swapped", swap
        other = _counterpart(node)
        if other is not None:  # the paper's two controls swap into each other

            def turn(ns: list[BTNode], i: int = i, other: str = other) -> None:
                ns[i].type = other

            operator = (
                "fallback_to_sequence" if node.type in FALLBACK_TYPES else "sequence_to_fallback"
            )
            yield operator, f"{label} ({node.type}) turned into a {other}", turn
        inverter = _inverter()
        if node.kind is NodeKind.CONDITION and inverter is not None:

            def invert(ns: list[BTNode], i: int = i, inverter: str = inverter) -> None:
                parent = ns[parent_at[i]]
                wrapper = BTNode(type=inverter, kind=NodeKind.DECORATOR, children=[ns[i]])
                parent.children[_index_of(parent, ns[i])] = wrapper

            if i in parent_at:
                yield "invert_condition", f"condition {label} wrapped in an {inverter}", invert
        if node.is_leaf and i in parent_at:
            parent = nodes[parent_at[i]]
            if parent.kind is NodeKind.CONTROL and _may_lose_a_child(parent):

                def drop(ns: list[BTNode], i: int = i) -> None:
                    parent = ns[parent_at[i]]
                    del parent.children[_index_of(parent, ns[i])]

                yield "drop_leaf", f"leaf {label} dropped", drop
        if node.type == STATE_TYPE:
            spec = StateSpec.from_attrs(node.attrs)

            def relabel_state(ns: list[BTNode], i: int = i) -> None:
                ns[i].attrs["action"] = f"{ns[i].attrs.get('action', '')}_mutated"

            yield "change_action", f"action of state leaf {label} changed", relabel_state

            def flip(ns: list[BTNode], i: int = i) -> None:
                ns[i].attrs["final"] = "false" if ns[i].attrs.get("final") == "true" else "true"

            yield (
                "flip_final",
                f"final flag of state leaf {label} flipped to {not spec.final}",
                flip,
            )
        elif node.is_leaf and node.type != GUARD_TYPE:

            def relabel(ns: list[BTNode], i: int = i) -> None:
                ns[i].name = f"{ns[i].label}_mutated"

            yield "change_action", f"leaf {label} renamed", relabel
        if node.type == GUARD_TYPE:
            guard = GuardSpec.from_attrs(node.attrs)
            for k, pair in enumerate(guard.pairs):

                def drop_pair(ns: list[BTNode], i: int = i, k: int = k) -> None:
                    old = GuardSpec.from_attrs(ns[i].attrs)
                    pairs = old.pairs[:k] + old.pairs[k + 1 :]
                    ns[i].attrs.update(GuardSpec(old.target, pairs).to_attrs())

                yield "drop_guard_pair", f"pair {pair[0]}/{pair[1]} dropped from {label}", drop_pair
                for j in guards:
                    if j == i:
                        continue

                    def move_pair(ns: list[BTNode], i: int = i, k: int = k, j: int = j) -> None:
                        old = GuardSpec.from_attrs(ns[i].attrs)
                        moved = old.pairs[k]
                        ns[i].attrs.update(
                            GuardSpec(old.target, old.pairs[:k] + old.pairs[k + 1 :]).to_attrs()
                        )
                        dest = GuardSpec.from_attrs(ns[j].attrs)
                        ns[j].attrs.update(GuardSpec(dest.target, dest.pairs + (moved,)).to_attrs())

                    yield (
                        "retarget_transition",
                        f"pair {pair[0]}/{pair[1]} moved from {label} to {nodes[j].label}",
                        move_pair,
                    )


def _may_lose_a_child(parent: BTNode) -> bool:
    """Whether ``parent`` stays a valid node with one child fewer: the arity its kind declares
    (``NodeSemantics.allows_children``: an exact count such as a ``Switch``'s cases and default,
    a set of counts, or a least count; the rule ``fsmbt.model.validate`` applies) and never
    none (BehaviorTree.CPP's loader refuses a control without children). A kind without a
    declaration (a custom control) keeps at least one child."""
    count = len(parent.children)
    spec = node_semantics(parent.type)
    return count >= 2 and (spec is None or spec.allows_children(count - 1))


def _counterpart(node: BTNode) -> str | None:
    """The plain control of the other family (sequence <-> fallback) that ``node``, a plain
    control, turns into, read from the declarations (``None``: not a plain control, or no
    counterpart whose arity admits the node's children)."""
    spec = node_semantics(node.type)
    if spec is None or node.type not in PLAIN_CONTROLS:
        return None
    for kind in sorted(PLAIN_CONTROLS):
        other = node_semantics(kind)
        if (
            other is not None
            and (kind in FALLBACK_TYPES) != (node.type in FALLBACK_TYPES)
            and other.allows_children(len(node.children))
        ):
            return kind
    return None


def _inverter() -> str | None:
    """The declared decorator that swaps SUCCESS and FAILURE (its ``result_map``)."""
    swapped = (RootResult.FAILURE.value, RootResult.SUCCESS.value)
    for kind in sorted(RESULT_MAP_DECORATORS):
        spec = node_semantics(kind)
        if spec is not None and spec.result_map == swapped:
            return kind
    return None


def _index_of(parent: BTNode, child: BTNode) -> int:
    """Position by identity (``list.index`` compares dataclasses by value)."""
    return next(k for k, c in enumerate(parent.children) if c is child)


# -- enumeration ----------------------------------------------------------------------------------
def mutants(model: Model, *, seed: int = 0, per_operator: int | None = 4) -> list[Mutant]:
    """Single mutants of ``model``: at most ``per_operator`` per operator (``None`` = all),
    sampled with ``seed``; the original is never modified."""
    rng = random.Random(seed)
    # each apply takes the FSM copy or the BT copy's node list, as its enumerator built it
    candidates: list[tuple[str, str, Callable[[Any], None]]]
    if isinstance(model, FSM):
        candidates = list(_fsm_candidates(model))
    else:
        candidates = list(_bt_candidates(model))
    by_operator: dict[str, list[int]] = {}
    for index, (operator, _description, _apply) in enumerate(candidates):
        by_operator.setdefault(operator, []).append(index)
    chosen: list[int] = []
    for indices in by_operator.values():
        if per_operator is not None and len(indices) > per_operator:
            indices = sorted(rng.sample(indices, per_operator))
        chosen.extend(indices)
    out: list[Mutant] = []
    for index in sorted(chosen):
        operator, description, apply = candidates[index]
        copied = copy.deepcopy(model)
        if isinstance(copied, FSM):
            apply(copied)
        else:
            apply([node for _tree, node in copied.nodes()])
        out.append(Mutant(operator, description, copied))
    return out


OPERATORS = (
    "retarget_transition",
    "drop_transition",
    "change_action",
    "flip_final",
    "swap_children",
    "sequence_to_fallback",
    "fallback_to_sequence",
    "invert_condition",
    "drop_leaf",
    "drop_guard_pair",
)
