"""The SMV tick rules of the built-in loops and parallels: Repeat, RetryUntilSuccessful, RunOnce,
Parallel and ParallelAll (docs/semantics.md, "Decorators" and "Control nodes"; docs/nusmv.md).

Each function adds one node's rules to a ``BTCore`` (``encode_bt``), as the interpreter's
rules in ``fsmbt.semantics.families.loops``, ``.once`` and ``.parallel`` do them
(BehaviorTree.CPP 4.8), in the same micro-step style: ``called`` is the node ticked with no
result yet, ``back`` a child's return (``res``; ``lidx`` says which child), ``resets[c]``
collects the conditions under which child ``c`` is reset (halted when RUNNING).

What each node keeps, and how it is encoded:

- Repeat / RetryUntilSuccessful (``num_cycles`` / ``num_attempts`` = L): the count is a memory
  variable ``lc_n`` in ``0..L-1`` reset by the node's halt (at rest the count is below L: the L-th
  repeated result ends the loop and resets it). With ``-1`` the interpreter keeps the count at 0
  (it is never read), so no variable is declared: the node's state is its status alone. The
  frame local ``prev_n`` (the child's status when it was called) decides the wake-up: after a
  synchronous child (``prev_n = I``) the loop returns RUNNING and asks the tree to re-tick.
  ``L <= 0`` (other than -1) never ticks the child.
- RunOnce: ``ro_n`` (0 not run yet, 1 succeeded, 2 failed) that a halt does **not** reset;
  once set the node returns it (``then_skip=false``) or SKIPPED (``then_skip=true``, the
  status ``K`` of ``res``, never stored) without ticking the child.
- SingleTrigger (Nav2): ``tr_n`` (triggered), cleared when the node is ticked while IDLE.
- Parallel / ParallelAll: the completed set and the counters are not variables. A child
  completed in this run of the parallel is exactly a child whose status is SUCCESS or FAILURE:
  a parallel never ticks a completed child again, and it resets every child whenever it
  completes (its halt clears them too), so the statuses already hold the memory; the success
  and failure counts are DEFINEs summing them (``psc_n``, ``pfc_n``). The threshold checks run
  after every child's return, in the interpreter's order (success first).

Cost: O(k²) rules for a parallel of k children (the next child not completed after each one),
O(1) for the decorators; one variable of log2(L) bits per finite loop, 2 bits per RunOnce.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.families.parallel import parallel_threshold
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets
from fsmbt.verify.nusmv.smv import all_of

#: The rule names (the node registry's ``nusmv`` field) this module encodes.
RULES = ("repeat", "retry", "run_once", "single_trigger", "parallel", "parallel_all")
#: Loop rule -> (the result that repeats the child, the one that ends the loop)
LOOPS = {"repeat": ("S", "F"), "retry": ("F", "S")}


def add_rules(
    core: BTCore, x: CompiledNode, rule: str, here: str, called: str, resets: Resets
) -> None:
    """Add node ``x``'s tick rules (``rule`` is one of ``RULES``)."""
    back = f"{here} & res != NONE"
    if rule in LOOPS:
        _loop(core, x, rule, called, back, resets)
    elif rule == "run_once":
        _run_once(core, x, called, back, resets)
    elif rule == "single_trigger":
        _single_trigger(core, x, called, back)
    else:
        _parallel(core, x, rule, called, back, resets)


def _loop(core: BTCore, x: CompiledNode, rule: str, called: str, back: str, resets: Resets) -> None:
    """Repeat / RetryUntilSuccessful (docs/semantics.md "Decorators"; ``loops.loop_decorator``)."""
    (limit,) = x.params
    again, stop = LOOPS[rule]
    c = x.children[0]
    prev = f"prev_{x.id}"
    if limit != -1 and limit <= 0:  # count < limit never holds: the child is never ticked
        core.ret(called, x.id, again)
        return
    core.rule(core.st(x.id), called, "R")
    core.call(called, c)
    core.rule(prev, called, core.st(c))
    core.ret(f"{back} & res = R", x.id, "R")
    resets[c].append(f"{back} & res != R")  # either result resets the child
    ended = f"{back} & res = {stop}"
    count = None if limit == -1 else core.memory("lc", x.id, limit - 1)
    if count is not None:
        core.rule(count, ended, "0")
    core.ret(ended, x.id, stop)
    repeated = f"{back} & res = {again}"
    if count is not None:
        last = f"{repeated} & {count} >= {limit - 1}"  # the L-th one: the loop is over
        core.rule(count, last, "0")
        core.ret(last, x.id, again)
        # exact conditions from here on: ``wake`` has no row for ``last`` to take precedence
        repeated = f"{repeated} & {count} < {limit - 1}"
        # below limit - 1 here (the bound keeps NuSMV's range check quiet on other states)
        core.rule(count, repeated, f"case {count} < {limit - 1} : {count} + 1; TRUE : 0; esac")
    woke = f"{repeated} & {prev} = I"  # a synchronous child: wake the tree, return RUNNING
    core.rule("wake", woke, "TRUE")
    core.ret(woke, x.id, "R")
    core.call(repeated, c)  # the child was RUNNING before this tick: tick it again at once
    core.rule(prev, repeated, "I")  # it has just been reset


def _run_once(core: BTCore, x: CompiledNode, called: str, back: str, resets: Resets) -> None:
    """RunOnce (docs/semantics.md "Decorators"; ``once.tick_run_once``); its memory survives halts."""
    (then_skip,) = x.params
    c = x.children[0]
    done = core.memory("ro", x.id, 2, reset_by_halt=False)
    if then_skip:  # SKIPPED after the first run (never stored: the status stays, §2)
        core.ret(f"{called} & {done} != 0", x.id, "K")
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


def _single_trigger(core: BTCore, x: CompiledNode, called: str, back: str) -> None:
    """Nav2 SingleTrigger (docs/semantics.md "Project nodes"; ``once.tick_single_trigger``):
    ``tr_n`` (triggered) is cleared when the node is ticked while IDLE, set when the child
    completes; ticked while active and triggered, the node returns FAILURE without ticking the
    child. The child is not reset on completion (as in Nav2); a halt keeps ``tr_n`` (the
    next activation clears it)."""
    c = x.children[0]
    st = core.st(x.id)
    triggered = core.memory("tr", x.id, 1, reset_by_halt=False)
    core.ret(f"{called} & {st} != I & {triggered} = 1", x.id, "F")
    core.rule(triggered, f"{called} & {st} = I", "0")
    core.rule(st, called, "R")
    core.call(called, c)
    core.rule(triggered, f"{back} & (res = S | res = F)", "1")
    core.ret(back, x.id, "case res = S : S; res = F : F; TRUE : R; esac")


def _parallel(
    core: BTCore, x: CompiledNode, rule: str, called: str, back: str, resets: Resets
) -> None:
    """Parallel (success/failure thresholds) and ParallelAll (max_failures): docs/semantics.md
    "Control nodes"; ``parallel.tick_parallel`` / ``tick_parallel_all``."""
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


def _named(rule: str) -> NusmvRule:
    """``add_rules`` for one rule name, in the registry's calling convention."""

    def encode(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
        add_rules(core, x, rule, here, called, resets)

    return encode


#: These rules by name, as ``fsmbt.verify.nusmv.families.registry`` registers them.
RULE_TABLE: dict[str, NusmvRule] = {name: _named(name) for name in RULES}
