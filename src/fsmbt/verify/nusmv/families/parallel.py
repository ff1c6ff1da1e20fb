"""NuSMV rules of the parallel family: Parallel, ParallelAll and julienbayle/stardust
RealParallel (docs/semantics.md "Control nodes", "Project nodes"; docs/nusmv.md), mirroring
``fsmbt.semantics.families.parallel`` (``tick_parallel``, ``tick_parallel_all``,
``tick_real_parallel``; BehaviorTree.CPP 4.8 parallel_node.cpp, parallel_all_node.cpp).

- ``parallel`` / ``parallel_all``: the completed set and the counters are not variables. A
child completed in this run of the parallel is exactly a child whose status is SUCCESS or
FAILURE: a parallel never ticks a completed child again, and it resets every child whenever it
completes (its halt clears them too), so the statuses already hold the memory; the success and
failure counts are DEFINEs summing them (``psc_n``, ``pfc_n``). The threshold checks run after
every child's return, in the interpreter's order (success first).
- ``real_parallel``: every child is called in order on every tick and none is reset; ``pr_n`` /
  ``pf_n`` remember within the tick whether a child was RUNNING / failed (both zeroed when the
  node is called and when it returns: RUNNING if any child ran, else FAILURE if any failed,
  else SUCCESS).

Cost: O(k²) rules for a parallel of k children (the next child not completed after each one),
no variable; O(k) rules and 2 bits for a RealParallel.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.families.parallel import parallel_threshold
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits, named
from fsmbt.verify.nusmv.smv import all_of


def parallel(
    core: BTCore, x: CompiledNode, rule: str, here: str, called: str, resets: Resets
) -> None:
    """Parallel (success/failure thresholds) and ParallelAll (max_failures); the module
    docstring."""
    back = f"{here} & res != NONE"
    kids = list(x.children)
    n = len(kids)
    done = [f"({core.st(c)} = S | {core.st(c)} = F)" for c in kids]
    successes = " + ".join(f"toint({core.st(c)} = S)" for c in kids)
    failures = " + ".join(f"toint({core.st(c)} = F)" for c in kids)
    sc, fc = f"psc_{x.id}", f"pfc_{x.id}"
    core.defines += [(sc, f"({successes})"), (fc, f"({failures})")]
    if rule == "parallel":
        succ_param, fail_param = x.params
        need_s, need_f = parallel_threshold(succ_param, n), parallel_threshold(fail_param, n)
        won = f"{sc} >= {need_s}"
        lost = f"!({won}) & ({n} - {fc} < {need_s} | {fc} = {need_f})"
        checks = [(won, "S"), (lost, "F")]  # run after every child's return, success first
    else:
        (need_f,) = x.params
        everything = all_of(done)  # every child completed: the verdict, else RUNNING
        checks = [
            (f"{everything} & {fc} >= {need_f}", "F"),
            (f"{everything} & {fc} < {need_f}", "S"),
        ]

    def first_open(cond: str, start: int) -> None:
        """From child ``start`` on, call the first child not completed; none: RUNNING."""
        for j in range(start, n):
            core.call(f"{cond} & {all_of(done[start:j] + [f'!{done[j]}'])}", kids[j])
        core.ret(cond, x.id, "R")

    def verdicts(cond: str) -> None:
        """The threshold checks under ``cond``: reset every child and return the verdict."""
        for check, status in checks:
            finished = f"{cond} & {check}"
            for c in kids:
                resets[c].append(finished)
            core.ret(finished, x.id, status)

    if rule == "parallel":
        verdicts(back)  # after every child's return
        for i in range(n):
            first_open(f"{back} & lidx = {i}", i + 1)
        # called: a completed child 0 is checked before anything is ticked (the checks of the
        # completed children after it read the same counts, so they give the same answer)
        verdicts(f"{called} & {done[0]}")
        core.rule(core.st(x.id), called, "R")  # after the verdicts' rows: they take precedence
        first_open(called, 0)
        return
    for i in range(n):
        at = f"{back} & lidx = {i}"
        for j in range(i + 1, n):
            core.call(f"{at} & {all_of(done[i + 1 : j] + [f'!{done[j]}'])}", kids[j])
        verdicts(at)  # exclusive with the calls: only once every child completed
        core.ret(at, x.id, "R")
    verdicts(called)  # (only once every child completed)
    core.rule(core.st(x.id), called, "R")
    first_open(called, 0)


def real_parallel(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """stardust RealParallel (the module docstring)."""
    kids = list(x.children)
    back = f"{here} & res != NONE"
    ran = core.memory("pr", x.id, 1)
    failed = core.memory("pf", x.id, 1)
    core.rule(core.st(x.id), called, "R")
    core.rule(ran, called, "0")
    core.rule(failed, called, "0")
    core.call(called, kids[0])
    for i in range(len(kids)):
        at = f"{back} & lidx = {i}"
        if i + 1 < len(kids):
            core.rule(ran, f"{at} & res = R", "1")
            core.rule(failed, f"{at} & res = F", "1")
            core.call(at, kids[i + 1])
            continue
        core.rule(ran, at, "0")
        core.rule(failed, at, "0")
        status = f"case {ran} = 1 | res = R : R; {failed} = 1 | res = F : F; TRUE : S; esac"
        core.ret(at, x.id, status)


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "parallel": named(parallel, "parallel"),
    "parallel_all": named(parallel, "parallel_all"),
    "real_parallel": real_parallel,
}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): the defaults
#: for each (a child that may return SKIPPED is refused; no leaf tick is guaranteed).
TRAITS: dict[str, RuleTraits] = {}
