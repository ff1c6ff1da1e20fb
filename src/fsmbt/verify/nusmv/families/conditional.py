"""NuSMV rules of the conditional family: IfThenElse, WhileDoElse (docs/semantics.md "Control
nodes", §2; docs/nusmv.md), mirroring ``fsmbt.semantics.families.conditional``
(``tick_if_then_else``, ``tick_while_do_else``; BehaviorTree.CPP 4.8 if_then_else_node.cpp,
while_do_else_node.cpp).

Child 0 is the condition, child 1 the then-branch, child 2 (optional) the else-branch.

- ``if_then_else``: the chosen branch is kept in ``ci_n`` (0: the condition is asked, 1 / 2:
  that branch runs; reset by a halt and when the branch completes), so a running branch is
  called again without asking the condition. Without an else-branch a FAILED condition returns
  FAILURE.
- ``while_do_else``: the condition is asked on every tick; the branch it picks is called and the
  other one reset (without an else-branch a FAILED condition resets every child and returns
  FAILURE).

Either way a RUNNING condition or branch returns RUNNING and a completed branch resets every
child and returns its status. A condition that may return SKIPPED is refused by the encoder.

Cost: O(1) rules per node; 2 bits for IfThenElse.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.verify.nusmv.families.common import PASSED
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits, named


def conditional(
    core: BTCore, x: CompiledNode, rule: str, here: str, called: str, resets: Resets
) -> None:
    """IfThenElse and WhileDoElse (``rule``: ``if_then_else`` / ``while_do_else``; the module
    docstring)."""
    kids = list(x.children)
    n = len(kids)
    back = f"{here} & res != NONE"
    core.rule(core.st(x.id), called, "R")

    def reset_all(cond: str) -> None:
        for c in kids:
            resets[c].append(cond)

    memo = core.memory("ci", x.id, n - 1) if rule == "if_then_else" else None
    if memo is not None:
        for i in range(n - 1, 0, -1):
            core.call(f"{called} & {memo} = {i}", kids[i])
    core.call(called, kids[0])
    from_cond = f"{back} & lidx = 0"
    core.ret(f"{from_cond} & res = R", x.id, "R")
    if memo is not None:
        core.rule(memo, f"{from_cond} & res = S", "1")
    elif n == 3:
        resets[kids[2]].append(f"{from_cond} & res = S")
    core.call(f"{from_cond} & res = S", kids[1])
    if n == 3:
        if memo is not None:
            core.rule(memo, f"{from_cond} & res = F", "2")
        else:
            resets[kids[1]].append(f"{from_cond} & res = F")
        core.call(f"{from_cond} & res = F", kids[2])
    else:
        if memo is None:
            reset_all(f"{from_cond} & res = F")
        core.ret(f"{from_cond} & res = F", x.id, "F")
    from_branch = f"{back} & lidx != 0"
    core.ret(f"{from_branch} & res = R", x.id, "R")
    reset_all(f"{from_branch} & res != R")
    if memo is not None:
        core.rule(memo, f"{from_branch} & res != R", "0")
    core.ret(from_branch, x.id, PASSED)


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "if_then_else": named(conditional, "if_then_else"),
    "while_do_else": named(conditional, "while_do_else"),
}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): the defaults
#: for each (a child that may return SKIPPED is refused; no leaf tick is guaranteed).
TRAITS: dict[str, RuleTraits] = {}
