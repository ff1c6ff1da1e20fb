#!/usr/bin/env python
"""A pick-and-place robot as a SMACH state machine, with a retry (written for fsmbt's examples).

fsmbt reads this file statically - parsed, never imported or run - so it needs no ROS. Its
behavior tree, written as a person would write it, is `pick_place_bt.xml` beside it; the
migration path (docs/runtime.md, "The migration path") turns that tree into the C++ or Python
classes you fill in:

    fsmbt convert examples/pick_place_smach.py -o out/pick_place_lebt.xml --force
    fsmbt runtime cpp out/pick_place_cpp examples/pick_place_bt.xml
    fsmbt runtime python out/pick_place_py examples/pick_place_bt.xml

DETECT looks for the object until it sees one; GRASP tries to pick it up, and when the grasp
fails the robot looks again (the retry); PLACE puts it at its location.
"""

import smach


class Detect(smach.State):
    def __init__(self, timeout=2.0):
        smach.State.__init__(self, outcomes=['found', 'not_found'], output_keys=['object_pose'])
        self.timeout = timeout

    def execute(self, userdata):
        userdata.object_pose = (0.4, 0.1, 0.02)
        return 'found'


class Grasp(smach.State):
    def __init__(self, force=10.0):
        smach.State.__init__(self, outcomes=['grasped', 'failed'], input_keys=['object_pose'])
        self.force = force

    def execute(self, userdata):
        return 'grasped'


class Place(smach.State):
    def __init__(self, location='bin'):
        smach.State.__init__(self, outcomes=['placed', 'failed'])
        self.location = location

    def execute(self, userdata):
        return 'placed'


def main():
    sm = smach.StateMachine(outcomes=['succeeded', 'aborted'])
    with sm:
        smach.StateMachine.add('DETECT', Detect(timeout=2.0),
                               transitions={'found': 'GRASP', 'not_found': 'DETECT'},
                               remapping={'object_pose': 'pose'})
        smach.StateMachine.add('GRASP', Grasp(force=10.0),
                               transitions={'grasped': 'PLACE', 'failed': 'DETECT'},
                               remapping={'object_pose': 'pose'})
        smach.StateMachine.add('PLACE', Place(location='bin'),
                               transitions={'placed': 'succeeded', 'failed': 'aborted'})
    return sm.execute()


if __name__ == '__main__':
    main()
