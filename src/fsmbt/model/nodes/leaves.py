"""Built-in leaves and the SubTree reference (BehaviorTree.CPP ``src/actions``, ``subtree_node``).

Environment leaves (the user's own actions and conditions) are not in the registry: they are
whatever type the file declares, an Action may return RUNNING, a Condition may not
(docs/semantics.md, "Leaves"). The built-ins here are internal (a fixed result, never observed),
time-based or blackboard-based.
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes.registry import Family, Gate, NodeSemantics, register

_A, _Q = NodeKind.ACTION, NodeKind.CONDITION
_BLACKBOARD = "its result depends on the blackboard"


def _internal(name: str, result: str, what: str, source: str) -> NodeSemantics:
    return register(
        NodeSemantics(
            name,
            _A,
            Family.INTERNAL_LEAF,
            0,
            tick=f"{what}; returns {result} (never RUNNING)",
            halt="nothing to halt",
            internal_result=result,
            nusmv="internal_leaf",
            source=source,
        )
    )


ALWAYS_SUCCESS = _internal("AlwaysSuccess", "SUCCESS", "does nothing", "always_success_node.h")
ALWAYS_FAILURE = _internal("AlwaysFailure", "FAILURE", "does nothing", "always_failure_node.h")
SCRIPT = _internal(
    "Script", "SUCCESS", "runs a blackboard script (no control flow is read)", "script_node.h"
)
SET_BLACKBOARD = _internal(
    "SetBlackboard", "SUCCESS", "writes a blackboard entry", "set_blackboard_node.h"
)
UNSET_BLACKBOARD = _internal(
    "UnsetBlackboard", "SUCCESS", "removes a blackboard entry", "unset_blackboard_node.h"
)
SLEEP = register(
    NodeSemantics(
        "Sleep",
        _A,
        Family.TIMER,
        0,
        tick="returns RUNNING for msec milliseconds, then SUCCESS",
        halt="cancels its timer",
        time_based=True,
        rejection="time-based node (needs a clock)",
        ports=("msec",),
        handler="sleep",
        nusmv="sleep",
        requires="time",
        abstraction="Sleep: whether its time is up is an environment input, asked on every tick "
        "(not yet: RUNNING, then SUCCESS)",
        gate=Gate("timer", closed="RUNNING"),
        source="sleep_node.cpp",
    )
)
SCRIPT_CONDITION = register(
    NodeSemantics(
        "ScriptCondition",
        _Q,
        Family.BLACKBOARD_LEAF,
        0,
        tick="evaluates a script on the blackboard: SUCCESS if true, else FAILURE",
        halt="nothing to halt",
        blackboard_based=True,
        rejection=_BLACKBOARD,
        nusmv_refusal=_BLACKBOARD,
        ports=("code",),
        handler="env_condition",
        requires="blackboard",
        abstraction="ScriptCondition: its script's value is an environment input (a condition)",
        source="script_condition.h",
    )
)
WAS_ENTRY_UPDATED = register(
    NodeSemantics(
        "WasEntryUpdated",
        _Q,
        Family.BLACKBOARD_LEAF,
        0,
        tick="SUCCESS if a blackboard entry changed since the last tick, else FAILURE",
        halt="nothing to halt",
        blackboard_based=True,
        rejection=_BLACKBOARD,
        nusmv_refusal=_BLACKBOARD,
        ports=("entry",),
        handler="env_condition",
        requires="blackboard",
        abstraction="WasEntryUpdated: whether the entry was updated is an environment input "
        "(a condition)",
        source="updated_action.cpp",
    )
)
SUBTREE = register(
    NodeSemantics(
        "SubTree",
        NodeKind.SUBTREE,
        Family.SUBTREE,
        0,
        tick="ticks the referenced tree's root and returns its result (port remapping does not "
        "change control flow); after SubTree expansion it has that root as its one child",
        halt="halts the referenced tree",
        handler="subtree",
        nusmv="subtree",
        ports=("ID",),
        aliases=("SubTreePlus",),
        source="subtree_node.cpp",
    )
)
