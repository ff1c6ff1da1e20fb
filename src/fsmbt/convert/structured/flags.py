"""The flag form of a region no structured form expresses (docs/conversion.md, "The structured
style"; docs/semantics.md §11, "The blackboard entries modelled").

One blackboard entry, the region's *program counter* ``pc`` (``Region.pc_key``), names the unit
to run next; its values are the units' and exits' names (an index where a name would not make
a literal). The form, with BehaviorTree.CPP built-ins only::

    Sequence
      Script pc:='<initial>'
      ForceSuccess
        KeepRunningUntilFailure
          Switch(pc): <unit> -> block(unit) ...; default -> AlwaysFailure   (an exit: stop)
      Switch(pc): <exit> -> the exit's terminal ...

``block(unit)`` runs the unit's leaf and sets ``pc`` from its result: ``IfThenElse(leaf,
Script pc:=S-target, Script pc:=F-target)``, ``Sequence(leaf, Script ...)`` when one target, or
for a dispatch unit ``Sequence(leaf, Switch(outcome) -> Script ...)``. Each unit's leaf appears
once. Cost: O(units + outcomes) nodes.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from fsmbt.convert.structured.builder import always, control, decorator, script
from fsmbt.convert.structured.shapes import Term, sequence, switch_chain
from fsmbt.model.bt import BTNode
from fsmbt.semantics.outcome_rules import FAILURE, SUCCESS
from fsmbt.semantics.outcome_view import Region, Unit

_LITERAL = re.compile(r"[A-Za-z_][A-Za-z0-9_ .-]*")


def flag_form(region: Region, emit: Callable[[Unit], BTNode], exits: dict[str, Term]) -> BTNode:
    """The region's tree in the flag form (see the module docstring)."""
    names = [*region.units, *exits]
    values = {
        name: name if _LITERAL.fullmatch(name) else f"s{index}" for index, name in enumerate(names)
    }
    pc = region.pc_key

    def goto(target: str) -> BTNode:
        return script(pc, values[target])

    blocks: list[tuple[str, BTNode]] = []
    for name, unit in region.units.items():
        x = emit(unit)
        if unit.dispatch:
            cases = [(o, goto(unit.targets[o])) for o in unit.outcomes[:-1]]
            block = sequence(
                x, switch_chain(unit.key, cases, goto(unit.targets[unit.outcomes[-1]]))
            )
        else:
            s_target = unit.target_of(SUCCESS)
            f_target = unit.target_of(FAILURE)
            if s_target is not None and f_target is not None and s_target != f_target:
                block = control("IfThenElse", x, goto(s_target), goto(f_target))
            elif s_target is not None and f_target is None:
                block = sequence(x, goto(s_target))
            else:
                target = s_target if s_target is not None else f_target
                assert target is not None
                block = sequence(decorator("ForceSuccess", x), goto(target))
        blocks.append((values[name], block))
    loop = decorator(
        "ForceSuccess",
        decorator("KeepRunningUntilFailure", switch_chain(pc, blocks, always(False))),
    )
    parts = [script(pc, values[region.initial]), loop]
    reached = [e for e in exits if any(e in u.targets.values() for u in region.units.values())]
    if len(reached) == 1:
        parts.append(exits[reached[0]].node())
    elif reached:
        cases = [(values[e], exits[e].node()) for e in reached[:-1]]
        parts.append(switch_chain(pc, cases, exits[reached[-1]].node()))
    return control("Sequence", *parts)
