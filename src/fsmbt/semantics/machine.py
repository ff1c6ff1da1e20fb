"""The one shape every behaviour is explored in: a deterministic Mealy machine with a status.

The checker (``fsmbt.verify``) and NuSMV's encoding compare two such machines fed the same
inputs. What counts as an input and an output depends on the pair (docs/verification.md,
"Both models become machines"; docs/semantics.md, "Statuses" names the values):

- FSM vs LEBT (macro steps): inputs are events; outputs are the actions run; status is
  ``"final"`` when the FSM is in a final state / the LEBT has terminated, else ``"running"``.
- BT vs FSM (leaf execution): inputs are leaf outcomes ``success``/``failure``/``running``;
  outputs name the next leaf ticked, or the root's result (``"SUCCESS"``/``"FAILURE"``); status
  is ``"final"`` once the root has returned, else ``"running"``.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from typing import Final, Protocol, TypeVar

from fsmbt.model.errors import InputError
from fsmbt.model.flatten import flatten, needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.semantics.status import LeafOutcome, MachineStatus

S = TypeVar("S", bound=Hashable)
Outputs = tuple[str, ...]

#: ``MachineStatus`` values as plain ``str`` (the checker compares them in its hot loops).
RUNNING: Final[str] = MachineStatus.RUNNING.value
FINAL: Final[str] = MachineStatus.FINAL.value


class Machine(Protocol[S]):
    """A deterministic machine the checker can explore breadth first."""

    name: str

    def start(self) -> tuple[S, Outputs]:
        """The initial state and what is output on start (e.g. the initial state's action)."""
        ...

    def inputs(self, state: S) -> Sequence[str]:
        """Inputs the environment may give in ``state`` (a condition leaf never says running)."""
        ...

    def step(self, state: S, symbol: str) -> tuple[S, Outputs]:
        """The next state and the outputs of consuming ``symbol``."""
        ...

    def status(self, state: S) -> str:
        """``"running"``, or the terminal status the environment can observe."""
        ...

    def describe(self, state: S) -> str:
        """A short human-readable name for traces."""
        ...

    # Optional (the checker uses them when present):
    # - ``active_inputs(state) -> Sequence[str]``: the inputs that may change the state, output
    #   something or change the status; every other offered input must be a silent self-loop.
    # - ``follows_environment: bool``: the machine takes whatever inputs the other machine
    #   offers (its own ``inputs`` must list every input it can be given).


class FSMMachine:
    """The macro-step machine of an FSM (hierarchical ones flattened first).

    A state is the flat state's name, or the start pseudo-state before the initial event.
    An event without a transition is ignored (no output); a final state ignores every event.
    Complexity: O(1) per step after an O(T) table build.
    """

    def __init__(self, fsm: FSM, *, alphabet: Sequence[str] | None = None) -> None:
        # Read-only use: a plain FSM is shared, not deep-copied (2 s for 10 000 states).
        self.fsm = flatten(fsm) if needs_flattening(fsm) else fsm
        self.name = self.fsm.name
        self.start_state = self.fsm.start_name or "__start__"
        self.table = self.fsm.transition_map()
        self.alphabet: tuple[str, ...] = tuple(
            alphabet if alphabet is not None else self.fsm.events()
        )

    def start(self) -> tuple[str, Outputs]:
        assert self.fsm.initial is not None, "validated FSMs have an initial state"
        if self.fsm.initial_event is not None:
            return self.start_state, ()
        return self.fsm.initial, self.entry_outputs(self.fsm.initial)

    def inputs(self, state: str) -> Sequence[str]:
        return self.alphabet

    def active_inputs(self, state: str) -> Sequence[str]:
        """The inputs that may do anything in ``state``; every other offered input is a silent
        self-loop. Optional in the protocol: lets the checker skip ignored events (O(T), not
        O(states x events))."""
        if state == self.start_state and state not in self.fsm.states:
            return (self.fsm.initial_event,) if self.fsm.initial_event is not None else ()
        if self.fsm.states[state].final:
            return ()
        return [event for event in self.table.get(state, {}) if event is not None]

    def step(self, state: str, symbol: str) -> tuple[str, Outputs]:
        if state == self.start_state and state not in self.fsm.states:
            if symbol == self.fsm.initial_event:
                assert self.fsm.initial is not None
                return self.fsm.initial, self.entry_outputs(self.fsm.initial)
            return state, ()
        if self.fsm.states[state].final:
            return state, ()
        transition = self.table.get(state, {}).get(symbol)
        if transition is None:
            return state, ()
        return transition.target, self.entry_outputs(transition.target)

    def status(self, state: str) -> str:
        known = self.fsm.states.get(state)
        return FINAL if known is not None and known.final else RUNNING

    def describe(self, state: str) -> str:
        return state

    def entry_outputs(self, name: str) -> Outputs:
        """What entering the flat state ``name`` outputs: its action, if it has one."""
        action = self.fsm.states[name].action
        return (action,) if action is not None else ()


#: The inputs of a leaf-execution machine: what a ticked leaf may return.
LEAF_OUTCOMES: Final[tuple[str, ...]] = tuple(outcome.value for outcome in LeafOutcome)


class FSMLeafMachine:
    """An FSM (flattened if hierarchical) read as a BT's leaf-execution machine (docs/semantics.md,
    'The leaf-execution machine').

    A state is the leaf about to be ticked: entering it outputs its action (the leaf's label).
    An outcome with no transition leaves the FSM where it is, so the same leaf is ticked again
    and its label is output again (a converter may omit ``running`` self-loops). A final state
    is the root's result: its action (``SUCCESS``/``FAILURE``) is output and the status is
    ``"final"``, as ``LeafMachine`` does. With ``loop`` the root is ticked again at once: entering
    a final state outputs its action and then the initial state's, and the machine is back in
    the initial state (``LeafMachine(loop=True)`` outputs ``(result, first leaf)`` likewise).
    The machine takes whatever outcomes the BT side offers.
    """

    follows_environment = True

    def __init__(self, fsm: FSM, *, loop: bool = False) -> None:
        self.inner = FSMMachine(fsm, alphabet=LEAF_OUTCOMES)
        self.fsm = self.inner.fsm
        self.name = self.fsm.name
        self.loop = loop
        if self.fsm.initial is None:
            raise InputError("the state machine has no initial state", element=self.name)
        self.initial: str = self.fsm.initial

    def start(self) -> tuple[str, Outputs]:
        # a leaf machine has no start event: the initial transition is taken at once
        return self._enter(self.initial, ())

    def inputs(self, state: str) -> Sequence[str]:
        if self.fsm.states[state].final:
            return ()
        return LEAF_OUTCOMES

    def step(self, state: str, symbol: str) -> tuple[str, Outputs]:
        if self.fsm.states[state].final:
            return state, ()
        # no transition leaves ``target == state``: the same leaf is ticked again
        target, _outputs = self.inner.step(state, symbol)
        return self._enter(target, ())

    def _enter(self, target: str, before: Outputs) -> tuple[str, Outputs]:
        outputs = before + self.inner.entry_outputs(target)
        if self.loop and self.fsm.states[target].final and target != self.initial:
            return self.initial, outputs + self.inner.entry_outputs(self.initial)
        return target, outputs

    def status(self, state: str) -> str:
        return FINAL if self.fsm.states[state].final else RUNNING

    def describe(self, state: str) -> str:
        return state
