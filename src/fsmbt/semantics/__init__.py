"""Executable semantics: BT interpreter, FSM runner, LEBT protocol, explored machines."""
