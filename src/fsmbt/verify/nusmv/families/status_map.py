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

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import all_nodes, node_semantics
from fsmbt.verify.nusmv.families.common import SKIPPED, ST
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets

#: The kinds of this rule (the encoder reads which can tick forever: no result map).
SIMPLE_DECORATORS = frozenset(n.name for n in all_nodes() if n.nusmv == "simple_decorator")


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


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {"simple_decorator": simple_decorator}
