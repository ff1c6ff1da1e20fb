"""The structured FSM -> BT style for outcome-driven machines (docs/conversion.md, "The
structured style"; the outcome rules: docs/semantics.md §11)."""

from fsmbt.convert.structured.convert import fsm_to_structured, structured_result

__all__ = ["fsm_to_structured", "structured_result"]
