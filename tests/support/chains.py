"""The n-state chain machine and the XML depth measure shared by the depth-bound tests and
benchmarks/bench_deep_chain.py (docs/semantics.md §5, "Depth-bounded LEBT")."""

from __future__ import annotations

from fsmbt.model.fsm import FSM


def chain(n: int, name: str = "chain") -> FSM:
    """S0 -next-> S1 -next-> ... S(n-1), the last final; each state's action a<i>."""
    fsm = FSM(name=name)
    for i in range(n):
        fsm.add_state(f"S{i}", action=f"a{i}", final=i == n - 1)
    fsm.initial = "S0"
    for i in range(n - 1):
        fsm.add_transition(f"S{i}", "next", f"S{i + 1}")
    return fsm


def xml_depth(text: str) -> int:
    """Deepest element of a written document (``<root>`` = 1), by counting tags in order."""
    depth = deepest = 0
    for piece in text.split("<")[1:]:
        if piece.startswith(("?", "!")):
            continue
        if piece.startswith("/"):
            depth -= 1
            continue
        depth += 1
        deepest = max(deepest, depth)
        if piece.split(">", 1)[0].endswith("/"):
            depth -= 1
    return deepest
