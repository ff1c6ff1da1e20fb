"""NuSMV rules of the parallel family: Parallel, ParallelAll (docs/semantics.md "Control
nodes"; docs/nusmv.md), mirroring ``fsmbt.semantics.families.parallel`` (``tick_parallel``,
``tick_parallel_all``; BehaviorTree.CPP 4.8 parallel_node.cpp, parallel_all_node.cpp).

Rules ``parallel`` / ``parallel_all``: the completed set and the counters are not variables. A
child completed in this run of the parallel is exactly a child whose status is SUCCESS or
FAILURE: a parallel never ticks a completed child again, and it resets every child whenever it
completes (its halt clears them too), so the statuses already hold the memory; the success and
failure counts are DEFINEs summing them (``psc_n``, ``pfc_n``). The threshold checks run after
every child's return, in the interpreter's order (success first).

Cost: O(k²) rules for a parallel of k children (the next child not completed after each one);
no variable.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.families.parallel import parallel_threshold
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, named
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


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "parallel": named(parallel, "parallel"),
    "parallel_all": named(parallel, "parallel_all"),
}
