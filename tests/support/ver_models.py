"""Models shared by the checker's tests: the paper's A-J FSM and an equivalent renamed copy; a
small tree with two regions of memory (the compositional check's, docs/semantics.md §4c)."""

from __future__ import annotations

from fsmbt.model import FSM, State
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind

PAPER_EDGES = ["AB", "AC", "AD", "AF", "BC", "BD", "CD", "DE", "EC", "ED", "EG", "GH", "FI", "IJ"]


def paper_fsm() -> FSM:
    """The paper's FSM; transition i is ``PAPER_EDGES[i]`` so tests can mutate one by name."""
    fsm = FSM(name="paper")
    for name in "ABCDEFGHIJ":
        fsm.add_state(name, final=name in "HJ")
    fsm.start_name, fsm.initial_event, fsm.initial = "Start", "eventStartA", "A"
    for a, b in PAPER_EDGES:
        fsm.add_transition(a, f"event{a}{b}", b)
    return fsm


def renamed_copy(fsm: FSM) -> FSM:
    """Same behaviour, other state names and declaration order."""
    out = FSM(name=f"{fsm.name}_renamed", start_name="Init", initial_event=fsm.initial_event)
    for name in reversed(list(fsm.states)):
        s = fsm.states[name]
        out.add_state(State(f"r_{name}", action=s.action, final=s.final))
    out.initial = f"r_{fsm.initial}"
    for t in reversed(fsm.transitions):
        out.add_transition(f"r_{t.source}", t.event, f"r_{t.target}")
    return out


def act(name: str) -> BTNode:
    """An action leaf named ``name``."""
    return BTNode("Act", NodeKind.ACTION, name=name)


def cond(name: str) -> BTNode:
    """A condition leaf named ``name``."""
    return BTNode("Cond", NodeKind.CONDITION, name=name)


def ctrl(kind: str, *children: BTNode) -> BTNode:
    """A control node of type ``kind`` over ``children``."""
    return BTNode(kind, NodeKind.CONTROL, children=list(children))


def memory_regions_tree() -> BTDocument:
    """Fallback(SequenceWithMemory(a1, a2), Sequence(c1, ReactiveSequence(c2, a3)), a4): two
    regions, so the compositional check decides it by parts."""
    return BTDocument.single(
        ctrl(
            "Fallback",
            ctrl("SequenceWithMemory", act("a1"), act("a2")),
            ctrl("Sequence", cond("c1"), ctrl("ReactiveSequence", cond("c2"), act("a3"))),
            act("a4"),
        )
    )
