from fsmbt.model import Model
def write_smach(model: Model) -> str:
    raise NotImplementedError
