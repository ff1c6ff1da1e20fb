"""The recorders the conform tests use: behaviortreepy's ``FileLogger`` (the library's
``fsmbt.conform.record``) and fsmbt's C++ driver in its scripted mode
(``fsmbt.runtime.cpp.scripted``: BehaviorTree.CPP 4.8.2's own ``FileLogger2`` and
``SqliteLogger``)."""

from fsmbt.conform.record import record_btlog
from fsmbt.runtime.cpp.scripted import record_scripted as record_cpp

__all__ = ["record_btlog", "record_cpp"]
