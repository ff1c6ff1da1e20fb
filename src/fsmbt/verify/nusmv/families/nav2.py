"""NuSMV rules of the Nav2 control family: PipelineSequence, RecoveryNode, RoundRobin
(docs/semantics.md "Project nodes", §10; docs/nusmv.md), mirroring
``fsmbt.semantics.families.nav2`` (``tick_pipeline``, ``tick_recovery``, ``tick_round_robin``;
nav2_behavior_tree pipeline_sequence.cpp, recovery_node.cpp, round_robin_node.cpp). The node is
RUNNING once called; its memory variables are reset by its halt. SKIPPED children are not
encoded (the encoder refuses them).

- ``pipeline``: ``pl_n``, the furthest child reached. Every tick calls child 0; a SUCCESS, or a
  RUNNING child before the furthest one, calls the next child; a RUNNING child at or past it
  becomes the furthest and returns RUNNING; a FAILURE resets every child and returns FAILURE;
  the last child's SUCCESS resets them all and returns SUCCESS.
- ``recovery`` (``number_of_retries`` = N): ``ri_n`` (0: the main child runs, 1: the recovery)
  and ``rt_n`` (recoveries so far, ``0..N``). The main child's SUCCESS returns SUCCESS; its
  FAILURE calls the recovery while fewer than N were tried, else returns FAILURE; the recovery's
  SUCCESS counts a try and calls the main child again, its FAILURE returns FAILURE. Completion
  resets every child and both variables.
- ``round_robin`` (``wrap_around``): ``rr_n``, the child to resume at, and ``rf_n``, the
  failures in a row. A SUCCESS moves on and returns SUCCESS; a FAILURE calls the next child
  until every child failed (FAILURE); without wrap-around the last child's completion returns
  FAILURE, as Nav2 reads.

Cost: O(k) rules for k children; log2(k) bits per variable.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.verify.nusmv.families.common import increment
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits


def _reset_all(x: CompiledNode, resets: Resets, cond: str) -> None:
    """Every child of ``x`` is reset under ``cond``."""
    for c in x.children:
        resets[c].append(cond)


def pipeline(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """PipelineSequence (the module docstring)."""
    kids = list(x.children)
    n = len(kids)
    back = f"{here} & res != NONE"
    core.rule(core.st(x.id), called, "R")
    last = core.memory("pl", x.id, n - 1)
    core.call(called, kids[0])
    failed = f"{back} & res = F"
    _reset_all(x, resets, failed)
    core.rule(last, failed, "0")
    core.ret(failed, x.id, "F")
    for i in range(n):
        at = f"{back} & lidx = {i}"
        core.ret(f"{at} & res = R & {last} <= {i}", x.id, "R")
        core.rule(last, f"{at} & res = R & {last} <= {i}", str(i))
        if i + 1 < n:
            core.call(at, kids[i + 1])  # SUCCESS, or RUNNING before the furthest
        else:
            _reset_all(x, resets, f"{at} & res = S")  # (res = R returned above)
            core.rule(last, at, "0")
            core.ret(at, x.id, "S")


def recovery(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """RecoveryNode (the module docstring)."""
    back = f"{here} & res != NONE"
    core.rule(core.st(x.id), called, "R")
    (retries,) = x.params
    main, recovery = x.children
    cur = core.memory("ri", x.id, 1)
    tries = core.memory("rt", x.id, max(retries, 0))
    core.call(f"{called} & {cur} = 0", main)
    core.call(called, recovery)
    from_main, from_rec = f"{back} & lidx = 0", f"{back} & lidx = 1"
    for side in (from_main, from_rec):
        core.ret(f"{side} & res = R", x.id, "R")
    won = f"{from_main} & res = S"
    retry = f"{from_main} & res = F & {tries} < {retries}"
    lost = f"({from_main} & res = F & {tries} >= {retries}) | ({from_rec} & res = F)"
    _reset_all(x, resets, won)
    core.rule(cur, won, "0")
    core.rule(tries, won, "0")
    core.ret(won, x.id, "S")
    resets[main].append(retry)
    core.rule(cur, retry, "1")
    core.call(retry, recovery)
    _reset_all(x, resets, f"({lost})")
    core.rule(cur, f"({lost})", "0")
    core.rule(tries, f"({lost})", "0")
    core.ret(f"({lost})", x.id, "F")
    recovered = f"{from_rec} & res = S"
    resets[recovery].append(recovered)
    core.rule(cur, recovered, "0")
    core.rule(tries, recovered, increment(tries, max(retries, 0)))
    core.call(recovered, main)


def round_robin(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """RoundRobin (the module docstring)."""
    kids = list(x.children)
    n = len(kids)
    back = f"{here} & res != NONE"
    core.rule(core.st(x.id), called, "R")
    (wrap,) = x.params
    pos = core.memory("rr", x.id, n - 1)
    fails = core.memory("rf", x.id, n)
    for i, c in enumerate(kids):
        core.call(f"{called} & {pos} = {i}", c)
    core.ret(f"{back} & res = R", x.id, "R")
    for i in range(n):
        at = f"{back} & lidx = {i}"
        end = i + 1 == n and not wrap
        nxt = (i + 1) % n
        won, lost = f"{at} & res = S", f"{at} & res = F"
        if end:  # the last child completed without wrap-around: FAILURE (as Nav2 reads)
            _reset_all(x, resets, f"{at} & res != R")
            core.rule(pos, f"{at} & res != R", "0")
            core.rule(fails, f"{at} & res != R", "0")
            core.ret(f"{at} & res != R", x.id, "F")
            continue
        _reset_all(x, resets, won)
        core.rule(pos, won, str(nxt))
        core.rule(fails, won, "0")
        core.ret(won, x.id, "S")
        more = f"{lost} & {fails} < {n - 1}"
        core.rule(pos, more, str(nxt))
        core.rule(fails, more, increment(fails, n))
        core.call(more, kids[nxt])
        _reset_all(x, resets, lost)
        core.rule(pos, lost, "0")
        core.rule(fails, lost, "0")
        core.ret(lost, x.id, "F")


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "pipeline": pipeline,
    "recovery": recovery,
    "round_robin": round_robin,
}
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): the defaults
#: for each (a child that may return SKIPPED is refused; no leaf tick is guaranteed).
TRAITS: dict[str, RuleTraits] = {}
