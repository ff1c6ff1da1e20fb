import smach


class Two(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["done", "failed"])


def build():
    sm = smach.StateMachine(outcomes=["finished", "gave_up"])
    with sm:
        cc = smach.Concurrence(
            outcomes=["ok", "bad"],
            default_outcome="bad",
            outcome_map={"ok": {"NAV": "arrived", "WATCH": "done"}},
        )
        with cc:
            nav = smach.StateMachine(outcomes=["arrived", "lost"])
            with nav:
                smach.StateMachine.add(
                    "PLAN", Two(), transitions={"done": "DRIVE", "failed": "ALT"}
                )
                smach.StateMachine.add(
                    "ALT", Two(), transitions={"done": "DRIVE", "failed": "lost"}
                )
                smach.StateMachine.add(
                    "DRIVE", Two(), transitions={"done": "arrived", "failed": "ALT"}
                )
            smach.Concurrence.add("NAV", nav)
            smach.Concurrence.add("WATCH", Two())
        smach.StateMachine.add("CC", cc, transitions={"ok": "finished", "bad": "gave_up"})
    return sm
