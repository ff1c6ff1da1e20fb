"""Simulations: put a model and its conversion into the same world and compare what they do.

A layer above ``fsmbt.api`` and ``fsmbt.semantics`` (docs/simulation.md): pure Python,
deterministic, seeded; no ROS, no game engine.

- ``world``: the world interface, ``StepRecord`` / ``Trajectory``, ``first_divergence``.
- ``robot``: the robot grasping world (the paper's ``examples/robot_bt.xml``).
- ``predator_prey``: the predator-prey game (``examples/predator_fsm.scxml``,
  ``examples/prey_bt.xml``).
- ``agents``: how each model runs on each engine (fsmbt, BehaviorTree.CPP, py_trees,
  python-statemachine).
- ``run``: seeded episodes, comparisons of two sides.
- ``pictures``: the side-by-side GIF and the trajectory plot.
This package imports nothing at import time: import the module that holds the name.
"""
