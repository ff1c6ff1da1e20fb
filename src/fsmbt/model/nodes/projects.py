"""Project node kinds: Nav2, MoveIt Pro, Groot 1 and BehaviorTree.CPP v3 built-ins.

Exact kinds (their tick rule is the project's source, read at Nav2 commit a3a9704; the rules in
our words are in docs/semantics.md, "Project nodes") are always available: their IDs are
unambiguous. Kinds whose control flow reads a clock, the robot's pose, a goal topic or a
blackboard value are *abstractions*: that input becomes an environment choice (a ``Gate``),
they are enabled by an option (``requires``: ``--nodes nav2`` / ``--nodes moveit_pro`` /
``--abstract blackboard``) and every verdict over a tree that uses one names the abstraction.
"""

from __future__ import annotations

from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes.registry import Family, Gate, NodeSemantics, register

_C, _D = NodeKind.CONTROL, NodeKind.DECORATOR
_NAV2 = "Nav2"
_CONTROLLER_HALT = "halts the child if running; the next tick after IDLE is a first tick again"

PIPELINE_SEQUENCE = register(
    NodeSemantics(
        "PipelineSequence",
        _C,
        Family.PIPELINE,
        None,
        tick="ticks every child from the first on each tick; a RUNNING child before the "
        "furthest one reached is passed over, the furthest RUNNING child ends the tick; a "
        "failure halts every child and returns FAILURE; all done: halt all, SUCCESS",
        halt="halts the children and forgets the furthest child reached",
        memory=("last_child_ticked",),
        default_memory=(0,),
        halt_resets_memory=True,
        handler="pipeline",
        nusmv="pipeline",
        library=_NAV2,
        source="nav2_behavior_tree/plugins/control/pipeline_sequence.cpp",
    )
)
RECOVERY_NODE = register(
    NodeSemantics(
        "RecoveryNode",
        _C,
        Family.RECOVERY,
        2,
        tick="ticks the main child; SUCCESS ends it with SUCCESS; FAILURE ticks the recovery "
        "child while retries remain (number_of_retries, default 1), whose SUCCESS counts a retry "
        "and ticks the main child again in the same tick; the recovery's FAILURE, or a main "
        "FAILURE with no retry left, ends it with FAILURE",
        halt="halts the children, forgets the retry count and the current child",
        memory=("current_child_idx", "retry_count"),
        default_memory=(0, 0),
        halt_resets_memory=True,
        handler="recovery",
        nusmv="recovery",
        ports=("number_of_retries",),
        library=_NAV2,
        source="nav2_behavior_tree/plugins/control/recovery_node.cpp",
    )
)
ROUND_ROBIN = register(
    NodeSemantics(
        "RoundRobin",
        _C,
        Family.ROUND_ROBIN,
        None,
        tick="ticks from the child after the last one that completed; a SUCCESS halts all and "
        "returns SUCCESS (the position is kept); a failure moves on; every child failed, or the "
        "last child completed with wrap_around=false (default): halt, FAILURE",
        halt="halts the children, forgets the position and the failure count",
        memory=("current_child_idx", "num_failed_children"),
        default_memory=(0, 0),
        halt_resets_memory=True,
        handler="round_robin",
        nusmv="round_robin",
        ports=("wrap_around",),
        library=_NAV2,
        source="nav2_behavior_tree/plugins/control/round_robin_node.cpp",
    )
)


def _controller(name: str, what: str, source: str) -> NodeSemantics:
    return register(
        NodeSemantics(
            name,
            _D,
            Family.CONTROLLER,
            1,
            tick=f"the first tick after IDLE and every tick with the child RUNNING tick the "
            f"child; otherwise the child is ticked only when {what} (else RUNNING); the child "
            "is not reset when it completes",
            halt=_CONTROLLER_HALT,
            handler="gated",
            nusmv="gated",
            requires="nav2",
            abstraction=f"{name} may skip its child on any tick (whether {what} is an "
            "environment input)",
            gate=Gate("gate", free_when_idle=True, reset_on_done=False),
            library=_NAV2,
            source=f"nav2_behavior_tree/plugins/decorator/{source}",
        )
    )


RATE_CONTROLLER = _controller("RateController", "its period has elapsed", "rate_controller.cpp")
DISTANCE_CONTROLLER = _controller(
    "DistanceController", "the robot travelled the distance", "distance_controller.cpp"
)
SPEED_CONTROLLER = _controller(
    "SpeedController", "the speed-scaled period has elapsed", "speed_controller.cpp"
)
GOAL_UPDATED_CONTROLLER = register(
    NodeSemantics(
        "GoalUpdatedController",
        _D,
        Family.CONTROLLER,
        1,
        tick="the first tick after IDLE and every tick with the child RUNNING tick the child; "
        "otherwise the child is ticked only when the goal was updated (else RUNNING)",
        halt=_CONTROLLER_HALT,
        handler="gated",
        nusmv="gated",
        requires="nav2",
        abstraction="GoalUpdatedController may skip its child on any tick (whether the goal was "
        "updated is an environment input)",
        gate=Gate("gate", free_when_idle=True, reset_on_done=False),
        library=_NAV2,
        source="nav2_behavior_tree/plugins/decorator/goal_updated_controller.cpp",
    )
)
PATH_LONGER_ON_APPROACH = register(
    NodeSemantics(
        "PathLongerOnApproach",
        _D,
        Family.CONTROLLER,
        1,
        tick="ticks the child only when a new, longer path arrived near the goal (else "
        "SUCCESS without ticking it); a completed child is reset",
        handler="gated",
        nusmv="gated",
        requires="nav2",
        abstraction="PathLongerOnApproach: whether a longer path arrived near the goal is an "
        "environment input on every tick (no: SUCCESS without ticking the child)",
        gate=Gate("gate", free_when_running=False, closed="SUCCESS", halt_on_closed=False),
        ports=("path", "prox_len", "length_factor"),
        library=_NAV2,
        source="nav2_behavior_tree/plugins/decorator/path_longer_on_approach.cpp",
    )
)
GOAL_UPDATER = register(
    NodeSemantics(
        "GoalUpdater",
        _D,
        Family.WRAPPER,
        1,
        tick="writes the latest goal to its output port, ticks the child and returns its "
        "status (the child is not reset)",
        halt="halts the child if running",
        handler="pass_through_keep",
        nusmv="pass_through_keep",
        requires="nav2",
        abstraction="GoalUpdater: the goal it writes to the blackboard is not modelled (it "
        "passes its child's status on)",
        ports=("input_goal", "output_goal"),
        library=_NAV2,
        source="nav2_behavior_tree/plugins/decorator/goal_updater_node.cpp",
    )
)
SINGLE_TRIGGER = register(
    NodeSemantics(
        "SingleTrigger",
        _D,
        Family.ONCE,
        1,
        tick="ticks the child until it completes once after the node became active; while the "
        "node stays active afterwards it returns FAILURE",
        halt="halts the child; the next activation runs the child again",
        memory=("triggered",),
        default_memory=(False,),
        handler="single_trigger",
        nusmv="single_trigger",
        library=_NAV2,
        source="nav2_behavior_tree/plugins/decorator/single_trigger_node.cpp",
    )
)

# -- MoveIt Pro ---------------------------------------------------------------------------------
REPEAT_EACH_TICK = register(
    NodeSemantics(
        "RepeatUnlessFailureEachTick",
        _D,
        Family.LOOP,
        1,
        tick="ticks the child; each SUCCESS counts a cycle and returns RUNNING (the next cycle "
        "runs on the next tick, no wake-up); num_cycles successes (default -1: never) return "
        "SUCCESS; FAILURE returns FAILURE",
        halt="forgets the cycle count, halts the child",
        memory=("repeat_count",),
        default_memory=(0,),
        halt_resets_memory=True,
        handler="repeat_each_tick",
        nusmv="repeat_each_tick",
        ports=("num_cycles",),
        library="MoveIt Pro",
        source="docs.picknik.ai: moveit_pro::behaviors::RepeatUnlessFailureEachTick",
    )
)
FOR_EACH = register(
    NodeSemantics(
        "ForEach",
        _D,
        Family.ITERATOR,
        1,
        tick="for each element of the vector_in blackboard vector: writes it to 'out' and ticks "
        "the child; a child FAILURE returns FAILURE; a SUCCESS moves to the next element (RUNNING); "
        "no element left: SUCCESS",
        halt="forgets the position, halts the child",
        handler="for_each",
        nusmv="for_each",
        requires="moveit_pro",
        abstraction="ForEach: whether its vector has another element is an environment input "
        "(asked before each child run)",
        gate=Gate("more", closed="SUCCESS"),
        ports=("vector_in", "out"),
        library="MoveIt Pro",
        source="docs.picknik.ai: ForEach",
    )
)
FOR_EACH_UNTIL_SUCCESS = register(
    NodeSemantics(
        "ForEachUntilSuccess",
        _D,
        Family.ITERATOR,
        1,
        tick="as ForEach, but a child SUCCESS returns SUCCESS and a FAILURE moves to the next "
        "element; no element left: FAILURE",
        halt="forgets the position, halts the child",
        handler="for_each",
        nusmv="for_each",
        requires="moveit_pro",
        abstraction="ForEachUntilSuccess: whether its vector has another element is an "
        "environment input (asked before each child run)",
        gate=Gate("more", closed="FAILURE"),
        ports=("vector_in", "out", "index"),
        library="MoveIt Pro",
        source="docs.picknik.ai: ForEachUntilSuccess",
    )
)

# -- Groot 1 and BehaviorTree.CPP v3 -------------------------------------------------------------
ROOT = register(
    NodeSemantics(
        "Root",
        _D,
        Family.WRAPPER,
        1,
        tick="Groot 1's editor wrapper around the tree's root: ticks the child and returns its "
        "status (the child is reset when it completes, as a SubTree does)",
        halt="halts the child if running",
        handler="pass_through",
        nusmv="pass_through",
        library="Groot 1",
        source="Groot 1 editor files (<Root> wrapping the root node)",
    )
)
BLACKBOARD_CHECKS = tuple(
    register(
        NodeSemantics(
            f"BlackboardCheck{value}",
            _D,
            Family.GATE,
            1,
            tick="ticks the child when the blackboard values value_A and value_B are equal "
            "(a RUNNING child is ticked again without comparing); else returns "
            "return_on_mismatch",
            halt="halts the child if running",
            blackboard_based=True,
            handler="gated",
            nusmv="gated",
            requires="blackboard",
            abstraction=f"BlackboardCheck{value}: whether value_A equals value_B is an "
            "environment input (mismatch: return_on_mismatch)",
            gate=Gate("match", free_when_running=False, closed="FAILURE", reset_on_done=False),
            closed_port="return_on_mismatch",
            ports=("value_A", "value_B", "return_on_mismatch"),
            rejection="its result depends on the blackboard",
            source="BehaviorTree.CPP 3.8 blackboard_precondition.h",
        )
    )
    for value in ("String", "Int", "Double")
)

# -- project controls read from their sources, enabled by a node-library file -------------------
# Their bare names (``RealParallel``) are a project's own registrations, which another project
# may define differently, so the registered kind is qualified by the project and a node-library
# file maps the bare name to it (node_libraries/, docs/semantics.md "Project nodes").
REAL_PARALLEL = register(
    NodeSemantics(
        "stardust.RealParallel",
        _C,
        Family.PARALLEL,
        None,
        tick="ticks every child on every tick, in order, whatever they returned before (a "
        "completed child is not reset, so a completed action keeps its status); any RUNNING "
        "child: RUNNING, else any FAILURE: FAILURE, else SUCCESS",
        halt="halts the RUNNING children and resets every child's status",
        handler="real_parallel",
        nusmv="real_parallel",
        library="julienbayle/stardust",
        source="julienbayle/stardust@f680da70 ros/src/sd_behavior/src/control_nodes.cpp "
        "(RealParallelNode::tick)",
    )
)
