"""What the families' NuSMV rules share (docs/nusmv.md): the status constants of the encoding,
the bounded increment and the reading of a status port.

- ``ST``: the SMV constants of the four stored statuses (``NodeStatus`` names' initials: ``I``,
  ``R``, ``S``, ``F``), and ``SKIPPED`` (``K``), a returned status only: it is a value of
  ``res``, never stored in a node's ``st_n`` (docs/semantics.md §2). ``encode_bt`` renames them
  to NuSMV-safe words when it emits the module.
- ``PASSED``: the child's result returned as it is (RUNNING for anything else).
- ``increment(var, top)``: ``var + 1`` kept inside ``0..top``.
- ``returned_status(x, value, when)``: the constant of a status a node returns by parameter.
- The ``RuleTraits`` parts several families share (``contract.RuleTraits``): ``always``,
  ``every_child_skips`` (a skip-aware node returns SKIPPED when every child may),
  ``every_child_sure`` and ``one_child_facts`` (the livelock test's facts of a node that ticks
  all its children, or passes its one child on).

Costs: O(1) each.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.model.errors import UnsupportedError
from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics
from fsmbt.semantics.status import NodeStatus
from fsmbt.verify.nusmv.families.contract import LeafFacts

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


def always(x: CompiledNode, spec: NodeSemantics) -> bool:
    """A trait every node of the rule has (``RuleTraits.skip_aware``, ``answers_alone``)."""
    return True


def every_child_skips(x: CompiledNode, spec: NodeSemantics, may_skip: Sequence[bool]) -> bool:
    """``RuleTraits.returns_skipped`` of a skip-aware node: it has children and each may
    return SKIPPED (docs/semantics.md, "SKIPPED")."""
    return bool(x.children) and all(may_skip[c] for c in x.children)


def every_child_sure(
    x: CompiledNode,
    spec: NodeSemantics,
    sure: Sequence[bool],
    busy: Sequence[bool],
    may_skip: Sequence[bool],
) -> tuple[bool, bool]:
    """``RuleTraits.leaf_facts`` of a node that may tick any child on any tick: ``sure`` (and
    ``busy``) when every child is ``sure``."""
    every = all(sure[c] for c in x.children)
    return every, every


def one_child_facts(*, sure_with_child: bool) -> LeafFacts:
    """``RuleTraits.leaf_facts`` of a node that ticks its one RUNNING child on every tick
    while RUNNING: ``busy`` when the child is (``sure`` when the child may skip: a SKIPPED
    child leaves the node RUNNING); ``sure`` when the child is and ``sure_with_child`` (the
    node ticks its child on every tick)."""

    def facts(
        x: CompiledNode,
        spec: NodeSemantics,
        sure: Sequence[bool],
        busy: Sequence[bool],
        may_skip: Sequence[bool],
    ) -> tuple[bool, bool]:
        (c,) = x.children
        return sure_with_child and sure[c], sure[c] if may_skip[c] else busy[c]

    return facts
