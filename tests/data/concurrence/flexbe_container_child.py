from flexbe_core import Autonomy, Behavior, ConcurrencyContainer, OperatableStateMachine
from flexbe_states.log_state import LogState


class ContainerChildSM(Behavior):
    def __init__(self, node):
        super().__init__()
        self.name = "Container Child"

    def create(self):
        _state_machine = OperatableStateMachine(outcomes=["finished", "failed"])
        _sm_inner_0 = OperatableStateMachine(outcomes=["finished", "failed"])
        with _sm_inner_0:
            OperatableStateMachine.add(
                "First",
                LogState(text="one"),
                transitions={"done": "Second"},
                autonomy={"done": Autonomy.Off},
            )
            OperatableStateMachine.add(
                "Second",
                LogState(text="two"),
                transitions={"done": "finished"},
                autonomy={"done": Autonomy.Off},
            )
        _sm_both_1 = ConcurrencyContainer(
            outcomes=["finished", "failed"],
            conditions=[("finished", [("Inner", "finished"), ("Log", "done")])],
        )
        with _sm_both_1:
            OperatableStateMachine.add(
                "Inner",
                _sm_inner_0,
                transitions={"finished": "finished", "failed": "failed"},
                autonomy={"finished": Autonomy.Inherit, "failed": Autonomy.Inherit},
            )
            OperatableStateMachine.add(
                "Log",
                LogState(text="side"),
                transitions={"done": "finished"},
                autonomy={"done": Autonomy.Off},
            )
        with _state_machine:
            OperatableStateMachine.add(
                "Both",
                _sm_both_1,
                transitions={"finished": "finished", "failed": "failed"},
                autonomy={"finished": Autonomy.Inherit, "failed": Autonomy.Inherit},
            )
        return _state_machine
