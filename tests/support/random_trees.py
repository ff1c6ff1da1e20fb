"""Random behavior trees and LEBT building blocks for tests (several helpers use them).

- ``random_tree(rng, ...)``: a seeded random ``BTDocument`` over every node type the
  interpreter supports (optionally restricted, e.g. to py_trees' subset), with valid parameters.
- ``bt_documents(...)``: the same as a hypothesis strategy (draws a seed).
- ``OutcomeScript``: a deterministic environment: per leaf path, a cycle of outcomes.
- ``lebt_from_structure(fsm, structure)``: an LEBT built from a hand-written nesting of states
  (docs/conversion.md, 'FSM -> BT'); guard pairs and state leaves are filled in from the FSM, the shape is the
  caller's. Used to test the runtime independently of the real converter.
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from dataclasses import dataclass, field

from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM
from fsmbt.semantics.lebt.spec import (
    DEFAULT_START,
    GUARD_TYPE,
    NO_EVENT,
    STATE_TYPE,
    GuardSpec,
    StateSpec,
)

ALL_CONTROLS = (
    "Sequence",
    "ReactiveSequence",
    "SequenceWithMemory",
    "Fallback",
    "ReactiveFallback",
    "Parallel",
    "ParallelAll",
    "IfThenElse",
    "WhileDoElse",
)
ALL_DECORATORS = (
    "Inverter",
    "ForceSuccess",
    "ForceFailure",
    "Repeat",
    "RetryUntilSuccessful",
    "KeepRunningUntilFailure",
    "RunOnce",
    "SubTree",
)
ALL_LEAVES = ("Action", "Condition", "AlwaysSuccess", "AlwaysFailure")
PYTREES_CONTROLS = ("Sequence", "ReactiveSequence", "Fallback", "ReactiveFallback")
PYTREES_DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure")
ALL_NODE_TYPES = ALL_CONTROLS + ALL_DECORATORS + ALL_LEAVES


#: The leaf kinds drawn by default (Action and Condition twice as often as the constants).
LEAVES = ("Action", "Condition", "Action", "Condition", "AlwaysSuccess", "AlwaysFailure")


@dataclass
class TreeGenerator:
    """Grows one random tree (``document``) from the kinds it is given; a generator for another
    node class subclasses it and overrides ``node`` (tests/semantics/test_sem_leaf_canonical_nav2)."""

    rng: random.Random
    controls: Sequence[str]
    decorators: Sequence[str]
    leaves: Sequence[str]
    max_nodes: int
    counter: int = 0
    subtrees: dict[str, BTNode] = field(default_factory=dict)

    def leaf(self) -> BTNode:
        self.counter += 1
        kind = self.rng.choice(self.leaves)
        if kind == "Action":
            return BTNode(f"Act{self.counter % 3}", NodeKind.ACTION, name=f"a{self.counter}")
        if kind == "Condition":
            return BTNode(f"Cond{self.counter % 3}", NodeKind.CONDITION, name=f"c{self.counter}")
        return BTNode(kind, NodeKind.ACTION)

    def node(self, depth: int) -> BTNode:
        """Grow a node; the size budget keeps trees small (no recursion hazard: depth ≤ 6)."""
        self.counter += 1
        if depth >= 5 or self.counter >= self.max_nodes or self.rng.random() < 0.3:
            return self.leaf()
        if self.decorators and self.rng.random() < 0.35:
            t = self.rng.choice(self.decorators)
            child = self.node(depth + 1)
            if t == "SubTree":
                sub_id = f"Sub{len(self.subtrees)}"
                self.subtrees[sub_id] = child
                return BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": sub_id})
            attrs: dict[str, str] = {}
            if t == "Repeat":
                attrs["num_cycles"] = str(self.rng.choice([0, 1, 2, 3, -1]))
            elif t == "RetryUntilSuccessful":
                attrs["num_attempts"] = str(self.rng.choice([0, 1, 2, 3, -1]))
            elif t == "RunOnce":
                attrs["then_skip"] = self.rng.choice(["true", "false"])
            return BTNode(t, NodeKind.DECORATOR, attrs=attrs, children=[child])
        t = self.rng.choice(self.controls)
        if t in ("IfThenElse", "WhileDoElse"):
            n = self.rng.choice([2, 3])
        else:
            n = self.rng.randint(1, 4)
        children = [self.node(depth + 1) for _ in range(n)]
        attrs = {}
        if t == "Parallel":
            attrs["success_count"] = str(
                self.rng.choice([v for v in range(-n - 1, n + 1) if v < 0 or v <= n])
            )
            attrs["failure_count"] = str(
                self.rng.choice([v for v in range(-n - 1, n + 1) if v < 0 or v <= n])
            )
        elif t == "ParallelAll":
            attrs["max_failures"] = str(
                self.rng.choice([v for v in range(-n - 1, n + 1) if v < 0 or v <= n])
            )
        return BTNode(t, NodeKind.CONTROL, attrs=attrs, children=children)

    def document(self) -> BTDocument:
        """The main tree grown from the root, plus one tree per SubTree occurrence."""
        doc = BTDocument.single(self.node(0))
        for sub_id, sub_root in self.subtrees.items():
            doc.trees[sub_id] = BehaviorTree(sub_id, sub_root)
        return doc


def random_tree(
    rng: random.Random,
    *,
    controls: Sequence[str] = ALL_CONTROLS,
    decorators: Sequence[str] = ALL_DECORATORS,
    leaves: Sequence[str] = LEAVES,
    max_nodes: int = 14,
) -> BTDocument:
    """A random document (main tree ``MainTree`` plus one tree per SubTree occurrence)."""
    return TreeGenerator(rng, controls, decorators, leaves, max_nodes).document()


def bt_documents(**kwargs):
    """Hypothesis strategy of random documents (seeded, so shrinking is by seed)."""
    from hypothesis import strategies as st

    return st.integers(min_value=0, max_value=2**32 - 1).map(
        lambda seed: random_tree(random.Random(seed), **kwargs)
    )


class OutcomeScript:
    """A deterministic environment: leaf at ``path`` returns the outcomes of a seeded cycle.

    Conditions never return ``running``. Every call is recorded in ``calls``.
    """

    def __init__(self, seed: int, *, running_weight: float = 0.3, length: int = 7) -> None:
        self.seed = seed
        self.running_weight = running_weight
        self.length = length
        self._plans: dict[str, list[str]] = {}
        self._next: dict[str, int] = {}
        self.calls: list[tuple[str, str]] = []

    def _plan(self, path: str, condition: bool) -> list[str]:
        key = f"{path}|{int(condition)}"
        plan = self._plans.get(key)
        if plan is None:
            rng = random.Random(f"{self.seed}:{key}")
            plan = []
            for _ in range(self.length):
                if not condition and rng.random() < self.running_weight:
                    plan.append("running")
                else:
                    plan.append(rng.choice(["success", "failure"]))
            self._plans[key] = plan
        return plan

    def __call__(self, node: BTNode, path: str) -> str:
        plan = self._plan(path, node.kind is NodeKind.CONDITION)
        i = self._next.get(path, 0)
        self._next[path] = i + 1
        outcome = plan[i % len(plan)]
        self.calls.append((path, outcome))
        return outcome

    def fresh(self) -> OutcomeScript:
        """The same script from its beginning (to replay in another engine)."""
        return OutcomeScript(self.seed, running_weight=self.running_weight, length=self.length)


# -- hand-built LEBTs ------------------------------------------------------------------------
#: A selector subtree: a state and its nested selector subtrees (its in-degree-1 successors).
Structure = tuple[str, list["Structure"]]


def lebt_from_structure(fsm: FSM, structure: Sequence[Structure]) -> BTDocument:
    """Root ``Sequence`` of ``Fallback(guard, body)`` per top-level entry; body = the state
    leaf alone, or ``Sequence(state leaf, selector subtrees...)`` (docs/conversion.md, 'FSM -> BT').

    Guard pairs are every transition into the state, plus the start pair for the initial state
    (``(start, initial_event)``, or ``(start, "")`` without an initial event).
    """
    start = fsm.start_name or DEFAULT_START
    exits: dict[str, list[str]] = {name: [] for name in fsm.states}
    entering: dict[str, list[tuple[str, str]]] = {name: [] for name in fsm.states}
    if fsm.initial is not None:
        entering[fsm.initial].append((start, fsm.initial_event or NO_EVENT))
    for t in fsm.transitions:
        assert t.event is not None, "hand-built LEBTs take plain FSMs"
        if t.event not in exits[t.source]:
            exits[t.source].append(t.event)
        entering[t.target].append((t.source, t.event))

    def selector(item: Structure) -> BTNode:
        """Iterative build (explicit stack) of one selector subtree."""
        made: dict[int, BTNode] = {}
        order: list[Structure] = []
        stack = [item]
        while stack:
            cur = stack.pop()
            order.append(cur)
            stack.extend(cur[1])
        for cur in reversed(order):
            name, kids = cur
            state = fsm.states[name]
            guard = BTNode(
                GUARD_TYPE,
                NodeKind.CONDITION,
                name=f"Guard_{name}",
                attrs=GuardSpec(name, tuple(entering[name])).to_attrs(),
            )
            leaf = BTNode(
                STATE_TYPE,
                NodeKind.ACTION,
                name=f"State_{name}",
                attrs=StateSpec(name, state.action, state.final, tuple(exits[name])).to_attrs(),
            )
            body = (
                leaf
                if not kids
                else BTNode(
                    "Sequence", NodeKind.CONTROL, children=[leaf] + [made[id(k)] for k in kids]
                )
            )
            made[id(cur)] = BTNode("Fallback", NodeKind.CONTROL, children=[guard, body])
        return made[id(item)]

    root = BTNode("Sequence", NodeKind.CONTROL, children=[selector(s) for s in structure])
    return BTDocument.single(root, tree_id="LEBT")
