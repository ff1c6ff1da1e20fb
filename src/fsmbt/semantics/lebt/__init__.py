"""The LEBT runtime: how a loop-execution BT (the rules engine's FSM -> BT result) runs.

docs/semantics.md §5 ("The LEBT protocol") states the rules; each module has one job:

- ``spec``: how the two leaves ``LebtGuard``/``LebtState`` are written (ports, pair codec,
  blackboard keys); imported by the converter, the checkers and the LLM path.
- ``leaves``: the leaves' behaviour (``guard_outcome``, ``state_on_start``,
  ``state_on_running``) and ``LebtLeaves``, the parsed leaves of a compiled tree.
- ``driver``: ``MacroStepDriver``, the macro step (post an event, tick, the second-tick rule,
  drop an unhandled event), start and termination, written once over a tick function;
  ``EngineLebtRun``, the same driver for real engines that keep their own memory.
- ``interpreted``: the tick function on the generic BT interpreter (any tree).
- ``fast``: the tick function for the strict LEBT grammar (O(1) per macro step).
- ``machine``: ``LEBTMachine``, the checker's ``Machine``, choosing fast or interpreted.
The engine tick functions (BehaviorTree.CPP, py_trees) live with their adapters in
``fsmbt.semantics.engines``. This package imports nothing at import time: import the module
that holds the name (``from fsmbt.semantics.lebt.machine import LEBTMachine``).
"""
