"""NuSMV rules of the loop family: Repeat, RetryUntilSuccessful (docs/semantics.md
"Decorators"; docs/nusmv.md), mirroring ``fsmbt.semantics.families.loops`` (``tick_repeat``,
``tick_retry``; BehaviorTree.CPP 4.8 repeat_node.cpp, retry_node.cpp).

Rules ``repeat`` / ``retry`` (``num_cycles`` / ``num_attempts`` = L): the count is a memory
variable ``lc_n`` in ``0..L-1`` reset by the node's halt (at rest the count is below L: the L-th
repeated result ends the loop and resets it). With ``-1`` the interpreter keeps the count at 0
(it is never read), so no variable is declared: the node's state is its status alone. The frame
local ``prev_n`` (the child's status when it was called; declared by the encoder for the kinds
in ``LOOP_KINDS``) decides the wake-up: after a synchronous child (``prev_n = I``) the loop
returns RUNNING and asks the tree to re-tick. ``L <= 0`` (other than -1) never ticks the child.

Cost: O(1) rules per node; one variable of log2(L) bits per finite loop.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import all_nodes
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, named

#: Loop rule -> (the result that repeats the child, the one that ends the loop)
LOOPS = {"repeat": ("S", "F"), "retry": ("F", "S")}
#: Kind -> its loop rule (the kinds whose frame keeps ``prev_n``).
LOOP_KINDS = {n.name: n.nusmv for n in all_nodes() if n.nusmv in LOOPS}


def loop(core: BTCore, x: CompiledNode, rule: str, here: str, called: str, resets: Resets) -> None:
    """Repeat / RetryUntilSuccessful (``rule`` in ``LOOPS``; the module docstring)."""
    back = f"{here} & res != NONE"
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


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "repeat": named(loop, "repeat"),
    "retry": named(loop, "retry"),
}
