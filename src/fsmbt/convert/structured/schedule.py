"""How a Concurrence's container child runs under a Parallel: the ``ChildSchedule`` the outcome
view reads a concurrence with (docs/semantics.md §11, "Container children").

Under a Parallel a child's tree is ticked once per tick: it runs on in the same tick until a
leaf returns RUNNING, the child ends, or one of its loops goes round - the structured style
writes every loop of such a child so that it returns RUNNING when it goes round
(``RegionStructurer(yielding_loops=True)``). This module structures each region of the child
as the conversion will (same structurer, same contexts, placeholder leaves) and returns the
transitions that go round a loop, where the round reading passes the turn to the next child; a
region that needs the flag form (whose loop returns RUNNING after every state, and once more
before it ends) keeps the concurrence's product form, named.

``read_structured_view`` is the outcome view with this schedule: the conversion, the outcome
pairing and the round trip read a machine with it, so both sides of a proof read a
concurrence alike. Cost: one structuring of each container child's regions.
"""

from __future__ import annotations

from collections.abc import Callable

from fsmbt.convert.structured.regions import RegionStructurer, Unstructured
from fsmbt.convert.structured.shapes import Term
from fsmbt.model.bt import BTNode
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.outcome_rules import FAILURE, SUCCESS, OutcomeRules
from fsmbt.semantics.outcome_view import OutcomeView, Region, Unit, read_outcome_view


def read_structured_view(fsm: FSM, rules: OutcomeRules | None = None) -> OutcomeView:
    """``read_outcome_view`` with the structured style's ``child_schedule``."""
    return read_outcome_view(fsm, rules, child_schedule)


def exit_terms(region: Region, root_status: Callable[[str], str] | None = None) -> dict[str, Term]:
    """The region's exits as terminals: at the top the root's result (``root_status`` of the
    exit, ``SUCCESS``/``FAILURE``); below, the container outcome's status; for a dispatch
    container SUCCESS after writing the outcome."""
    owner = region.owner
    terms: dict[str, Term] = {}
    for name, state in region.machine.states.items():
        if not state.final:
            continue
        if owner is None:
            result = root_status(name) if root_status is not None else "SUCCESS"
            terms[name] = Term(FAILURE if result == "FAILURE" else SUCCESS)
        elif owner.dispatch:
            terms[name] = Term(SUCCESS, (owner.key, name))
        else:
            terms[name] = Term(owner.status.get(name) or SUCCESS)
    return terms


def child_schedule(
    top: Region, regions: dict[str, Region]
) -> tuple[str | None, frozenset[tuple[str, str]]]:
    """Why the child cannot run under a Parallel (or None), and its loops' round trips."""
    trips: set[tuple[str, str]] = set()
    for path, region in regions.items():
        structurer = RegionStructurer(region, _placeholder, exit_terms(region),
                                      yielding_loops=True)  # fmt: skip
        try:
            structurer.structure()
        except Unstructured as why:
            where = path.removeprefix(top.path).strip("/") or "its machine"
            return (
                f"needs the flag form in {where} ({why}), whose loop returns RUNNING after "
                "every state",
                frozenset(),
            )
        trips |= structurer.round_trips
    return None, frozenset(trips)


def _placeholder(unit: Unit) -> BTNode:
    return BTNode(unit.name, NodeKind.ACTION, name=unit.path)
