"""Compact text forms of models for prompts: the fewest tokens that still say everything.

JSON or XML of a 30-state FSM costs 2-3 thousand tokens; these forms cost a few hundred, which
is how a whole conversion request stays within the paper's 500-1 000 tokens. Both are lossless
for what the conversion needs (names, actions, final flags, transitions; node types, names and
the attributes that change behavior) and plain enough to read without explanation.
Complexity: linear in the model's size; no recursion (trees may be 100 000 deep).
"""

from __future__ import annotations

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM
from fsmbt.semantics.lebt.spec import DEFAULT_START

#: Attributes that change a node's behavior and so stay in the outline.
BEHAVIOR_ATTRS = (
    "num_cycles",
    "num_attempts",
    "success_count",
    "failure_count",
    "max_failures",
    "if",
    "else",
    "code",
    "ID",
)


def compact_fsm(fsm: FSM) -> str:
    """``FSM name`` / start line / states line / one line of transitions per source state."""
    lines = [f"FSM {fsm.name}"]
    start = fsm.start_name or DEFAULT_START
    event = fsm.initial_event if fsm.initial_event is not None else ""
    lines.append(
        f"start: {start} --{event}--> {fsm.initial}"
        if event
        else f"start: {start} enters {fsm.initial} with no event"
    )
    items = []
    for state in fsm.states.values():
        item = state.name
        if state.action != state.name:
            item += f"={state.action or ''}"
        if state.final:
            item += " (final)"
        if state.regions:
            item += " (composite)"
        items.append(item)
    lines.append("states (name=action when they differ): " + ", ".join(items))
    lines.append("transitions (source: event->target):")
    by_source: dict[str, list[str]] = {}
    for t in fsm.transitions:
        by_source.setdefault(t.source, []).append(
            f"{t.event if t.event is not None else '(none)'}->{t.target}"
        )
    lines.extend(f"{source}: {', '.join(items)}" for source, items in by_source.items())
    return "\n".join(lines)


def compact_bt(doc: BTDocument) -> str:
    """An indented outline, one node a line: ``Kind label`` plus behavior-relevant attributes.

    SubTree references are written inline under their tree's own heading so nothing is lost.
    """
    out: list[str] = []
    main = doc.main
    ordered = [main] + [t for t in doc.trees.values() if t.id != main.id]
    for tree in ordered:
        if len(ordered) > 1:
            out.append(f"tree {tree.id}:")
        if tree.root is None:
            out.append("(empty)")
            continue
        stack: list[tuple[BTNode, int]] = [(tree.root, 0)]
        while stack:
            node, depth = stack.pop()
            out.append(" " * depth + _node_line(node))
            stack.extend((child, depth + 1) for child in reversed(node.children))
    return "\n".join(out)


def _node_line(node: BTNode) -> str:
    if node.is_leaf:
        kind = "Condition" if node.kind is NodeKind.CONDITION else "Action"
        line = f"{kind} {node.label}"
        if node.name and node.name != node.type and not node.is_builtin:
            line += f" [{node.type}]"
        elif node.is_builtin and node.name:
            line = f"{kind} {node.name} [{node.type}]"
    else:
        line = node.type + (f" {node.name}" if node.name and node.name != node.type else "")
    extras = [f"{key}={node.attrs[key]}" for key in BEHAVIOR_ATTRS if key in node.attrs]
    return line + (f" ({', '.join(extras)})" if extras else "")
