"""YASMIN (ROS 2) state machines: the ``yasmin_factory`` XML, read and written, and YASMIN
Python, read statically (docs/formats/yasmin.md).

Reading builds the FSM the SMACH reader builds (outcome-driven: events are outcomes, containers
are composite states); nothing is imported or run. The XML is detected by its root element
``<StateMachine>``; Python by an ``import yasmin`` / ``from yasmin import``.
"""
