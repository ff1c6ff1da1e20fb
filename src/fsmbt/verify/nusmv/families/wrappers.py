"""NuSMV rules of the wrapper family: SubTree, Nav2's Root and GoalUpdater (docs/semantics.md
"SubTree", "Project nodes", §10; docs/nusmv.md), mirroring ``fsmbt.semantics.families.wrappers``
(``tick_subtree``, ``tick_pass_through``, ``tick_pass_through_keep``).

- ``subtree``: the node calls the subtree's root on every tick (its status is set to RUNNING
  only when it was IDLE) and passes its status on: RUNNING and SKIPPED (never stored) as they
  are, a completed root reset first.
- ``pass_through`` / ``pass_through_keep``: the child's status returned as it is (RUNNING for
  anything but SUCCESS/FAILURE); ``pass_through`` resets a completed child, ``_keep`` does not.

No variable. Cost: O(1) rules per node.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.verify.nusmv.families.common import (
    FAILURE,
    PASSED,
    SKIPPED,
    SUCCESS,
    always,
    every_child_skips,
    one_child_facts,
)
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits, named


def subtree(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """SubTree (the module docstring)."""
    c = x.children[0]
    core.rule(core.st(x.id), f"{called} & {core.st(x.id)} = I", "R")
    core.call(called, c)
    back = f"{here} & res != NONE"
    done = f"{back} & (res = S | res = F)"
    core.ret(f"{back} & res = R", x.id, "R")
    core.ret(f"{back} & res = K", x.id, SKIPPED)  # SKIPPED passes through
    resets[c].append(done)
    core.ret(done, x.id, f"case res = S : {SUCCESS}; TRUE : {FAILURE}; esac")


def pass_through(
    core: BTCore, x: CompiledNode, rule: str, here: str, called: str, resets: Resets
) -> None:
    """Root, GoalUpdater (``rule``: ``pass_through`` / ``pass_through_keep``)."""
    back = f"{here} & res != NONE"
    core.rule(core.st(x.id), called, "R")
    c = x.children[0]
    core.call(called, c)
    if rule == "pass_through":
        resets[c].append(f"{back} & (res = S | res = F)")
    core.ret(back, x.id, PASSED)


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "subtree": subtree,
    "pass_through": named(pass_through, "pass_through"),
    "pass_through_keep": named(pass_through, "pass_through_keep"),
}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): SubTree passes
#: SKIPPED on, resets its completed root and ticks it on every tick; Root and GoalUpdater have
#: the defaults.
TRAITS: dict[str, RuleTraits] = {
    "subtree": RuleTraits(
        skip_aware=always,
        returns_skipped=every_child_skips,
        keeps_completed=True,
        leaf_facts=one_child_facts(sure_with_child=True),
    )
}
