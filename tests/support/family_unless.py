"""The worked example of docs/semantics.md, "Node families": a node kind added from one module.

``Unless`` ticks its child and swaps SUCCESS and FAILURE (the child is reset when it completes;
RUNNING and SKIPPED pass through): the Inverter's contract, on purpose, so the checker can prove
a tree using it equivalent to the same tree with an Inverter. docs/semantics.md shows this file
verbatim (tests/semantics/test_sem_families.py checks that it does).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import Family, NodeSemantics, registered
from fsmbt.semantics.compiled import (
    FAILURE,
    RUNNING,
    SUCCESS,
    CompiledNode,
    Frame,
    HaltHook,
    TickAction,
    Work,
)
from fsmbt.semantics.families.contract import FamilyRule, Interp
from fsmbt.semantics.families.registry import register_rule, unregister_rule
from fsmbt.verify.nusmv.families.common import (
    SKIPPED,
    always,
    every_child_skips,
    one_child_facts,
)
from fsmbt.verify.nusmv.families.contract import BTCore, Resets, RuleTraits
from fsmbt.verify.nusmv.families.registry import register_nusmv_rule, unregister_nusmv_rule

# 1. The declaration: what the readers, validate and the tables know of the kind.
UNLESS = NodeSemantics(
    "Unless",
    NodeKind.DECORATOR,
    Family.STATUS_MAP,
    1,
    tick="ticks the child; SUCCESS becomes FAILURE and FAILURE becomes SUCCESS",
    handler="unless",
    nusmv="unless",
)


# 2. The tick rule (the interpreter's; the contract: fsmbt.semantics.families.contract).
def tick_unless(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    child = node.children[0]
    if frame[1] == 0:  # ticked: tick the child, resume at pc 1
        w.st[node.id] = RUNNING
        return ("call", child, (node.id, 1))
    if result not in (SUCCESS, FAILURE):  # RUNNING or SKIPPED: passed on
        return ("ret", result)
    ip.reset_child(w, child, hook)
    return ("ret", FAILURE if result == SUCCESS else SUCCESS)


# 3. The NuSMV rule (the same micro-steps in SMV; fsmbt.verify.nusmv.families.contract).
def nusmv_unless(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    child = x.children[0]
    core.rule(core.st(x.id), called, "R")
    core.call(called, child)
    back = f"{here} & res != NONE"
    core.ret(f"{back} & res = R", x.id, "R")
    core.ret(f"{back} & res = K", x.id, SKIPPED)  # SKIPPED passed on, as tick_unless does
    done = f"{back} & (res = S | res = F)"
    resets[child].append(done)
    core.ret(done, x.id, "case res = S : F; TRUE : S; esac")


# 4. What the encoder's whole-tree checks read of the rule (the contract's RuleTraits): it
# passes SKIPPED on (so a child that may skip is allowed, and it skips when its child does),
# resets a completed child, and ticks its child on every tick (the livelock test).
UNLESS_TRAITS = RuleTraits(
    skip_aware=always,
    returns_skipped=every_child_skips,
    keeps_completed=True,
    leaf_facts=one_child_facts(sure_with_child=True),
)


# 5. Registration (a built-in kind is listed in its family modules instead).
@contextmanager
def unless_installed() -> Iterator[None]:
    """``Unless`` known to the registry, the interpreter and the NuSMV encoder in the block."""
    register_rule("unless", FamilyRule(tick_unless))
    register_nusmv_rule("unless", nusmv_unless, UNLESS_TRAITS)
    try:
        with registered(UNLESS):
            yield
    finally:
        unregister_nusmv_rule("unless")
        unregister_rule("unless")
