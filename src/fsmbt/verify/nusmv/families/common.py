"""What the families' NuSMV rules share (docs/nusmv.md): the status constants of the encoding,
the bounded increment and the reading of a status port.

- ``ST``: the SMV constants of the four stored statuses (``NodeStatus`` names' initials: ``I``,
  ``R``, ``S``, ``F``), and ``SKIPPED`` (``K``), a returned status only: it is a value of
  ``res``, never stored in a node's ``st_n`` (docs/semantics.md §2). ``encode_bt`` renames them
  to NuSMV-safe words when it emits the module.
- ``PASSED``: the child's result returned as it is (RUNNING for anything else).
- ``increment(var, top)``: ``var + 1`` kept inside ``0..top``.
- ``returned_status(x, value, when)``: the constant of a status a node returns by parameter.

Costs: O(1) each.
"""

from __future__ import annotations

from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.status import NodeStatus

#: The SMV constants of the four stored statuses (``NodeStatus`` names' initials).
ST = {s.name: s.name[0] for s in NodeStatus if s is not NodeStatus.SKIPPED}
SUCCESS, FAILURE = ST[NodeStatus.SUCCESS.name], ST[NodeStatus.FAILURE.name]
#: SKIPPED, a returned status only (``res``; never stored in ``st_n``, docs/semantics.md §2).
SKIPPED = "K"
#: The child's SUCCESS or FAILURE returned as it is, anything else as RUNNING.
PASSED = "case res = S : S; res = F : F; TRUE : R; esac"


def increment(var: str, top: int) -> str:
    """``var + 1`` kept inside ``0..top`` (NuSMV checks every assignment's range, even on
    states the rules never reach)."""
    return f"case {var} < {top} : {var} + 1; TRUE : {top}; esac"


def returned_status(x: CompiledNode, value: int, when: str, *, skipped_ok: bool = False) -> str:
    """The SMV constant of a status node ``x`` returns by parameter (``value``); IDLE is
    refused, and SKIPPED unless ``skipped_ok`` (a gated node's closed gate, whose parents the
    encoder's ``may_skip`` checked).

    Raises:
        UnsupportedError: the status is IDLE, or SKIPPED without ``skipped_ok``.
    """
    status = NodeStatus(value).name
    if skipped_ok and status == NodeStatus.SKIPPED.name:
        return SKIPPED
    if status not in ST or status == NodeStatus.IDLE.name:
        raise UnsupportedError(
            f"the NuSMV encoding does not support {x.type} returning {status}{when} "
            "(SKIPPED is not encoded); use --engine native",
            location=x.source.location,
            element=f"<{x.type}> '{x.label}'",
        )
    return ST[status]
