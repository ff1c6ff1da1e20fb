"""The node types of BehaviorTree.CPP v4 that fsmbt knows, and the names older inputs use.

Everything is mapped to BehaviorTree.CPP v4 meaning (docs/semantics.md, 'Names'): the reactive
"Sequence" of Colledanchise & Ögren is ``ReactiveSequence`` here, their "Sequence*" is the plain
``Sequence``; BehaviorTree.CPP v3's ``SequenceStar`` is v4's ``SequenceWithMemory``.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class NodeKind(str, Enum):
    """What a node is, which decides how many children it has and what it may return."""

    CONTROL = "Control"
    DECORATOR = "Decorator"
    ACTION = "Action"
    CONDITION = "Condition"
    SUBTREE = "SubTree"


@dataclass(frozen=True)
class NodeSpec:
    """A built-in node type: its kind and how many children it takes (``None`` = one or more)."""

    type: str
    kind: NodeKind
    children: int | None
    time_based: bool = False


def _specs() -> dict[str, NodeSpec]:
    control_many = [
        "Sequence", "ReactiveSequence", "SequenceWithMemory", "AsyncSequence",
        "Fallback", "ReactiveFallback", "AsyncFallback",
        "Parallel", "ParallelAll", "ManualSelector",
    ]
    specs = {name: NodeSpec(name, NodeKind.CONTROL, None) for name in control_many}
    specs["IfThenElse"] = NodeSpec("IfThenElse", NodeKind.CONTROL, None)  # 2 or 3 children
    specs["WhileDoElse"] = NodeSpec("WhileDoElse", NodeKind.CONTROL, None)  # 2 or 3 children
    for n in range(2, 7):
        specs[f"Switch{n}"] = NodeSpec(f"Switch{n}", NodeKind.CONTROL, n + 1)
    decorators = [
        "Inverter", "ForceSuccess", "ForceFailure", "Repeat", "RetryUntilSuccessful",
        "KeepRunningUntilFailure", "RunOnce", "Precondition", "SkipUnlessUpdated",
        "WaitValueUpdate", "LoopInt", "LoopBool", "LoopDouble", "LoopString",
    ]
    for name in decorators:
        specs[name] = NodeSpec(name, NodeKind.DECORATOR, 1)
    for name in ("Delay", "Timeout"):
        specs[name] = NodeSpec(name, NodeKind.DECORATOR, 1, time_based=True)
    for name in ("AlwaysSuccess", "AlwaysFailure", "Script", "SetBlackboard", "UnsetBlackboard"):
        specs[name] = NodeSpec(name, NodeKind.ACTION, 0)
    specs["Sleep"] = NodeSpec("Sleep", NodeKind.ACTION, 0, time_based=True)
    for name in ("ScriptCondition", "WasEntryUpdated"):
        specs[name] = NodeSpec(name, NodeKind.CONDITION, 0)
    specs["SubTree"] = NodeSpec("SubTree", NodeKind.SUBTREE, 0)
    return specs


BUILTIN_NODES: dict[str, NodeSpec] = _specs()

#: BehaviorTree.CPP v3 (and misspelt) names and their v4 equivalents.
V3_ALIASES: dict[str, str] = {
    "SequenceStar": "SequenceWithMemory",
    "RetryUntilSuccesful": "RetryUntilSuccessful",
    "SubTreePlus": "SubTree",
}

#: Control node types whose children are merged by depth compression when nested in themselves.
SEQUENCE_TYPES = frozenset({"Sequence", "ReactiveSequence", "SequenceWithMemory"})
FALLBACK_TYPES = frozenset({"Fallback", "ReactiveFallback"})


def canonical_type(type_name: str) -> str:
    """The v4 name of a node type (v3 aliases mapped, everything else unchanged)."""
    return V3_ALIASES.get(type_name, type_name)


def builtin_spec(type_name: str) -> NodeSpec | None:
    return BUILTIN_NODES.get(canonical_type(type_name))
