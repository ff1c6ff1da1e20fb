"""A dispatch tree (docs/semantics.md section 12) run for the Python runtime, on fsmbt's own
interpreter: the checker's macro steps, not a second copy of them.

``fsmbt.runtime.python_runtime.TreeRunner`` runs an LEBT through ``lebt_engine_run`` (py_trees
or BehaviorTree.CPP) and a dispatch tree through ``DispatchRun`` here, with the same interface:
``initial()`` and ``macro_step(event)`` return the entry keys of the leaves entered, in order;
``state``, ``start`` and ``terminated`` say where the run is.

Rules (all of them ``fsmbt.semantics.dispatch_runtime.DispatchMachine.tick``, which the checker's
pairing rule explores):

- ``initial()`` is the start tick (no ``event`` on the blackboard); ``macro_step(e)`` writes
  ``event = e``, ticks the root once and unsets ``event`` again.
- The keys returned are those of the ``DispatchEntry`` leaves the tick ran with a non-empty
  ``action`` port (leaves without one enter their state silently, as an FSM state without an
  entry action does), each an ``Entry``: the action, the leaf's ``state`` port (the state's
  label) and its optional ``params`` port (``name=value;...``, the LEBT leaves' encoding,
  ``fsmbt.semantics.lebt.spec.decode_params``).
- ``state`` is the ``state`` port of the last ``DispatchEntry`` run (``start`` before any);
  ``terminated``: the last tick returned SUCCESS (the current state is final).
- Checked when built (``InputError`` naming the leaf and its line): every leaf is a
  ``DispatchEntry`` action (``DispatchMachine``), every ``DispatchEntry`` has a non-empty
  ``state`` port and a well-formed ``params`` port; every node is one the blackboard
  interpreter models exactly (``OutcomeTree``); the index annotations agree
  (``fsmbt.semantics.dispatch_check``: every digit well formed, every index a transition writes
  a state's, one state per index - docs/semantics.md section 12, "Checked at load time").

Cost: building is O(nodes + reachable configurations x (digits + nesting) + transitions x
digits); a macro step is one tick of the blackboard interpreter,
O(log7 states + events of the current state / 6) node ticks (each with an O(entries) blackboard
copy: the snapshot is immutable).
"""

from __future__ import annotations

from dataclasses import dataclass

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.semantics.dispatch_check import check_dispatch_annotations
from fsmbt.semantics.dispatch_runtime import ENTRY, DispatchMachine
from fsmbt.semantics.lebt.spec import PARAMS_PORT, decode_params
from fsmbt.semantics.status import NodeStatus

#: The name of the start before the first state is entered (as ``DispatchMachine.describe``).
START = "start"


@dataclass(frozen=True)
class Entry:
    """One state leaf's entry: the action it runs, the state's label, its parameters."""

    action: str
    state: str
    params: dict[str, str]


class DispatchRun:
    """One run of a dispatch tree (see the module text)."""

    def __init__(self, doc: BTDocument) -> None:
        """Check ``doc`` and compile it (not started).

        Raises:
            InputError: a leaf other than ``DispatchEntry``, a node the interpreter does not
                model, a ``DispatchEntry`` with an empty ``state`` port or a malformed
                ``params`` port, index annotations that disagree (each named with its line).
        """
        self.machine = DispatchMachine(doc, ())
        #: entry key (the leaf's node id, as text) -> the entry, for leaves with an action
        self.entries: dict[str, Entry] = {}
        for nid, (state, action) in sorted(self.machine.entries.items()):
            node = self.machine.tree.nodes[nid].source
            element = f"<{ENTRY}> '{node.label}'"
            if not state:
                raise InputError(
                    f"{ENTRY} has no 'state' port: the runtime could not say which state it enters",
                    location=node.location,
                    element=element,
                )
            try:
                params = decode_params(node.attrs.get(PARAMS_PORT, ""))
            except ValueError as exc:
                raise InputError(
                    f"port '{PARAMS_PORT}': {exc}", location=node.location, element=element
                ) from None
            if action is not None:
                self.entries[str(nid)] = Entry(action, state, params)
        check_dispatch_annotations(self.machine)
        self._at = self.machine.before_start()
        self._state = START
        self.start = START

    @property
    def state(self) -> str:
        """The label of the state last entered (``start`` before any)."""
        return self._state

    @property
    def terminated(self) -> bool:
        """The last tick returned SUCCESS: the current state is final."""
        return self._at.last_result == NodeStatus.SUCCESS

    def initial(self) -> tuple[str, ...]:
        """The start tick; the keys of the entries run."""
        return self._tick(None)

    def macro_step(self, event: str) -> tuple[str, ...]:
        """One macro step for ``event``; the keys of the entries run."""
        return self._tick(event)

    def reset(self) -> None:
        """Back to before the start (nothing written on the blackboard)."""
        self._at = self.machine.before_start()
        self._state = START

    def _tick(self, event: str | None) -> tuple[str, ...]:
        done = self.machine.tick(self._at, event)
        self._at = done.state
        if done.entered:
            self._state = self.machine.entries[done.entered[-1]][0]
        return tuple(str(nid) for nid in done.entered if str(nid) in self.entries)
