"""NuSMV rules of the loop family: Repeat, RetryUntilSuccessful, MoveIt Pro
RepeatUnlessFailureEachTick and LoopInt/LoopBool/LoopDouble/LoopString (docs/semantics.md
"Decorators", "Project nodes", "LoopInt, LoopBool, LoopDouble, LoopString", §10; docs/nusmv.md),
mirroring ``fsmbt.semantics.families.loops`` (``tick_repeat``, ``tick_retry``,
``tick_repeat_each_tick``, ``tick_loop_queue``; BehaviorTree.CPP 4.8 repeat_node.cpp,
retry_node.cpp, loop_node.h).

- ``repeat`` / ``retry`` / ``retry`` (``num_cycles`` / ``num_attempts`` = L): the count is a memory
variable ``lc_n`` in ``0..L-1`` reset by the node's halt (at rest the count is below L: the L-th
repeated result ends the loop and resets it). With ``-1`` the interpreter keeps the count at 0
(it is never read), so no variable is declared: the node's state is its status alone. The frame
local ``prev_n`` (the child's status when it was called; declared by the encoder, as
``TRAITS`` below asks) decides the wake-up: after a synchronous child (``prev_n = I``) the loop
returns RUNNING and asks the tree to re-tick. ``L <= 0`` (other than -1) never ticks the child.
- ``repeat_each_tick`` (``num_cycles`` = L): one cycle per tick, no wake-up: a SUCCESS returns
  RUNNING until the L-th (count ``rc_n`` in ``0..L-1``, reset by a halt; none for -1), FAILURE
  ends it; either completion resets the child.
- ``loop_queue`` (``params = (if_empty, length)``): a literal queue keeps ``lq_n`` (elements
  left, reloaded when the node is ticked while IDLE, reset by a halt); a {blackboard} queue
  (``length = -1``) asks its gate, the last child (a condition leaf the environment answers),
  whether an element is left. Either way an element is taken only while the child is not
  RUNNING; an empty queue returns ``if_empty`` (SKIPPED is refused), a child's FAILURE ends the
  loop, any other completion leaves it RUNNING.

Cost: O(1) rules per node; one variable of log2(L) bits per finite loop or literal queue.
"""

from __future__ import annotations

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.nodes import NodeSemantics
from fsmbt.verify.nusmv.families.common import increment, returned_status
from fsmbt.verify.nusmv.families.contract import BTCore, NusmvRule, Resets, RuleTraits, named

#: Loop rule -> (the result that repeats the child, the one that ends the loop)
LOOPS = {"repeat": ("S", "F"), "retry": ("F", "S")}


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


def repeat_each_tick(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """RepeatUnlessFailureEachTick (the module docstring)."""
    back = f"{here} & res != NONE"
    core.rule(core.st(x.id), called, "R")
    (limit,) = x.params
    c = x.children[0]
    core.call(called, c)
    core.ret(f"{back} & res = R", x.id, "R")
    done = f"{back} & (res = S | res = F)"
    resets[c].append(done)
    if limit == -1:
        core.ret(f"{back} & res = S", x.id, "R")
        core.ret(back, x.id, "F")
        return
    count = core.memory("rc", x.id, limit - 1)
    core.rule(count, f"{back} & res = F", "0")
    core.ret(f"{back} & res = F", x.id, "F")
    finished = f"{back} & res = S & {count} >= {limit - 1}"
    core.rule(count, finished, "0")
    core.ret(finished, x.id, "S")
    core.rule(count, f"{back} & res = S", increment(count, limit - 1))
    core.ret(f"{back} & res = S", x.id, "R")


def loop_queue(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
    """LoopInt & co (loop_node.h; the module docstring)."""
    if_empty, length = x.params
    empty = returned_status(x, if_empty, " on an empty queue")
    kids = list(x.children)
    c = kids[0]
    back = f"{here} & res != NONE"
    from_child = f"{back} & lidx = 0"
    resumed = f"{called} & {core.st(c)} = R"
    if length < 0:
        gate = kids[-1]
        from_gate = f"{back} & lidx = {len(kids) - 1}"
        resets[gate].append(from_gate)
        core.rule(core.st(x.id), resumed, "R")
        core.call(resumed, c)
        core.call(called, gate)
        opened = f"{from_gate} & res = S"
        core.rule(core.st(x.id), opened, "R")
        core.call(opened, c)
        core.ret(from_gate, x.id, empty)
    else:
        left = core.memory("lq", x.id, length)
        fresh = f"{called} & {core.st(x.id)} = I"
        if length == 0:
            core.ret(fresh, x.id, empty)
        else:
            core.rule(left, fresh, str(length - 1))
            core.rule(core.st(x.id), fresh, "R")
            core.call(fresh, c)
        core.rule(left, resumed, left)  # a RUNNING child: nothing is popped
        core.rule(core.st(x.id), resumed, "R")
        core.call(resumed, c)
        more = f"{called} & {left} > 0"
        core.rule(left, more, f"case {left} > 0 : {left} - 1; TRUE : 0; esac")
        core.rule(core.st(x.id), more, "R")
        core.call(more, c)
        core.ret(called, x.id, empty)
    core.ret(f"{from_child} & res = R", x.id, "R")
    resets[c].append(f"{from_child} & res != R")
    core.ret(f"{from_child} & res = F", x.id, "F")
    core.ret(from_child, x.id, "R")


#: This family's rules by name (``registry`` merges the families' tables).
RULES: dict[str, NusmvRule] = {
    "repeat": named(loop, "repeat"),
    "retry": named(loop, "retry"),
    "repeat_each_tick": repeat_each_tick,
    "loop_queue": loop_queue,
}


def _never_ticks(x: CompiledNode, spec: NodeSemantics) -> bool:
    """A count <= 0 other than -1 answers without ticking the child."""
    limit: int = x.params[0]
    return -1 != limit <= 0


def _endless(x: CompiledNode, spec: NodeSemantics) -> bool:
    """A count of -1 loops without end."""
    return bool(x.params[0] == -1)


_LOOP_TRAITS = RuleTraits(prev=True, answers_alone=_never_ticks, ticks_forever=_endless)
#: What the encoder's whole-tree checks read of them (``contract.RuleTraits``): Repeat and
#: RetryUntilSuccessful keep ``prev_n`` (the wake-up test), may answer without ticking the
#: child or loop forever by their count; the others have the defaults.
TRAITS: dict[str, RuleTraits] = {"repeat": _LOOP_TRAITS, "retry": _LOOP_TRAITS}
