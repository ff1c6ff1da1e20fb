"""Adapters that run fsmbt behavior trees in real BT engines, for differential testing.

- ``btcpp_engine``: BehaviorTree.CPP v4 (4.8.2) through the ``behaviortreepy`` bindings.
- ``pytrees_engine``: py_trees 2.6 on the subset of node types it has.
Both expose a runner with ``tick_once() -> TickRecord`` like ``bt_interpreter.BTRunner``.
"""
