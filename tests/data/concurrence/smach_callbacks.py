import smach


class Two(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["done", "failed"])


def child_term_cb(outcome_map):
    return True


def out_cb(outcome_map):
    if outcome_map["A"] == "done":
        return "ok"
    return "bad"


def build():
    sm = smach.StateMachine(outcomes=["finished", "gave_up"])
    with sm:
        cc = smach.Concurrence(
            outcomes=["ok", "bad"],
            default_outcome="bad",
            child_termination_cb=child_term_cb,
            outcome_cb=out_cb,
        )
        with cc:
            smach.Concurrence.add("A", Two())
            smach.Concurrence.add("B", Two())
        smach.StateMachine.add("CC", cc, transitions={"ok": "finished", "bad": "gave_up"})
    return sm
