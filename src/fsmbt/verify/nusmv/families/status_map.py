"""NuSMV rule of the status-map family: Inverter, ForceSuccess, ForceFailure,
KeepRunningUntilFailure (docs/semantics.md "Decorators", "SKIPPED"; docs/nusmv.md), mirroring
``fsmbt.semantics.families.status_map`` (``tick_simple_decorator``; BehaviorTree.CPP 4.8
inverter_node.cpp, force_success_node.h, force_failure_node.h,
keep_running_until_failure_node.h).

Rule ``simple_decorator``. No variable: the node calls its child on every tick. With a declared
``result_map`` (SUCCESS, FAILURE -> statuses) a RUNNING child's status is passed on, SKIPPED too
(never stored), and a completed child is reset and its status mapped. Without one
(KeepRunningUntilFailure) a completed child is reset, FAILURE is returned and anything else is
RUNNING.

Cost: O(1) rules per node.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics, node_semantics
from fsmbt.verify.nusmv.families.common import SKIPPED, ST, every_child_skips, one_child_facts
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits


def simple_decorator(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """Inverter, ForceSuccess, ForceFailure, KeepRunningUntilFailure (the module docstring)."""
    c = x.children[0]
    spec = node_semantics(x.type)
    assert spec is not None
    result_map = spec.result_map
    core.rule(core.st(x.id), called, "R")
    core.call(called, c)
    back = f"{here} & res != NONE"
    done = f"{back} & (res = S | res = F)"
    if result_map is None:  # KeepRunningUntilFailure
        resets[c].append(done)
        core.ret(f"{back} & res = F", x.id, "F")
        core.ret(f"{back} & res != F", x.id, "R")
        return
    core.ret(f"{back} & res = R", x.id, "R")
    core.ret(f"{back} & res = K", x.id, SKIPPED)  # SKIPPED passes through
    resets[c].append(done)
    on_s, on_f = ST[result_map[0]], ST[result_map[1]]
    mapped = on_s if on_s == on_f else f"case res = S : {on_s}; TRUE : {on_f}; esac"
    core.ret(done, x.id, mapped)


def _maps(x: CompiledNode, spec: NodeSemantics) -> bool:
    """A status map (a declared ``result_map``): it passes SKIPPED on."""
    return spec.result_map is not None


def _skips(x: CompiledNode, spec: NodeSemantics, may_skip: Sequence[bool]) -> bool:
    """A status map returns SKIPPED when its child may."""
    return _maps(x, spec) and every_child_skips(x, spec, may_skip)


def _keeps_running(x: CompiledNode, spec: NodeSemantics) -> bool:
    """KeepRunningUntilFailure (no result map) can tick its child forever."""
    return spec.result_map is None


_PASSES = one_child_facts(sure_with_child=True)


def _leaf_facts(
    x: CompiledNode,
    spec: NodeSemantics,
    sure: Sequence[bool],
    busy: Sequence[bool],
    may_skip: Sequence[bool],
) -> tuple[bool, bool]:
    """The livelock test's facts (``RuleTraits.leaf_facts``): a status map's are its child's;
    KeepRunningUntilFailure guarantees none."""
    return _PASSES(x, spec, sure, busy, may_skip) if _maps(x, spec) else (False, False)


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {"simple_decorator": simple_decorator}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): a status map
#: passes SKIPPED on; every kind resets a completed child; KeepRunningUntilFailure may tick
#: forever.
TRAITS: dict[str, RuleTraits] = {
    "simple_decorator": RuleTraits(
        skip_aware=_maps,
        returns_skipped=_skips,
        keeps_completed=True,
        leaf_facts=_leaf_facts,
        ticks_forever=_keeps_running,
    )
}
