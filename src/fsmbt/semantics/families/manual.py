"""Manual family: ManualSelector (manual_node.cpp; docs/semantics.md "ManualSelector").

Contract: a person picks the child to run (or a status) through a terminal UI; fsmbt asks the
pick through synthetic condition leaves added after the children at compile time
(``choice_leaves``): the first that answers SUCCESS is the pick, none means the last pick. A
picked child's status is returned; with ``repeat_last_selection`` the pick is remembered
(memory ``(pick,)``) and re-used without asking. Nothing else is halted or reset.
"""

from __future__ import annotations

from typing import Any

from fsmbt.model.bt import BTNode
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.compiled import (
    FAILURE,
    GATE_TYPE,
    RUNNING,
    SUCCESS,
    CompiledNode,
    Frame,
    HaltHook,
    TickAction,
    Work,
)
from fsmbt.semantics.families.contract import FamilyRule, Interp
from fsmbt.semantics.families.ports import bool_param
from fsmbt.semantics.status import NodeStatus

#: The person's picks of a ManualSelector besides its children (manual_node.cpp: S, F, R keys).
MANUAL_STATUSES: tuple[int, ...] = (SUCCESS, FAILURE, RUNNING)


def manual_choices(n_children: int, repeat_last: bool) -> int:
    """How many picks a ManualSelector offers: its children and the three statuses; with
    ``repeat_last_selection`` the children only (a status picked there makes BehaviorTree.CPP
    4.8.2 index past its children on the next tick; docs/semantics.md); without children the
    three statuses."""
    if n_children == 0:
        return len(MANUAL_STATUSES)
    return n_children if repeat_last else n_children + len(MANUAL_STATUSES)


def manual_params(node: BTNode, ctype: str, exact: bool) -> tuple[Any, ...]:
    """``(number of children, repeat_last_selection)``."""
    return (len(node.children), bool_param(node, "repeat_last_selection", False))


def choice_leaves(node: BTNode, params: tuple[Any, ...]) -> list[BTNode]:
    """The conditions that ask the person for a ManualSelector's pick, one per pick but the
    last (docs/semantics.md, "ManualSelector"): ``pick_<i>`` (child i, 1-based as the terminal
    UI numbers them), ``pick_SUCCESS``, ``pick_FAILURE``; the first that answers SUCCESS is the
    pick, none means the last pick (RUNNING, or the last child with repeat_last_selection)."""
    n_children, repeat_last = params
    words = [f"pick_{i + 1}" for i in range(n_children)]
    if n_children == 0 or not repeat_last:
        words += [f"pick_{NodeStatus(s).name}" for s in MANUAL_STATUSES]
    return [
        BTNode(GATE_TYPE, NodeKind.CONDITION, f"{node.label}.{word}", location=node.location)
        for word in words[: manual_choices(n_children, repeat_last) - 1]
    ]


def tick_manual_selector(
    ip: Interp, w: Work, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
) -> TickAction:
    """ManualSelector (manual_node.cpp): the person's pick is asked through the choice
    conditions after the children (``choice_leaves``), the first SUCCESS wins; a picked
    child's status is returned; nothing else is halted or reset."""
    n, repeat_last = node.params
    choices = node.children[n:]
    pc = frame[1]
    if pc == 0:
        (previous,) = ip.mem(w, node)
        if n and repeat_last and previous >= 0:
            return ("call", node.children[previous], (node.id, 2))
        if n:
            w.st[node.id] = RUNNING  # setStatus(RUNNING) before selectChild()
        if not choices:  # one child under repeat_last_selection: the only pick
            pick = 0
        else:
            return ("call", choices[0], (node.id, 1, 0))
    elif pc == 1:
        asked = frame[2]
        w.st.pop(choices[asked], None)  # a choice keeps no status: asked afresh each time
        if result == SUCCESS:
            pick = asked
        elif asked + 1 < len(choices):
            return ("call", choices[asked + 1], (node.id, 1, asked + 1))
        else:
            pick = len(choices)  # none said yes: the last pick
    else:  # pc == 2: the picked child returned
        assert result is not None
        return ("ret", result)
    if pick < n:
        if repeat_last:
            ip.set_mem(w, node, (pick,))
        return ("call", node.children[pick], (node.id, 2))
    return ("ret", MANUAL_STATUSES[pick - n])


#: This family's rules, by the ``handler`` name its kinds declare.
RULES: dict[str, FamilyRule] = {
    "manual_selector": FamilyRule(
        tick_manual_selector, params=manual_params, extra_children=choice_leaves
    ),
}
