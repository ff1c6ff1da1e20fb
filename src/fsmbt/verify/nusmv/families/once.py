"""NuSMV rules of the once family: RunOnce and Nav2 SingleTrigger (docs/semantics.md
"Decorators", "Project nodes"; docs/nusmv.md), mirroring ``fsmbt.semantics.families.once``
(``tick_run_once``, ``tick_single_trigger``).

- ``run_once``: ``ro_n`` (0 not run yet, 1 succeeded, 2 failed), which a halt does **not**
  reset; once set the node returns it (``then_skip=false``) or SKIPPED (``then_skip=true``, the
  status ``K`` of ``res``, never stored) without ticking the child.
- ``single_trigger``: ``tr_n`` (triggered), cleared when the node is ticked while IDLE, set when
  the child completes; ticked while active and triggered, the node returns FAILURE without
  ticking the child. The child is not reset on completion (as in Nav2); a halt keeps ``tr_n``
  (the next activation clears it).

Cost: O(1) rules per node; 2 bits per RunOnce, 1 per SingleTrigger.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics
from fsmbt.verify.nusmv.families.common import SKIPPED, always, one_child_facts
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits


def run_once(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """RunOnce (``once.tick_run_once``); its memory survives halts."""
    back = f"{here} & res != NONE"
    (then_skip,) = x.params
    c = x.children[0]
    done = core.memory("ro", x.id, 2, reset_by_halt=False)
    if then_skip:  # SKIPPED after the first run (never stored: the status stays, §2)
        core.ret(f"{called} & {done} != 0", x.id, SKIPPED)
    else:
        core.ret(f"{called} & {done} = 1", x.id, "S")
        core.ret(f"{called} & {done} = 2", x.id, "F")
    core.rule(core.st(x.id), called, "R")
    core.call(called, c)
    core.ret(f"{back} & res = R", x.id, "R")
    finished = f"{back} & res != R"
    resets[c].append(finished)
    core.rule(done, finished, "case res = S : 1; TRUE : 2; esac")
    core.ret(finished, x.id, "case res = S : S; TRUE : F; esac")


def single_trigger(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """Nav2 SingleTrigger (``once.tick_single_trigger``; the module docstring)."""
    back = f"{here} & res != NONE"
    c = x.children[0]
    st = core.st(x.id)
    triggered = core.memory("tr", x.id, 1, reset_by_halt=False)
    core.ret(f"{called} & {st} != I & {triggered} = 1", x.id, "F")
    core.rule(triggered, f"{called} & {st} = I", "0")
    core.rule(st, called, "R")
    core.call(called, c)
    core.rule(triggered, f"{back} & (res = S | res = F)", "1")
    core.ret(back, x.id, "case res = S : S; res = F : F; TRUE : R; esac")


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {"run_once": run_once, "single_trigger": single_trigger}


def _then_skip(x: CompiledNode, spec: NodeSemantics, may_skip: Sequence[bool]) -> bool:
    """RunOnce with ``then_skip`` returns SKIPPED after its first run."""
    return bool(x.params[0])


#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): both can answer
#: without ticking any leaf (a RunOnce that has run, a triggered SingleTrigger) and tick their
#: RUNNING child while RUNNING; RunOnce may return SKIPPED and never ticks a completed child
#: again. Neither encodes a child that returns SKIPPED.
TRAITS: dict[str, RuleTraits] = {
    "run_once": RuleTraits(
        returns_skipped=_then_skip,
        keeps_completed=True,
        leaf_facts=one_child_facts(sure_with_child=False),
        answers_alone=always,
    ),
    "single_trigger": RuleTraits(
        leaf_facts=one_child_facts(sure_with_child=False), answers_alone=always
    ),
}
