"""Decorator nodes (BehaviorTree.CPP ``src/decorators``): one entry per kind, one child each.

The rules are summaries; docs/semantics.md ("Decorators") is the reference.
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes.registry import Family, Gate, NodeSemantics, register

_D = NodeKind.DECORATOR
_BLACKBOARD = "its result depends on the blackboard"
_CLOCK = "time-based node (needs a clock)"
_RESET = "halts the child if running; keeps no memory"

INVERTER = register(
    NodeSemantics(
        "Inverter",
        _D,
        Family.STATUS_MAP,
        1,
        tick="ticks the child; SUCCESS becomes FAILURE and FAILURE becomes SUCCESS; RUNNING and "
        "SKIPPED pass through",
        halt=_RESET,
        result_map=("FAILURE", "SUCCESS"),
        handler="simple_decorator",
        nusmv="simple_decorator",
        source="inverter_node.cpp",
    )
)
FORCE_SUCCESS = register(
    NodeSemantics(
        "ForceSuccess",
        _D,
        Family.STATUS_MAP,
        1,
        tick="ticks the child; SUCCESS and FAILURE become SUCCESS; RUNNING and SKIPPED pass through",
        halt=_RESET,
        result_map=("SUCCESS", "SUCCESS"),
        handler="simple_decorator",
        nusmv="simple_decorator",
        source="force_success_node.h",
    )
)
FORCE_FAILURE = register(
    NodeSemantics(
        "ForceFailure",
        _D,
        Family.STATUS_MAP,
        1,
        tick="ticks the child; SUCCESS and FAILURE become FAILURE; RUNNING and SKIPPED pass through",
        halt=_RESET,
        result_map=("FAILURE", "FAILURE"),
        handler="simple_decorator",
        nusmv="simple_decorator",
        source="force_failure_node.h",
    )
)
KEEP_RUNNING_UNTIL_FAILURE = register(
    NodeSemantics(
        "KeepRunningUntilFailure",
        _D,
        Family.STATUS_MAP,
        1,
        tick="ticks the child; FAILURE ends it with FAILURE, SUCCESS resets the child and returns "
        "RUNNING (the child is ticked afresh next tick)",
        halt=_RESET,
        handler="simple_decorator",
        nusmv="simple_decorator",
        source="keep_running_until_failure_node.h",
    )
)
REPEAT = register(
    NodeSemantics(
        "Repeat",
        _D,
        Family.LOOP,
        1,
        tick="ticks the child again after each SUCCESS, num_cycles times (-1: forever); FAILURE "
        "ends it; after a synchronous success it asks for a wake-up and returns RUNNING",
        halt="forgets the cycle count, halts the child",
        memory=("repeat_count",),
        default_memory=(0,),
        halt_resets_memory=True,
        wakes_up=True,
        handler="repeat",
        nusmv="repeat",
        ports=("num_cycles",),
        source="repeat_node.cpp",
    )
)
RETRY_UNTIL_SUCCESSFUL = register(
    NodeSemantics(
        "RetryUntilSuccessful",
        _D,
        Family.LOOP,
        1,
        tick="ticks the child again after each FAILURE, num_attempts times (-1: forever); SUCCESS "
        "ends it; after a synchronous failure it asks for a wake-up and returns RUNNING",
        halt="forgets the attempt count, halts the child",
        memory=("try_count",),
        default_memory=(0,),
        halt_resets_memory=True,
        wakes_up=True,
        handler="retry",
        nusmv="retry",
        ports=("num_attempts",),
        aliases=("RetryUntilSuccesful",),
        source="retry_node.cpp",
    )
)
RUN_ONCE = register(
    NodeSemantics(
        "RunOnce",
        _D,
        Family.ONCE,
        1,
        tick="ticks the child until it completes once; afterwards returns SKIPPED (then_skip=true) "
        "or the remembered result without ticking it",
        halt="halts the child; keeps the memory (the node stays 'already run')",
        memory=("already_ticked", "returned_status"),
        default_memory=(False, 0),
        handler="run_once",
        nusmv="run_once",
        ports=("then_skip",),
        source="run_once_node.h",
    )
)
PRECONDITION = register(
    NodeSemantics(
        "Precondition",
        _D,
        Family.GATE,
        1,
        tick="evaluates a script on the blackboard to decide whether the child runs",
        blackboard_based=True,
        rejection=_BLACKBOARD,
        ports=("if", "else"),
        handler="gated",
        nusmv="gated",
        requires="blackboard",
        abstraction="Precondition: whether its 'if' script holds is an environment input, asked "
        "while its child is not running (closed: it returns its 'else' status)",
        gate=Gate("if", closed="FAILURE"),
        closed_port="else",
        source="script_precondition.h",
    )
)
SKIP_UNLESS_UPDATED = register(
    NodeSemantics(
        "SkipUnlessUpdated",
        _D,
        Family.GATE,
        1,
        tick="ticks the child only if a blackboard entry changed since the last tick",
        blackboard_based=True,
        rejection=_BLACKBOARD,
        ports=("entry",),
        handler="gated",
        nusmv="gated",
        requires="blackboard",
        abstraction="SkipUnlessUpdated: whether the entry was updated is an environment input, "
        "asked while its child is not running (not updated: SKIPPED)",
        gate=Gate("updated", closed="SKIPPED"),
        source="updated_decorator.cpp",
    )
)
WAIT_VALUE_UPDATE = register(
    NodeSemantics(
        "WaitValueUpdate",
        _D,
        Family.GATE,
        1,
        tick="returns RUNNING until a blackboard entry changes, then ticks the child",
        blackboard_based=True,
        rejection=_BLACKBOARD,
        ports=("entry",),
        handler="gated",
        nusmv="gated",
        requires="blackboard",
        abstraction="WaitValueUpdate: whether the entry was updated is an environment input, "
        "asked while its child is not running (not yet: RUNNING)",
        gate=Gate("updated", closed="RUNNING"),
        source="updated_decorator.cpp",
    )
)
#: BehaviorTree.CPP 4.8 LoopNode<T> (loop_node.h), registered as LoopInt, LoopBool, LoopDouble
#: and LoopString. A literal queue ("1;2;3") is copied when the node starts (IDLE): its rules
#: are exact, one element per tick. A {blackboard} queue is the environment's: an abstraction.
LOOPS = tuple(
    register(
        NodeSemantics(
            f"Loop{value}",
            _D,
            Family.BLACKBOARD_LOOP,
            1,
            tick="when not RUNNING it reloads its queue; while the child is not RUNNING it pops "
            f"the next {value.lower()} value to 'value' and ticks the child; an empty queue "
            "returns if_empty (default SUCCESS) without ticking it; the child's SUCCESS resets "
            "it and returns RUNNING (the next value on the next tick, no wake-up), FAILURE "
            "resets it and returns FAILURE, RUNNING and SKIPPED return RUNNING",
            halt="halts the child; the queue is reloaded on the next start",
            memory=("left_in_queue", "child_running"),
            default_memory=(0, False),
            halt_resets_memory=True,
            blackboard_based=True,
            rejection="its queue is read from the blackboard",
            handler="loop_queue",
            nusmv="loop_queue",
            ports=("queue", "value", "if_empty"),
            requires="blackboard",
            abstraction=f"Loop{value}: whether its blackboard queue still has an element is an "
            "environment input, asked while its child is not running (no element: if_empty)",
            gate=Gate("more", closed="SUCCESS"),
            closed_port="if_empty",
            abstract_port="queue",
            source="loop_node.h",
        )
    )
    for value in ("Int", "Bool", "Double", "String")
)
DELAY = register(
    NodeSemantics(
        "Delay",
        _D,
        Family.TIMER,
        1,
        tick="returns RUNNING for delay_msec milliseconds, then ticks the child",
        time_based=True,
        rejection=_CLOCK,
        ports=("delay_msec",),
        handler="gated",
        nusmv="gated",
        requires="time",
        abstraction="Delay: whether its delay has elapsed is an environment input, asked until "
        "the child starts (not yet: RUNNING)",
        gate=Gate("timer", closed="RUNNING"),
        source="delay_node.cpp",
    )
)
TIMEOUT = register(
    NodeSemantics(
        "Timeout",
        _D,
        Family.TIMER,
        1,
        tick="ticks the child; halts it and returns FAILURE after msec milliseconds",
        time_based=True,
        rejection=_CLOCK,
        ports=("msec",),
        handler="timeout",
        nusmv="timeout",
        requires="time",
        abstraction="Timeout: whether its timer has fired is an environment input, asked on "
        "every tick after the first (fired: the child is halted, FAILURE)",
        gate=Gate("timer", closed="FAILURE"),
        source="timeout_node.h",
    )
)
