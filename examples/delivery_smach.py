#!/usr/bin/env python
"""A delivery robot as a SMACH state machine (written for fsmbt's examples).

fsmbt reads this file statically - it is parsed, never imported or run - so it needs no ROS:

    fsmbt info examples/delivery_smach.py
    fsmbt convert examples/delivery_smach.py -o out/delivery_bt.xml --force
    fsmbt translate examples/delivery_smach.py -o out/delivery.scxml --force

It shows a nested StateMachine (DELIVER), a Concurrence whose outcome map needs both children
(LOAD: the arm grips while the base docks), a Sequence, and outcomes that fall through to the
container outcome of the same name (CHARGE's 'aborted').
"""

import smach


class WaitForOrder(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["order", "shutdown"])

    def execute(self, userdata):
        return "order"


class Dock(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["docked", "blocked"])

    def execute(self, userdata):
        return "docked"


class Grip(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["gripped", "slipped"])

    def execute(self, userdata):
        return "gripped"


class Drive(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["arrived", "lost"])

    def execute(self, userdata):
        return "arrived"


class Handover(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["done", "refused"])

    def execute(self, userdata):
        return "done"


class Charge(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["charged", "aborted"])

    def execute(self, userdata):
        return "charged"


def build():
    robot = smach.StateMachine(outcomes=["off", "aborted"])
    with robot:
        smach.StateMachine.add(
            "IDLE", WaitForOrder(), transitions={"order": "LOAD", "shutdown": "off"}
        )

        load = smach.Concurrence(
            outcomes=["loaded", "not_loaded"],
            default_outcome="not_loaded",
            outcome_map={"loaded": {"DOCK": "docked", "GRIP": "gripped"}},
        )
        with load:
            smach.Concurrence.add("DOCK", Dock())
            smach.Concurrence.add("GRIP", Grip())
        smach.StateMachine.add(
            "LOAD", load, transitions={"loaded": "DELIVER", "not_loaded": "IDLE"}
        )

        deliver = smach.Sequence(outcomes=["delivered", "failed"], connector_outcome="arrived")
        with deliver:
            smach.Sequence.add("DRIVE", Drive(), transitions={"lost": "failed"})
            smach.Sequence.add(
                "HANDOVER", Handover(), transitions={"done": "delivered", "refused": "failed"}
            )
        smach.StateMachine.add(
            "DELIVER", deliver, transitions={"delivered": "CHARGE", "failed": "IDLE"}
        )

        smach.StateMachine.add("CHARGE", Charge(), transitions={"charged": "IDLE"})
    return robot


if __name__ == "__main__":
    build().execute()
