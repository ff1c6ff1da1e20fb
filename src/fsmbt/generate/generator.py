"""Seeded, reproducible random FSMs and BTs within the paper's limits.

- ``random_fsm``: deterministic FSMs of 2-30 states (by default) built from a spanning structure
  (chains and branches from the initial state, so every state is reachable) plus extra edges
  (back edges = loops, self-loops, cross edges = shared targets). A state with no way out is
  final. Half of the machines (by default) start from a ``Start`` pseudo-state with an initial
  event, as the paper's XML does.
- ``random_bt``: trees of depth and breadth 2-10 (by default) of Sequence, Fallback, Action and
  Condition; ``extended=True`` adds ReactiveSequence, ReactiveFallback, SequenceWithMemory,
  Parallel and the decorators Inverter, ForceSuccess, ForceFailure, Repeat,
  RetryUntilSuccessful, KeepRunningUntilFailure and RunOnce. Depth counts node levels (root = 1;
  decorators occupy a level); breadth is the largest child count (the root has exactly
  ``breadth`` children; one root-to-leaf path has exactly ``depth`` levels).

Same seed, same arguments -> the same model, on every machine (``random.Random`` seeded with an
int or a string is platform-independent). Building is iterative: sizes are not limited by
Python's recursion limit (``random_bt(..., max_nodes=100_000)`` serves the benchmarks).
Complexity: O(n) in the number of states + transitions / nodes.
"""

from __future__ import annotations

import random
from collections import deque

from fsmbt.generate.vocab import SCENARIOS, letters, numbered, vocabulary
from fsmbt.model.bt import BTDocument, BTNode, NodeModel
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM, State

Seed = int | str | random.Random | None

FSM_SHAPES = ("mixed", "chain", "tree", "loop")
PAPER_CONTROLS = ("Sequence", "Fallback")
EXTENDED_CONTROLS = (
    "Sequence",
    "Fallback",
    "ReactiveSequence",
    "ReactiveFallback",
    "SequenceWithMemory",
    "Parallel",
)
_EXTENDED_WEIGHTS = (3, 3, 1, 1, 1, 0.7)
DECORATORS = (
    "Inverter",
    "ForceSuccess",
    "ForceFailure",
    "Repeat",
    "RetryUntilSuccessful",
    "KeepRunningUntilFailure",
    "RunOnce",
)
MAX_OUT_DEGREE = 4


def make_rng(seed: Seed) -> random.Random:
    """A ``random.Random`` from an int/str seed (or the given generator itself)."""
    if isinstance(seed, random.Random):
        return seed
    return random.Random(seed)


def _check_scenario(scenario: str) -> None:
    if scenario not in SCENARIOS:
        raise ValueError(f"unknown scenario {scenario!r} (known: {', '.join(SCENARIOS)})")


# -- FSMs -----------------------------------------------------------------------------------------
def random_fsm(
    seed: Seed = None,
    n_states: int | None = None,
    scenario: str = "basic",
    *,
    shape: str = "mixed",
    min_states: int = 2,
    max_states: int = 30,
    start_event: bool | None = None,
    extra_edges: int | None = None,
) -> FSM:
    """A random deterministic FSM (see the module docstring).

    ``n_states`` defaults to a draw in ``[min_states, max_states]``; ``shape`` biases the
    structure (``chain``: each state follows the previous one; ``tree``: random parents;
    ``loop``: a chain with many back edges; ``mixed``: all of these); ``start_event`` forces
    (True) or forbids (False) a start pseudo-state with an initial event; ``extra_edges`` fixes
    the number of extra edges tried (default: random, up to ``n_states``).
    """
    _check_scenario(scenario)
    if shape not in FSM_SHAPES:
        raise ValueError(f"unknown shape {shape!r} (known: {', '.join(FSM_SHAPES)})")
    rng = make_rng(seed)
    n = n_states if n_states is not None else rng.randint(min_states, max_states)
    if n < 1:
        raise ValueError("an FSM needs at least one state")
    vocab = vocabulary(scenario)
    basic = scenario == "basic"
    names = [numbered(vocab.states, i, basic=basic) for i in range(n)]

    targets: list[list[int]] = [[] for _ in range(n)]  # out-edges in creation order
    for i in range(1, n):
        if shape == "chain" or shape == "loop":
            parent = i - 1
        elif shape == "tree":
            parent = rng.randrange(i)
        else:
            parent = i - 1 if rng.random() < 0.55 else rng.randrange(i)
        targets[parent].append(i)

    if extra_edges is None:
        if shape == "loop":
            extra_edges = n // 2 + 1
        elif shape == "mixed":
            extra_edges = rng.randint(0, n)
        else:
            extra_edges = rng.randint(0, max(1, n // 3))
    for _ in range(extra_edges):
        source = rng.randrange(n)
        kind = rng.choice(("back", "self", "cross")) if shape != "loop" else "back"
        if kind == "back":
            target = rng.randrange(source + 1)
        elif kind == "self":
            target = source
        else:
            target = rng.randrange(n)
        if target in targets[source] or len(targets[source]) >= MAX_OUT_DEGREE:
            continue
        targets[source].append(target)

    fsm = FSM(name=f"{scenario}_fsm")
    for i, name in enumerate(names):
        fsm.add_state(State(name, action=name, final=not targets[i]))
    fsm.initial = names[0]
    for source, outs in enumerate(targets):
        if basic:
            events = [f"event{names[source]}{names[t]}" for t in outs]
        else:
            events = rng.sample(vocab.events, len(outs))
        for target, event in zip(outs, events):
            fsm.add_transition(names[source], event, names[target])
    if start_event is None:
        start_event = rng.random() < 0.5
    if start_event:
        fsm.start_name = "Start"
        fsm.initial_event = f"eventS{names[0]}" if basic else "start"
    return fsm


# -- BTs ------------------------------------------------------------------------------------------
class _BTBuilder:
    """Breadth-first builder that keeps a node budget and one path of exactly ``depth`` levels."""

    def __init__(
        self,
        rng: random.Random,
        depth: int,
        breadth: int,
        scenario: str,
        extended: bool,
        max_nodes: int,
        condition_ratio: float,
    ) -> None:
        self.rng = rng
        self.depth = depth
        self.breadth = breadth
        self.vocab = vocabulary(scenario)
        self.basic = scenario == "basic"
        self.extended = extended
        self.max_nodes = max_nodes
        self.condition_ratio = condition_ratio
        self.count = 0
        self.uses: dict[str, int] = {}
        self.leaf_kinds: dict[str, NodeKind] = {}
        self.next_symbol = {NodeKind.ACTION: 0, NodeKind.CONDITION: 0}

    # node factories -------------------------------------------------------------------------
    def control(self, *, parallel: bool = True) -> BTNode:
        self.count += 1
        kinds: tuple[str, ...]
        weights: tuple[float, ...]
        if self.extended:
            kinds, weights = EXTENDED_CONTROLS, _EXTENDED_WEIGHTS
            if not parallel:
                kinds, weights = kinds[:-1], weights[:-1]
            kind = self.rng.choices(kinds, weights)[0]
        else:
            kind = self.rng.choice(PAPER_CONTROLS)
        return BTNode(type=kind, kind=NodeKind.CONTROL)

    def decorator(self) -> BTNode:
        self.count += 1
        kind = self.rng.choice(DECORATORS)
        attrs: dict[str, str] = {}
        if kind == "Repeat":
            attrs["num_cycles"] = str(self.rng.randint(2, 3))
        elif kind == "RetryUntilSuccessful":
            attrs["num_attempts"] = str(self.rng.randint(2, 3))
        return BTNode(type=kind, kind=NodeKind.DECORATOR, attrs=attrs)

    def leaf(self) -> BTNode:
        self.count += 1
        kind = NodeKind.CONDITION if self.rng.random() < self.condition_ratio else NodeKind.ACTION
        words = self.vocab.conditions if kind is NodeKind.CONDITION else self.vocab.actions
        if self.basic:
            index = self.next_symbol[kind]
            self.next_symbol[kind] += 1
            word = words[index % len(words)]
        else:
            word = self.rng.choice(words)
        used = self.uses.get(word, 0)
        self.uses[word] = used + 1
        self.leaf_kinds[word] = kind
        name = None if used == 0 else f"{word}_{used + 1}"
        return BTNode(type=word, kind=kind, name=name)

    # structure --------------------------------------------------------------------------------
    def child(self, level: int, spine: bool) -> tuple[BTNode, BTNode | None, int]:
        """A child at ``level``: (node to attach, control node to expand or None, its level)."""
        make_control = spine or (
            level < self.depth and self.count < self.max_nodes and self.rng.random() < 0.3
        )
        decorate = self.extended and self.rng.random() < 0.2
        if decorate:
            # the decorated node sits one level lower; it must still fit in ``depth``
            decorate = level + 1 < self.depth if make_control else level + 1 <= self.depth
        if make_control:
            inner = self.control()
            if decorate:
                top = self.decorator()
                top.children.append(inner)
                return top, inner, level + 1
            return inner, inner, level
        leaf = self.leaf()
        if decorate:
            top = self.decorator()
            top.children.append(leaf)
            return top, None, level
        return leaf, None, level

    def build(self) -> BTNode:
        root = self.control(parallel=False)  # the root alone has exactly ``breadth`` children
        queue: deque[tuple[BTNode, int, bool]] = deque([(root, 1, self.depth > 2)])
        while queue:
            node, level, spine = queue.popleft()
            if node is root:
                n_children = self.breadth
            elif self.count >= self.max_nodes:
                n_children = 2
            else:
                n_children = self.rng.randint(min(2, self.breadth), self.breadth)
            if node.type == "Parallel":  # keeps the product of running children small
                n_children = min(n_children, 3)
            spine_index = self.rng.randrange(n_children) if spine else -1
            for index in range(n_children):
                continue_spine = index == spine_index
                top, expand, expand_level = self.child(level + 1, continue_spine)
                node.children.append(top)
                if expand is not None:
                    queue.append(
                        (expand, expand_level, continue_spine and expand_level + 1 < self.depth)
                    )
            if node.type == "Parallel":
                n = len(node.children)
                node.attrs["success_count"] = str(self.rng.randint(1, n))
                node.attrs["failure_count"] = str(self.rng.randint(1, n))
        return root


def random_bt(
    seed: Seed = None,
    depth: int | None = None,
    breadth: int | None = None,
    scenario: str = "basic",
    *,
    extended: bool = False,
    max_nodes: int = 120,
    condition_ratio: float = 0.4,
) -> BTDocument:
    """A random BT document (see the module docstring).

    ``depth`` and ``breadth`` default to draws in [2, 10]; ``max_nodes`` is a soft budget (the
    one path of full depth is always completed); leaves are Conditions with probability
    ``condition_ratio``. Leaf types come from the scenario's vocabulary; a type used again gets a
    unique ``name`` (``Grasp_2``), so every leaf has a distinct label. The document declares
    every leaf type in its ``TreeNodesModel``.
    """
    _check_scenario(scenario)
    rng = make_rng(seed)
    depth = depth if depth is not None else rng.randint(2, 10)
    breadth = breadth if breadth is not None else rng.randint(2, 10)
    if depth < 2 or breadth < 1:
        raise ValueError("a generated BT needs depth >= 2 and breadth >= 1")
    builder = _BTBuilder(rng, depth, breadth, scenario, extended, max_nodes, condition_ratio)
    root = builder.build()
    doc = BTDocument.single(root)
    for word, kind in sorted(builder.leaf_kinds.items()):
        doc.node_models[word] = NodeModel(word, kind, ports=[])
    return doc


__all__ = [
    "random_fsm",
    "random_bt",
    "make_rng",
    "FSM_SHAPES",
    "DECORATORS",
    "EXTENDED_CONTROLS",
    "PAPER_CONTROLS",
    "letters",
]
