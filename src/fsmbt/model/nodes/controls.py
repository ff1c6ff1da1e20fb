"""Control nodes (BehaviorTree.CPP ``src/controls``): one entry per kind.

The rules are summaries; docs/semantics.md ("Control nodes") is the reference. ``handler`` names
the interpreter's tick rule (``fsmbt.semantics.bt_interpreter``), ``nusmv`` the encoder's
(``fsmbt.verify.nusmv.encode_bt``).
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes.registry import Family, NodeSemantics, register

_C = NodeKind.CONTROL
_SEQ_MEMORY = ("current_child_idx", "skipped_count")

SEQUENCE = register(
    NodeSemantics(
        "Sequence",
        _C,
        Family.SEQUENCE,
        None,
        tick="ticks children left to right; a failure ends it with FAILURE and resets every child; "
        "a RUNNING child ends the tick and is resumed (not re-ticked from the start) next tick",
        halt="resets the running index and halts the running child",
        memory=_SEQ_MEMORY,
        default_memory=(0, 0),
        halt_resets_memory=True,
        mergeable=True,
        handler="sequence",
        nusmv="sequence",
        source="sequence_node.cpp",
    )
)
ASYNC_SEQUENCE = register(
    NodeSemantics(
        "AsyncSequence",
        _C,
        Family.SEQUENCE,
        None,
        tick="as Sequence, but after a child that was IDLE succeeds it returns RUNNING and asks for "
        "a wake-up instead of ticking the next child in the same tick",
        halt="resets the running index and halts the running child",
        memory=_SEQ_MEMORY,
        default_memory=(0, 0),
        halt_resets_memory=True,
        asynchronous=True,
        wakes_up=True,
        handler="sequence",
        nusmv="sequence",
        source="sequence_node.cpp",
    )
)
SEQUENCE_WITH_MEMORY = register(
    NodeSemantics(
        "SequenceWithMemory",
        _C,
        Family.SEQUENCE,
        None,
        tick="as AsyncSequence, but a failure keeps the index: the failed child is ticked again "
        "next time and earlier successes are not re-run",
        halt="halts the running child; keeps the index (the memory survives a halt)",
        memory=_SEQ_MEMORY,
        default_memory=(0, 0),
        with_memory=True,
        wakes_up=True,
        handler="sequence",
        nusmv="sequence",
        aliases=("SequenceStar",),
        source="sequence_with_memory_node.cpp",
    )
)
REACTIVE_SEQUENCE = register(
    NodeSemantics(
        "ReactiveSequence",
        _C,
        Family.SEQUENCE,
        None,
        tick="ticks children from the first on every tick; a RUNNING child halts every other child "
        "and ends the tick; a failure resets all children",
        halt="halts the running child; keeps no memory",
        reactive=True,
        handler="reactive",
        nusmv="reactive",
        source="reactive_sequence.cpp",
    )
)
FALLBACK = register(
    NodeSemantics(
        "Fallback",
        _C,
        Family.FALLBACK,
        None,
        tick="ticks children left to right; a success ends it with SUCCESS and resets every child; "
        "a RUNNING child ends the tick and is resumed next tick",
        halt="resets the running index and halts the running child",
        memory=_SEQ_MEMORY,
        default_memory=(0, 0),
        halt_resets_memory=True,
        mergeable=True,
        handler="sequence",
        nusmv="sequence",
        source="fallback_node.cpp",
    )
)
ASYNC_FALLBACK = register(
    NodeSemantics(
        "AsyncFallback",
        _C,
        Family.FALLBACK,
        None,
        tick="as Fallback, but after a child that was IDLE fails it returns RUNNING and asks for a "
        "wake-up",
        halt="resets the running index and halts the running child",
        memory=_SEQ_MEMORY,
        default_memory=(0, 0),
        halt_resets_memory=True,
        asynchronous=True,
        wakes_up=True,
        handler="sequence",
        nusmv="sequence",
        source="fallback_node.cpp",
    )
)
REACTIVE_FALLBACK = register(
    NodeSemantics(
        "ReactiveFallback",
        _C,
        Family.FALLBACK,
        None,
        tick="ticks children from the first on every tick; a RUNNING child halts every other child "
        "and ends the tick; a success resets all children",
        halt="halts the running child; keeps no memory",
        reactive=True,
        handler="reactive",
        nusmv="reactive",
        source="reactive_fallback.cpp",
    )
)
PARALLEL = register(
    NodeSemantics(
        "Parallel",
        _C,
        Family.PARALLEL,
        None,
        tick="ticks every child not yet completed; SUCCESS once success_count children succeeded, "
        "FAILURE once failure_count failed (negative counts mean all but -n-1); else RUNNING",
        halt="forgets the completed set and counters, halts running children",
        memory=("completed", "success_count", "failure_count"),
        default_memory=(frozenset(), 0, 0),
        halt_resets_memory=True,
        handler="parallel",
        nusmv="parallel",
        ports=("success_count", "failure_count"),
        source="parallel_node.cpp",
    )
)
PARALLEL_ALL = register(
    NodeSemantics(
        "ParallelAll",
        _C,
        Family.PARALLEL,
        None,
        tick="ticks every child not yet completed until all completed; then FAILURE if at least "
        "max_failures failed, else SUCCESS",
        halt="forgets the completed set and the failure count, halts running children",
        memory=("completed", "failure_count"),
        default_memory=(frozenset(), 0),
        halt_resets_memory=True,
        handler="parallel_all",
        nusmv="parallel_all",
        ports=("max_failures",),
        source="parallel_all_node.cpp",
    )
)
IF_THEN_ELSE = register(
    NodeSemantics(
        "IfThenElse",
        _C,
        Family.CONDITIONAL,
        None,
        child_counts=(2, 3),
        tick="ticks child 0 once; SUCCESS runs child 1, FAILURE runs child 2 (or returns FAILURE "
        "with two children); the condition is not re-ticked while the branch runs",
        halt="forgets the chosen branch, halts the running child",
        memory=("child_idx",),
        default_memory=(0,),
        halt_resets_memory=True,
        handler="if_then_else",
        nusmv="if_then_else",
        source="if_then_else_node.cpp",
    )
)
WHILE_DO_ELSE = register(
    NodeSemantics(
        "WhileDoElse",
        _C,
        Family.CONDITIONAL,
        None,
        child_counts=(2, 3),
        tick="ticks child 0 on every tick; SUCCESS runs child 1 (halting child 2), FAILURE runs "
        "child 2 (halting child 1) or returns FAILURE with two children",
        halt="halts the running child; keeps no memory",
        handler="while_do_else",
        nusmv="while_do_else",
        source="while_do_else_node.cpp",
    )
)
MANUAL_SELECTOR = register(
    NodeSemantics(
        "ManualSelector",
        _C,
        Family.MANUAL,
        None,
        tick="a person picks, on every tick, a child to tick or a status to return (SUCCESS, "
        "FAILURE, RUNNING); the node returns the picked child's status; a child left RUNNING by "
        "an earlier pick is not halted. With repeat_last_selection the first pick (a child) is "
        "ticked again on every later tick without asking. Without children the person picks a "
        "status. The pick is an environment input: chained choice conditions "
        "'<label>.pick_<i>', '<label>.pick_SUCCESS', '<label>.pick_FAILURE' (docs/semantics.md)",
        halt="halts its RUNNING children; keeps the repeated selection",
        min_children=0,
        memory=("previously_executed_idx",),
        default_memory=(-1,),
        handler="manual_selector",
        nusmv="manual_selector",
        ports=("repeat_last_selection",),
        source="manual_node.cpp",
    )
)

SWITCHES = tuple(
    register(
        NodeSemantics(
            f"Switch{n}",
            _C,
            Family.SWITCH,
            n + 1,
            tick=f"compares the blackboard value 'variable' with case_1..case_{n} and ticks the matching "
            "child (the last child is the default)",
            halt="halts the running child",
            blackboard_based=True,
            nusmv_refusal="its choice depends on the blackboard",
            ports=("variable",),
            source="switch_node.h",
        )
    )
    for n in range(2, 7)
)
