"""The diff picture: NEW drawn with what changed highlighted and OLD's removed parts ghosted
(docs/diff.md, 'The picture'). Drawn by the one DOT writer (``fsmbt.render``) through its
``marks`` and ghost parameters; this module only decides which element gets which mark.

Legend (also in docs/diff.md): a **red bold border** is where the runs part (for a BT: the
leaf each distinguishing run ticks next in NEW, and the leaf before it; for an FSM: the state
each part from and the state NEW goes to); a **green fill** is added, **orange** moved,
**light blue** re-typed, renamed or re-parameterised; dashed grey nodes (and, for an FSM,
dashed grey transitions) are OLD's parts that NEW no longer has.

Costs: O(size of NEW + edits + groups); Graphviz's layout on top (``fsmbt.render.dot``).
"""

from __future__ import annotations

from pathlib import Path

from fsmbt.diff.report import DiffReport
from fsmbt.diff.structure import (
    ADDED,
    MOVED,
    REMOVED,
    RENAMED,
    RETARGETED,
    RETYPED,
    UPDATED,
    fsm_transitions,
)
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.render import Ghost, bt_to_dot, fsm_to_dot, trace_anchors, write_picture
from fsmbt.render.anchor_ids import node_anchor, state_anchor
from fsmbt.render.dot import DEFAULT_MAX_NODES

Model = FSM | BTDocument

FILLS = {
    ADDED: "palegreen",
    MOVED: "orange",
    RETYPED: "lightblue",
    RENAMED: "lightblue",
    UPDATED: "lightblue",
    RETARGETED: "lightblue",
}
BEHAVIOUR = {"color": "red", "penwidth": "3"}


def _bt_anchor(place: str) -> str:
    tree, _, path = place.partition(":")
    return node_anchor("" if path == "root" else path, tree)


def _fsm_anchor(place: str) -> str:
    return state_anchor(place)


def _subtree_places(doc: BTDocument, place: str) -> list[str]:
    """``place`` (``tree:path``) and every node below it, as places (explicit stack)."""
    tree_id, _, path = place.partition(":")
    tree = doc.trees.get(tree_id)
    node = tree.root if tree is not None else None
    steps = [] if path == "root" else path.split("/")
    for step in steps:
        if node is None or not step.isdigit() or int(step) >= len(node.children):
            return [place]
        node = node.children[int(step)]
    if node is None:
        return [place]
    out: list[str] = []
    stack = [(node, "" if path == "root" else path)]
    while stack:
        current, where = stack.pop()
        out.append(f"{tree_id}:{where or 'root'}")
        for index, child in enumerate(current.children):
            stack.append((child, f"{where}/{index}" if where else str(index)))
    return out


def diff_dot(
    old: Model, new: Model, report: DiffReport, *, max_nodes: int = DEFAULT_MAX_NODES
) -> str:
    """The DOT source of the diff picture (see the module docstring)."""
    marks: dict[str, dict[str, str]] = {}

    def mark(anchor: str, attrs: dict[str, str]) -> None:
        marks.setdefault(anchor, {}).update(attrs)

    for op in report.script or []:
        if op.op == REMOVED or op.new is None:
            continue
        fill = {"fillcolor": FILLS[op.op]}
        if isinstance(new, BTDocument):
            places = _subtree_places(new, op.new) if op.op == ADDED else [op.new]
            for place in places:
                mark(_bt_anchor(place), fill)
            continue
        fill["style"] = "filled"
        if op.what == "state":
            mark(_fsm_anchor(op.new), fill)
        elif op.what == "transition":
            mark(_fsm_anchor(op.new.split(" --", 1)[0]), fill)
    for group in report.behaviour.groups:
        for state in (group.new_state, group.new_next):
            if state is None:
                continue
            for anchor in trace_anchors(new, state, expanded=False)[:1]:
                mark(anchor, BEHAVIOUR)
    if isinstance(new, BTDocument):
        removed = [op for op in report.script or [] if op.op == REMOVED]
        ghosts = [
            Ghost(
                f"removed: {op.label}" + (f" ({op.detail})" if op.detail else ""),
                _bt_anchor(op.parent) if op.parent else None,
            )
            for op in removed
        ]
        return bt_to_dot(new, max_nodes=max_nodes, marks=marks, ghosts=ghosts)
    ghost_states: list[str] = []
    ghost_edges: list[tuple[str, str, str]] = []
    if isinstance(old, FSM):
        ghost_states = [
            op.old
            for op in report.script or []
            if op.op == REMOVED and op.what == "state" and op.old
        ]
        kept = fsm_transitions(new)
        for (source, event, _guard), target in fsm_transitions(old).items():
            if kept.get((source, event, _guard)) != target:
                ghost_edges.append(
                    (state_anchor(source), state_anchor(target), f"removed: {event or '(none)'}")
                )
    return fsm_to_dot(
        new, max_nodes=max_nodes, marks=marks, ghosts=ghost_states, ghost_edges=ghost_edges
    )


def write_diff_picture(
    old: Model, new: Model, report: DiffReport, path: str | Path, *, overwrite: bool = False
) -> Path:
    """Write the diff picture to ``path`` (SVG, PNG, PDF or DOT, from the suffix)."""
    return write_picture(diff_dot(old, new, report), path, overwrite=overwrite)
