"""NuSMV rule of the manual family: ManualSelector (docs/semantics.md "ManualSelector";
docs/nusmv.md), mirroring ``fsmbt.semantics.families.manual`` (``tick_manual_selector``;
BehaviorTree.CPP 4.8 manual_node.cpp).

Rule ``manual_selector`` (``params = (n, repeat_last_selection)``): the pick is an environment
input asked through the choice conditions the interpreter adds after the ``n`` children (one per
child, then SUCCESS, FAILURE, RUNNING): they are called in order, the first SUCCESS is the pick,
none means the last pick; a choice keeps no status (reset once it answered). A picked child is
called and its status returned (RUNNING for anything but SUCCESS/FAILURE); a picked status is
returned at once. With ``repeat_last_selection`` the first pick is kept in ``sel_n`` (0: none
yet, i + 1: child i), a memory a halt does not reset, and later ticks call it without asking.

Cost: O(n) rules; one variable of log2(n + 1) bits with ``repeat_last_selection``.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.verify.nusmv.families.common import PASSED
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits


def manual_selector(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """ManualSelector (the module docstring)."""
    n, repeat_last = x.params
    kids, choices = list(x.children[:n]), list(x.children[n:])
    back = f"{here} & res != NONE"
    sel = f"sel_{x.id}"
    choosing = called
    if n and repeat_last:
        sel = core.memory("sel", x.id, n, reset_by_halt=False)
        for i, c in enumerate(kids):
            core.call(f"{called} & {sel} = {i + 1}", c)
        choosing = f"{called} & {sel} = 0"
    if n:
        core.rule(core.st(x.id), choosing, "R")

    def pick(cond: str, index: int) -> None:
        if index < n:
            if repeat_last:
                core.rule(sel, cond, str(index + 1))
            core.call(cond, kids[index])
        else:
            core.ret(cond, x.id, ("S", "F", "R")[index - n])

    if choices:
        core.call(choosing, choices[0])
    else:  # one child under repeat_last_selection: the only pick
        pick(choosing, 0)
    for j, choice in enumerate(choices):
        answered = f"{back} & lidx = {n + j}"
        resets[choice].append(answered)  # a choice keeps no status
        pick(f"{answered} & res = S", j)
        if j + 1 < len(choices):
            core.call(f"{answered} & res != S", choices[j + 1])
        else:
            pick(f"{answered} & res != S", len(choices))
    core.ret(f"{back} & lidx < {max(n, 1)}" if n else "FALSE", x.id, PASSED)


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {"manual_selector": manual_selector}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): the defaults
#: for each (a child that may return SKIPPED is refused; no leaf tick is guaranteed).
TRAITS: dict[str, RuleTraits] = {}
