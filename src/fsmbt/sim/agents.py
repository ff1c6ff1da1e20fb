"""Agents: a model (BT, HFSM, converted BT) driving one role of a world, on one engine.

How each kind of model runs (docs/simulation.md, "How each model runs"):

- leaf-driven role (the robot, a prey): the world answers every leaf.
  - a BT is ticked once per step by fsmbt's interpreter (``BTRunner``), by BehaviorTree.CPP
    (``BTCppRunner``) or by py_trees (``PyTreesRunner``); each leaf asks the world.
  - an FSM (a BT -> FSM conversion) runs by leaf execution (docs/semantics.md, "The
    leaf-execution machine"; ``fsmbt.verify.pairing.FSMLeafMachine``): its state is the leaf
    being ticked, the world answers that leaf and the transition on the outcome is taken; a step
    ends when the world answers ``running`` or a final state (the root's result) is entered.
  - a BT converted from such an FSM (an LEBT, or a BSD/CHDS state-variable BT) runs the same
    way through its macro-step machine: the outcome is the posted event, the action run is the
    next leaf.
- event-driven role (the predator): each step the world's sensors raise events; each is posted
  in order (an FSM's macro step: ``FSMMachine``; an LEBT's: ``LEBTMachine`` or the LEBT runtime
  on BehaviorTree.CPP / py_trees; a state-variable BT: ``StateVariableMachine``); then the action
  of the state the model is in runs in the world for that step.

After a root result the next step starts from the root again (a BT's tick loop; the FSM's
initial state). Every name a model uses is checked against the role's name table when the agent
is built (``fsmbt.sim.world.check_names``).

Costs: a step is one tick (O(nodes ticked)) or one machine step per leaf / event.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.model.flatten import flatten, needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.semantics.execution import ENGINES as EXECUTION_ENGINES
from fsmbt.semantics.execution import (
    Flavour,
    check_engine,
    event_machine,
    flavour_of,
    leaf_machine,
    lebt_engine_run,
    tick_runner,
)
from fsmbt.semantics.machine import FINAL
from fsmbt.semantics.status import LeafOutcome, RootResult
from fsmbt.sim.world import EVENT_DRIVEN, World, check_names

#: Engines a side can run on; ``fsmbt`` = fsmbt's own interpreter and machines.
#: The engines a world can run a model on: ``fsmbt.semantics.execution``'s registry.
ENGINES = tuple(EXECUTION_ENGINES)
ROOT_RESULTS = frozenset(result.value for result in RootResult)
LEAF_OUTCOMES = tuple(outcome.value for outcome in LeafOutcome)
#: A step that ticks more leaves than this does not end (a tree that loops without RUNNING).
MAX_LEAVES_PER_STEP = 10_000

Answer = Callable[[str], str]
#: Leaves the interpreter answers itself (never asked of the world).
INTERNAL_LEAVES = frozenset(
    {"AlwaysSuccess", "AlwaysFailure", "Script", "SetBlackboard", "UnsetBlackboard"}
)


class LeafAgent(Protocol):
    """Drives a leaf-driven role: one ``tick`` per step."""

    engine: str

    def tick(self, answer: Answer) -> tuple[list[tuple[str, str]], str]:
        """One step: the (leaf, outcome) pairs in order and the root's status name."""
        ...


class EventAgent(Protocol):
    """Drives an event-driven role: ``start`` once, then ``post`` each sensor event."""

    engine: str
    action: str | None

    def start(self) -> None: ...

    def post(self, event: str) -> None: ...

    @property
    def terminated(self) -> bool: ...


class BTTickAgent:
    """A BT ticked once per step by a runner whose leaves ask the world."""

    def __init__(
        self, make_runner: Callable[[Callable[[Any, str], str]], Any], engine: str
    ) -> None:
        self.engine = engine
        self._answer: Answer | None = None
        self.runner = make_runner(self._env)

    def _env(self, node: Any, path: str) -> str:
        assert self._answer is not None
        return self._answer(node.name or node.type)

    def tick(self, answer: Answer) -> tuple[list[tuple[str, str]], str]:
        self._answer = answer
        record = self.runner.tick_once()
        return [(label, outcome) for label, _path, outcome in record.leaves], record.result


class MachineLeafAgent:
    """A machine whose inputs are leaf outcomes and whose outputs name the next leaf (or the
    root's result), run by leaf execution. ``make_machine`` is called at every (re)start."""

    def __init__(self, make_machine: Callable[[], Any], engine: str) -> None:
        self.engine = engine
        self._make = make_machine
        self.machine: Any = None
        self.state: Any = None
        self.current: str | None = None

    def _start(self) -> str | None:
        self.machine = self._make()
        self.state, outputs = self.machine.start()
        return self._read(outputs)

    def _read(self, outputs: Sequence[str]) -> str | None:
        result = None
        for output in outputs:
            if output in ROOT_RESULTS:
                result = output
            else:
                self.current = output
        return result

    def tick(self, answer: Answer) -> tuple[list[tuple[str, str]], str]:
        leaves: list[tuple[str, str]] = []
        result = self._start() if self.machine is None else None
        while result is None:
            if self.current is None:
                raise InputError("the state machine runs no leaf (its state has no action)")
            if len(leaves) >= MAX_LEAVES_PER_STEP:
                raise InputError(
                    f"a step does not end: {MAX_LEAVES_PER_STEP} leaf ticks "
                    f"without RUNNING or a root result (last leaf "
                    f"'{self.current}'); a real engine would hang here"
                )
            outcome = answer(self.current)
            leaves.append((self.current, outcome))
            self.state, outputs = self.machine.step(self.state, outcome)
            result = self._read(outputs)
            if result is None and self.machine.status(self.state) == FINAL:
                result = RootResult.SUCCESS.value
            if result is None and outcome == LeafOutcome.RUNNING.value:
                return leaves, "RUNNING"
        self.machine = None  # the next step starts again from the root / initial state
        return leaves, result


class MachineEventAgent:
    """An FSM, LEBT or state-variable BT as a macro-step machine fed the world's events."""

    def __init__(self, machine: Any, engine: str) -> None:
        self.engine = engine
        self.machine = machine
        self.state: Any = None
        self.action: str | None = None

    def start(self) -> None:
        self.state, outputs = self.machine.start()
        self._read(outputs)

    def _read(self, outputs: Sequence[str]) -> None:
        if outputs:
            self.action = outputs[-1]

    def post(self, event: str) -> None:
        self.state, outputs = self.machine.step(self.state, event)
        self._read(outputs)

    @property
    def terminated(self) -> bool:
        return bool(self.machine.status(self.state) == FINAL)


class EngineEventAgent:
    """An LEBT on a real engine (``EngineLebtRun``: BehaviorTree.CPP or py_trees)."""

    def __init__(self, run: Any, engine: str) -> None:
        self.engine = engine
        self.run = run
        self.action: str | None = None

    def start(self) -> None:
        self._read(self.run.initial())

    def _read(self, outputs: Sequence[str]) -> None:
        if outputs:
            self.action = outputs[-1]

    def post(self, event: str) -> None:
        self._read(self.run.macro_step(event))

    @property
    def terminated(self) -> bool:
        return bool(self.run.terminated)


class EngineAsMachine:
    """An ``EngineLebtRun`` seen as a machine (state = nothing; the engine keeps it), so a
    converted BT on a real engine runs by leaf execution like fsmbt's machines."""

    def __init__(self, run: Any) -> None:
        self.run = run

    def start(self) -> tuple[None, tuple[str, ...]]:
        return None, tuple(self.run.initial())

    def step(self, state: None, symbol: str) -> tuple[None, tuple[str, ...]]:
        return None, tuple(self.run.macro_step(symbol))

    def status(self, state: None) -> str:
        return FINAL if self.run.terminated else "running"


# -- what a model is -------------------------------------------------------------------------
def bt_flavour(doc: BTDocument) -> str:
    """``"lebt"``, ``"state-variable"`` or ``"plain"``: ``fsmbt.semantics.execution``'s answer."""
    return str(flavour_of(doc))


def model_names(model: FSM | BTDocument) -> list[str]:
    """The behaviour names a model asks the world for: a plain BT's environment leaves, an
    FSM's state actions, a converted BT's state actions (root results left out)."""
    names: dict[str, None] = {}
    if isinstance(model, FSM):
        flat = flatten(model) if needs_flattening(model) else model
        for state in flat.states.values():
            if state.action and state.action not in ROOT_RESULTS:
                names.setdefault(state.action, None)
        return list(names)
    flavour = bt_flavour(model)
    for _tree, node in model.nodes():
        if flavour == "plain":
            if (
                node.is_leaf
                and node.kind in (NodeKind.ACTION, NodeKind.CONDITION)
                and node.type not in INTERNAL_LEAVES
            ):
                names.setdefault(node.name or node.type, None)
        elif node.attrs.get("action") and node.attrs["action"] not in ROOT_RESULTS:
            names.setdefault(node.attrs["action"], None)
    return list(names)


def build_agent(
    model: FSM | BTDocument, world: World, role: str, engine: str = "fsmbt", *, where: str = "model"
) -> LeafAgent | EventAgent:
    """An agent running ``model`` as ``role`` of ``world`` on ``engine``.

    Args:
        model: the model.
        world: the world (its name table and events).
        role: the role the model plays.
        engine: one of ``ENGINES`` that ``engines_for(model)`` lists
            (``fsmbt.semantics.execution``).
        where: the model's name for messages.

    Returns:
        A ``LeafAgent`` for a leaf-driven role, an ``EventAgent`` for an event-driven one.

    Raises:
        InputError: an unknown role or engine, a name outside the role's table, a plain BT for
            an event-driven role. UnsupportedError: the engine cannot run this model.
    """
    if role not in world.roles:
        raise InputError(
            f"the {world.name} world has no role '{role}' (roles: {', '.join(world.roles)})"
        )
    check_engine(model, engine, where)
    if (
        world.roles[role] == EVENT_DRIVEN
        and isinstance(model, BTDocument)
        and bt_flavour(model) == "plain"
    ):
        raise InputError(
            f"{where}: an event-driven role needs an FSM or a BT converted from one "
            "(LEBT, BSD, CHDS); this is a plain BT"
        )
    check_names(world, role, model_names(model), where)
    if world.roles[role] == EVENT_DRIVEN:
        return _event_agent(model, list(world.event_names(role)), engine, where)
    return _leaf_agent(model, engine)


def _leaf_agent(model: FSM | BTDocument, engine: str) -> LeafAgent:
    if isinstance(model, FSM):
        if engine == "python-statemachine":
            from fsmbt.sim.scxml_engine import SCXMLLeafMachine

            text = SCXMLLeafMachine.document(model)
            return MachineLeafAgent(lambda: SCXMLLeafMachine(text, model), engine)
        machine = leaf_machine(model)
        return MachineLeafAgent(lambda: machine, engine)
    if flavour_of(model) is Flavour.PLAIN:
        return BTTickAgent(tick_runner(model, engine), engine)
    make = _converted_machine(model, LEAF_OUTCOMES, engine)
    return MachineLeafAgent(make, engine)


def _converted_machine(doc: BTDocument, alphabet: Sequence[str], engine: str) -> Callable[[], Any]:
    """A factory of the macro-step machine of a converted BT on ``engine``."""
    if engine in ("btcpp", "py_trees") and flavour_of(doc) is Flavour.LEBT:
        return lambda: EngineAsMachine(lebt_engine_run(doc, engine))
    machine = event_machine(doc, alphabet)
    return lambda: machine


def _event_agent(model: FSM | BTDocument, events: list[str], engine: str, where: str) -> EventAgent:
    if isinstance(model, FSM):
        if engine == "python-statemachine":
            from fsmbt.sim.scxml_engine import SCXMLEventAgent

            return SCXMLEventAgent(model)
        alphabet = list(dict.fromkeys([*model.events(), *events]))
        return MachineEventAgent(event_machine(model, alphabet), engine)
    if flavour_of(model) is Flavour.PLAIN:
        raise InputError(
            f"{where}: an event-driven role needs an FSM or a BT converted from one "
            "(LEBT, BSD, CHDS); this is a plain BT"
        )
    if engine in ("btcpp", "py_trees"):
        return EngineEventAgent(_converted_machine(model, events, engine)().run, engine)
    return MachineEventAgent(_converted_machine(model, events, engine)(), engine)
