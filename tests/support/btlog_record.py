"""The recorder the conform tests use (the library's, ``fsmbt.conform.record``)."""

from fsmbt.conform.record import record_btlog

__all__ = ["record_btlog"]
