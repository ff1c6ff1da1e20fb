"""NuSMV's verdict on each distinct local check a native per-node walk recorded, compared unit
by unit (``fsmbt.verify.nusmv.pernode.check_plan``): shared by the NuSMV per-node tests."""

from __future__ import annotations

from fsmbt.verify.compositional import CheckPlan
from fsmbt.verify.nusmv.pernode import check_plan
from fsmbt.verify.pernode import LocalUnit


def units_agree(plan: CheckPlan) -> tuple[list[LocalUnit], list[LocalUnit], set[int]]:
    """Run NuSMV on ``plan``'s units and assert that each unit it encodes gets the native
    walk's verdict. Returns (every unit, the units NuSMV checked, ids of the ones it refused)."""
    found = check_plan(plan.units, [])
    units = [u for _region, region_units in plan.units for u in region_units]
    refused = {id(u) for u, _why in found.local.refused}
    checked = [u for u in units if id(u) not in refused]
    assert len(checked) == len(found.local.verdicts)
    for unit, verdict in zip(checked, found.local.verdicts, strict=True):
        assert unit.held == verdict.holds, (
            f"{verdict.node}: native {'holds' if unit.held else 'fails'}, "
            f"NuSMV {'holds' if verdict.holds else 'fails'}: {verdict.steps}"
        )
    return units, checked, refused
