"""Runtimes for the trees fsmbt writes: run a converted LEBT with the user's own actions.

- ``fsmbt.runtime.cpp``: the header-only C++ runtime for BehaviorTree.CPP v4 (``fsmbt/lebt.hpp``),
  its CMake example, the driver built by ``scripts/build_btcpp.sh`` and how to find it.
- ``fsmbt.runtime.python_runtime``: the same on py_trees and behaviortreepy from Python, with a
  mapping from action names to callables.
"""
