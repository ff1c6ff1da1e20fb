"""Run a ``BTDocument`` in py_trees 2.6, on the node types py_trees has.

Name mapping (BehaviorTree.CPP v4 meaning -> py_trees): ``Sequence`` -> ``Sequence(memory=True)``,
``ReactiveSequence`` -> ``Sequence(memory=False)``, ``Fallback`` -> ``Selector(memory=True)``,
``ReactiveFallback`` -> ``Selector(memory=False)``, ``Inverter`` -> ``Inverter``,
``ForceSuccess`` -> ``FailureIsSuccess``, ``ForceFailure`` -> ``SuccessIsFailure``,
``AlwaysSuccess``/``AlwaysFailure`` -> ``behaviours.Success``/``Failure``; SubTrees are
inlined. Everything else (SequenceWithMemory, Parallel*, IfThenElse, WhileDoElse, Repeat,
RetryUntilSuccessful, KeepRunningUntilFailure, RunOnce) has no py_trees equivalent with the same
v4 semantics and raises ``UnsupportedError``. None of the supported types emits a wake-up, so
one py_trees tick equals one ``tickOnce``.

Leaves are ``Behaviour`` subclasses whose ``update()`` asks the environment; py_trees calls
``initialise()`` when a leaf is ticked while not RUNNING, which is how the LEBT state leaf knows
its first tick.
"""

from __future__ import annotations

from collections.abc import Callable

import py_trees
from py_trees.common import Status

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics.bt_interpreter import CompiledNode, CompiledTree, Environment, TickRecord
from fsmbt.semantics.lebt.driver import EngineLebtRun
from fsmbt.semantics.lebt.leaves import (
    LebtLeaves,
    PlainBlackboard,
    guard_outcome,
    state_on_running,
    state_on_start,
)
from fsmbt.semantics.status import LeafOutcome, NodeStatus

SUPPORTED_TYPES = frozenset(
    {
        "Sequence",
        "ReactiveSequence",
        "Fallback",
        "ReactiveFallback",
        "Inverter",
        "ForceSuccess",
        "ForceFailure",
        "SubTree",
        "AlwaysSuccess",
        "AlwaysFailure",
    }
)
#: A leaf outcome (``LeafOutcome`` or its string) as py_trees' status.
_STATUS: dict[str, Status] = {
    LeafOutcome.SUCCESS: Status.SUCCESS,
    LeafOutcome.FAILURE: Status.FAILURE,
    LeafOutcome.RUNNING: Status.RUNNING,
}
#: py_trees' status as ours (INVALID = never ticked or halted = IDLE), and by name.
_NODE_STATUS = {
    Status.SUCCESS: NodeStatus.SUCCESS,
    Status.FAILURE: NodeStatus.FAILURE,
    Status.RUNNING: NodeStatus.RUNNING,
    Status.INVALID: NodeStatus.IDLE,
}
_NAME = {engine: status.name for engine, status in _NODE_STATUS.items()}

#: Builds the py_trees leaf for an environment leaf of the compiled tree.
LeafFactory = Callable[[CompiledNode], py_trees.behaviour.Behaviour]


class EnvLeaf(py_trees.behaviour.Behaviour):
    """A leaf whose every tick asks ``callback(first_tick)`` for an outcome string."""

    def __init__(self, name: str, callback: Callable[[bool], str]) -> None:
        super().__init__(name)
        self.callback = callback
        self._first = True

    def initialise(self) -> None:
        self._first = True

    def update(self) -> Status:
        first, self._first = self._first, False
        return _STATUS[self.callback(first)]


def supports(tree: CompiledTree) -> bool:
    return all(n.is_env_leaf or n.type in SUPPORTED_TYPES for n in tree.nodes)


def build(tree: CompiledTree, leaf_factory: LeafFactory) -> py_trees.behaviour.Behaviour:
    """The py_trees tree (bottom-up over the pre-order ids: no recursion)."""
    made: dict[int, py_trees.behaviour.Behaviour] = {}
    for node in reversed(tree.nodes):
        name = f"n{node.id}"
        if node.is_env_leaf:
            made[node.id] = leaf_factory(node)
            continue
        if node.type not in SUPPORTED_TYPES:
            raise UnsupportedError(
                f"py_trees has no equivalent of {node.type}",
                location=node.source.location,
                element=node.label,
            )
        kids = [made.pop(c) for c in node.children]
        t = node.type
        if t == "AlwaysSuccess":
            made[node.id] = py_trees.behaviours.Success(name)
        elif t == "AlwaysFailure":
            made[node.id] = py_trees.behaviours.Failure(name)
        elif t in ("Sequence", "ReactiveSequence"):
            made[node.id] = py_trees.composites.Sequence(
                name, memory=t == "Sequence", children=kids
            )
        elif t in ("Fallback", "ReactiveFallback"):
            made[node.id] = py_trees.composites.Selector(
                name, memory=t == "Fallback", children=kids
            )
        elif t == "Inverter":
            made[node.id] = py_trees.decorators.Inverter(name, child=kids[0])
        elif t == "ForceSuccess":
            made[node.id] = py_trees.decorators.FailureIsSuccess(name, child=kids[0])
        elif t == "ForceFailure":
            made[node.id] = py_trees.decorators.SuccessIsFailure(name, child=kids[0])
        else:  # SubTree: inlined
            made[node.id] = kids[0]
    return made[0]


class PyTreesRunner:
    """A py_trees tree whose leaves ask ``env(node, path)`` for their outcome."""

    def __init__(self, doc: BTDocument | CompiledTree, env: Environment) -> None:
        self.tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        self.env = env
        self._leaves: list[tuple[str, str, str]] = []
        self.root = build(self.tree, self._make_leaf)

    def _make_leaf(self, node: CompiledNode) -> py_trees.behaviour.Behaviour:
        def ask(first: bool) -> str:
            outcome = self.env(node.source, node.path)
            self._leaves.append((node.label, node.path, outcome))
            return outcome

        return EnvLeaf(f"n{node.id}", ask)

    def tick_once(self) -> TickRecord:
        self._leaves = []
        self.root.tick_once()
        return TickRecord(self._leaves, _NAME[self.root.status])


class PyTreesLebtRunner(EngineLebtRun):
    """An LEBT in py_trees: guard and state leaves are ``EnvLeaf`` s running the shared leaf
    behaviours; the state leaf's first tick is the tick that called ``initialise()``; the
    blackboard is a plain object held by the runner."""

    def __init__(self, doc: BTDocument | CompiledTree, *, start: str | None = None) -> None:
        self.tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        super().__init__()
        self.leaves = LebtLeaves.of(self.tree, start)
        self.bb = PlainBlackboard(self.leaves.start)
        self.root = build(self.tree, self._make_leaf)

    def _make_leaf(self, node: CompiledNode) -> py_trees.behaviour.Behaviour:
        guard = self.leaves.guards.get(node.id)
        if guard is not None:
            return EnvLeaf(f"n{node.id}", lambda first: guard_outcome(guard, self.bb))
        spec = self.leaves.states[node.id]

        def state_leaf(first: bool) -> str:
            if first:
                return state_on_start(spec, self.bb, self.actions)
            return state_on_running(spec, self.bb)

        return EnvLeaf(f"n{node.id}", state_leaf)

    def _tick_engine(self) -> NodeStatus:
        """One py_trees tick of the root."""
        self.root.tick_once()
        return _NODE_STATUS[self.root.status]
