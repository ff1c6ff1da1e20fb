"""A patrol robot as a YASMIN (ROS 2) program: fsmbt reads it statically, never runs it.

The states' classes live in the robot's own package (not here): fsmbt needs only how the
machine is built. `fsmbt convert examples/patrol_yasmin.py -o out/patrol_bt.xml`.
"""

import rclpy
from patrol_states import Charge, Dock, GoTo, Look
from yasmin import OrthogonalState, StateMachine
from yasmin_ros.basic_outcomes import ABORT, SUCCEED


def build() -> StateMachine:
    inspect = StateMachine(outcomes=["done"])
    inspect.add_state("LOOK", Look(), transitions={"seen": "done", "nothing": "LOOK"})
    charge = StateMachine(outcomes=["done"])
    charge.add_state("CHARGE", Charge(), transitions={"full": "done"})
    pause = OrthogonalState("done", {"done": {"INSPECT": "done", "CHARGE": "done"}})
    pause.add_region("INSPECT", inspect)
    pause.add_region("CHARGE", charge)

    sm = StateMachine(outcomes=["finished", ABORT])
    sm.add_state(
        "GO_TO_A",
        GoTo(waypoint="A", speed=0.4),
        transitions={SUCCEED: "GO_TO_B", ABORT: "DOCK"},
        remappings={"pose": "waypoint_a"},
    )
    sm.add_state("GO_TO_B", GoTo(waypoint="B"), transitions={SUCCEED: "PAUSE", ABORT: "DOCK"})
    sm.add_state("PAUSE", pause, transitions={"done": "GO_TO_A"})
    sm.add_state("DOCK", Dock(), transitions={SUCCEED: "finished", ABORT: ABORT})
    return sm


def main() -> None:
    rclpy.init()
    build()()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
