"""The execution registry: how a model runs, and on which engines (docs/semantics.md).

Why one module: "what kind of model is this and how is it run" used to be answered three times
(the verifier's pairing rule, the simulation's agents, the Python runtime), in different orders,
with an engine-name -> runner table in each. Every layer now asks here:

- ``flavour_of(model)``: the one classification. An FSM runs as a macro-step machine (events in,
  actions out) or, against a plain BT, as a leaf-execution machine; a BT is an LEBT (fsmbt's
  FSM -> BT rules: ``LebtGuard``/``LebtState`` leaves, docs/semantics.md "The LEBT protocol"),
  a state-variable tree (the BSD/CHDS baselines' leaves), a dispatch tree (``DispatchEntry``
  leaves, docs/semantics.md section 12) or a plain tree (any other: its leaves
  are the environment's). The LEBT test comes first: its leaves decide the protocol.
- ``ENGINES`` / ``engines_for(model)``: which engines can run it: ``fsmbt`` (the reference
  interpreters here), ``btcpp`` (BehaviorTree.CPP 4.8.2 through behaviortreepy), ``py_trees``,
  ``python-statemachine`` (a W3C SCXML engine, for FSMs written as SCXML).
- ``leaf_machine`` / ``event_machine`` / ``tick_runner``: the runner for one engine, built the
  same way for the checker, the simulations, the runtimes and the conformance and test
  generation commands.

Engines are imported only when asked for (behaviortreepy and py_trees are heavy imports), so
asking what a model is costs nothing but one pass over its nodes: O(nodes).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from enum import StrEnum
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_runtime import is_dispatch_bt
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE
from fsmbt.semantics.machine import LEAF_OUTCOMES, FSMLeafMachine, FSMMachine, Machine
from fsmbt.semantics.state_variable_runtime import is_state_variable_bt


class Flavour(StrEnum):
    """How a model runs."""

    FSM = "fsm"  # a state machine (flat or hierarchical)
    LEBT = "lebt"  # fsmbt's loop-execution BT of an FSM (macro steps under the LEBT protocol)
    STATE_VARIABLE = "state-variable"  # a baseline's BT with state-variable leaves (BSD, CHDS)
    DISPATCH = "dispatch"  # fsmbt's dispatch form of an FSM (DispatchEntry leaves, macro steps)
    PLAIN = "plain"  # any other BT: its leaves are the environment's (leaf execution)


#: Engine name -> what it is. ``fsmbt`` is the reference every other one is checked against.
ENGINES: dict[str, str] = {
    "fsmbt": "fsmbt's own interpreters (the reference of docs/semantics.md)",
    "btcpp": "BehaviorTree.CPP 4.8.2 through behaviortreepy",
    "py_trees": "py_trees 2.x (trees whose nodes it has)",
    "python-statemachine": "python-statemachine's W3C SCXML engine (FSMs)",
}


def is_lebt(doc: BTDocument) -> bool:
    """Whether any leaf of ``doc`` is a loop-execution leaf (``LebtGuard`` / ``LebtState``)."""
    return any(node.type in (GUARD_TYPE, STATE_TYPE) for _tree, node in doc.nodes())


def flavour_of(model: FSM | BTDocument) -> Flavour:
    """The one answer to "how does this model run" (see the module text). O(nodes)."""
    if isinstance(model, FSM):
        return Flavour.FSM
    if is_lebt(model):
        return Flavour.LEBT
    if is_state_variable_bt(model):
        return Flavour.STATE_VARIABLE
    if is_dispatch_bt(model):
        return Flavour.DISPATCH
    return Flavour.PLAIN


def engines_for(model: FSM | BTDocument) -> tuple[str, ...]:
    """The engines ``model`` can run on (``fsmbt`` always first)."""
    flavour = flavour_of(model)
    if flavour is Flavour.FSM:
        return ("fsmbt", "python-statemachine")
    if flavour in (Flavour.STATE_VARIABLE, Flavour.DISPATCH):
        return ("fsmbt",)
    if flavour is Flavour.LEBT:
        return ("fsmbt", "btcpp", "py_trees")
    assert isinstance(model, BTDocument)
    from fsmbt.semantics.bt_interpreter import CompiledTree
    from fsmbt.semantics.engines.pytrees_engine import supports

    return ("fsmbt", "btcpp", "py_trees") if supports(CompiledTree(model)) else ("fsmbt", "btcpp")


def check_engine(model: FSM | BTDocument, engine: str, where: str = "the model") -> None:
    """Refuse an unknown engine, or one that cannot run ``model``.

    Raises:
        InputError: an unknown engine name. UnsupportedError: the engine cannot run it.
    """
    if engine not in ENGINES:
        raise InputError(f"unknown engine '{engine}' (known: {', '.join(ENGINES)})")
    runs_on = engines_for(model)
    if engine not in runs_on:
        raise UnsupportedError(f"{where} cannot run on {engine} (it runs on: {', '.join(runs_on)})")


def tick_runner(doc: BTDocument, engine: str) -> Callable[[Any], Any]:
    """A factory ``env -> runner`` of a plain BT ticked on ``engine`` (fsmbt's ``BTRunner``,
    BehaviorTree.CPP's, py_trees'), the environment answering its leaves."""
    from fsmbt.semantics.bt_interpreter import BTRunner, CompiledTree

    tree = CompiledTree(doc)
    if engine == "btcpp":
        from fsmbt.semantics.engines.btcpp_engine import BTCppRunner

        return lambda env: BTCppRunner(tree, env)
    if engine == "py_trees":
        from fsmbt.semantics.engines.pytrees_engine import PyTreesRunner

        return lambda env: PyTreesRunner(tree, env)
    return lambda env: BTRunner(tree, env)


def lebt_engine_run(doc: BTDocument, engine: str) -> Any:
    """An LEBT loaded in a real engine (``btcpp`` or ``py_trees``): an ``EngineLebtRun``
    whose ``post(event)`` runs one macro step (docs/semantics.md, "The LEBT protocol")."""
    from fsmbt.semantics.bt_interpreter import CompiledTree

    tree = CompiledTree(doc)
    if engine == "btcpp":
        from fsmbt.semantics.engines.btcpp_engine import BTCppLebtRunner

        return BTCppLebtRunner(tree)
    if engine == "py_trees":
        from fsmbt.semantics.engines.pytrees_engine import PyTreesLebtRunner

        return PyTreesLebtRunner(tree)
    raise InputError(f"an LEBT runs in an engine on btcpp or py_trees, not '{engine}'")


def event_machine(doc_or_fsm: FSM | BTDocument, alphabet: Sequence[str]) -> Machine[Any]:
    """fsmbt's macro-step machine of an FSM, an LEBT, a state-variable or dispatch tree over
    ``alphabet`` (events in, actions out), as the checker explores it.

    Raises:
        InputError: a plain BT (it has leaf outcomes, not events).
    """
    flavour = flavour_of(doc_or_fsm)
    if isinstance(doc_or_fsm, FSM):
        return FSMMachine(doc_or_fsm, alphabet=alphabet)
    if flavour is Flavour.STATE_VARIABLE:
        from fsmbt.semantics.state_variable_runtime import StateVariableMachine

        return StateVariableMachine(doc_or_fsm, alphabet)
    if flavour is Flavour.DISPATCH:
        from fsmbt.semantics.dispatch_runtime import DispatchMachine

        return DispatchMachine(doc_or_fsm, alphabet)
    if flavour is Flavour.LEBT:
        from fsmbt.semantics.bt_interpreter import CompiledTree
        from fsmbt.semantics.lebt.machine import LEBTMachine

        return LEBTMachine(CompiledTree(doc_or_fsm), alphabet)
    raise InputError(
        "a plain BT has no events: it runs leaf by leaf (an FSM, an LEBT or a BSD/CHDS tree "
        "runs on events)"
    )


def leaf_machine(
    model: FSM | BTDocument, *, loop: bool = False, generic: bool = False
) -> Machine[Any]:
    """fsmbt's leaf-execution machine of a plain BT (``LeafMachine``) or of an FSM read as one
    (``FSMLeafMachine``: a state is the leaf about to be ticked); docs/semantics.md §4.

    Args:
        model: an FSM or a plain BT.
        loop: the root is ticked again after it returns.
        generic: the BT's faithful interpreter states instead of its canonical ones.
    """
    if isinstance(model, FSM):
        return FSMLeafMachine(model, loop=loop)
    from fsmbt.semantics.leaf_machine import LeafMachine

    return LeafMachine(model, loop=loop, generic=generic)


__all__ = [
    "ENGINES",
    "LEAF_OUTCOMES",
    "Flavour",
    "check_engine",
    "engines_for",
    "event_machine",
    "flavour_of",
    "is_lebt",
    "lebt_engine_run",
    "leaf_machine",
    "tick_runner",
]
