"""The intermediate representation: FSM (flat or hierarchical) and BT documents."""

from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode, NodeModel, PortModel
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError, InputError, SourceLocation, UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM, State, Transition

Model = FSM | BTDocument

__all__ = [
    "FSM",
    "State",
    "Transition",
    "BTDocument",
    "BehaviorTree",
    "BTNode",
    "NodeModel",
    "PortModel",
    "NodeKind",
    "FsmbtError",
    "InputError",
    "UnsupportedError",
    "SourceLocation",
    "flatten",
    "Model",
]
