"""The nodes both dispatch forms are made of (docs/semantics.md section 12): the flat one
(``fsmbt.convert.dispatch``) and the hierarchical one (``fsmbt.convert.dispatch_hier``).

- ``switch``: a ``Switch2``..``Switch6`` over one blackboard entry (a one-case switch gets a
  padding case);
- ``index_tree``: the balanced base-7 tree of ``Switch`` nodes over an index kept in digit
  entries ``<prefix>0`` (least significant) .. ``<prefix>{L-1}`` (letters ``a``..``g``): below
  its root a full group of seven takes ``a``..``f`` as cases and ``g`` as the default child, a
  smaller group's default is ``AlwaysFailure`` (unreachable); the root's default is the node
  given (the flat form's start case), so a full root group puts its seventh member under a
  ``Switch2`` on the same digit;
- ``running``: ``KeepRunningUntilFailure(AlwaysSuccess)``, RUNNING without output (an ignored
  event);
- ``check_event``: the event names a ``Switch`` compares as plain strings.

Cost: ``index_tree`` is O(cases) nodes, depth ``levels`` (+1 for a full root group).
"""

from __future__ import annotations

import re
from collections.abc import Callable

from fsmbt.model.bt import BTNode, NodeModel, PortModel
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.dispatch_runtime import BASE, DIGITS, ENTRY, EVENT_KEY, MAX_CASES

_NUMBER = re.compile(r"\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*")


def entry_model() -> NodeModel:
    """``DispatchEntry``'s declaration (Action; ports ``state``, ``action``)."""
    return NodeModel(
        ENTRY, NodeKind.ACTION, [PortModel("state", "input"), PortModel("action", "input")]
    )


def control(type_name: str, name: str, children: list[BTNode], **attrs: str) -> BTNode:
    """A control node."""
    return BTNode(type=type_name, kind=NodeKind.CONTROL, name=name, children=children, attrs=attrs)


def leaf(type_name: str, name: str = "", **attrs: str) -> BTNode:
    """An action leaf (``DispatchEntry``, ``AlwaysSuccess``, ``AlwaysFailure``)."""
    return BTNode(type=type_name, kind=NodeKind.ACTION, name=name, attrs=attrs)


def running() -> BTNode:
    """``KeepRunningUntilFailure(AlwaysSuccess)``: RUNNING, nothing output (event ignored)."""
    return BTNode(
        type="KeepRunningUntilFailure", kind=NodeKind.DECORATOR, children=[leaf("AlwaysSuccess")]
    )


def never() -> BTNode:
    """``AlwaysFailure``: a child no tick reaches (a padding or unused index case)."""
    return leaf("AlwaysFailure")


def switch(
    key: str,
    cases: list[tuple[str, BTNode]],
    default: BTNode,
    name: str,
    pad: Callable[[], BTNode] = never,
) -> BTNode:
    """``Switch{k}`` over ``cases`` (1..6 of them). One case gets a padding case: an unused
    digit or event name whose child ``pad()`` makes (``AlwaysFailure``, never taken, for a
    digit; for ``{event}`` the caller makes a node doing what the default does)."""
    if len(cases) == 1:
        value = next(v for v in (*DIGITS, "z", "zz") if v != cases[0][0])
        cases = [*cases, (value, pad())]
    attrs = {"variable": "{" + key + "}"}
    attrs.update({f"case_{i}": value for i, (value, _n) in enumerate(cases, 1)})
    return control(f"Switch{len(cases)}", name, [n for _v, n in cases] + [default], **attrs)


def index_levels(count: int) -> int:
    """How many base-7 digits an index of ``count`` values needs (at least one)."""
    levels = 1
    while BASE**levels < count:
        levels += 1
    return levels


def digits_of(i: int, levels: int) -> list[str]:
    """Index ``i`` as ``levels`` digit letters, least significant first."""
    out = []
    for _j in range(levels):
        out.append(DIGITS[i % BASE])
        i //= BASE
    return out


def index_tree(
    cases: list[BTNode], prefix: str, levels: int, root_default: BTNode, names: tuple[str, str]
) -> BTNode:
    """The balanced ``Switch`` tree selecting ``cases[i]`` when the digit entries
    ``<prefix>j`` hold index ``i`` (see the module docstring); ``names`` = (its root's name,
    the inner switches' prefix: ``<prefix><j>_<group>``)."""
    nodes: list[BTNode] = cases
    for j in range(levels):
        key = f"{prefix}{j}"
        groups = [nodes[k : k + BASE] for k in range(0, len(nodes), BASE)]
        last = j == levels - 1
        nodes = []
        for g, group in enumerate(groups):
            label = names[0] if last else f"{names[1]}{j}_{g}"
            cases_j = [(DIGITS[i], n) for i, n in enumerate(group)]
            if len(cases_j) <= MAX_CASES:
                default = root_default if last else leaf("AlwaysFailure")
            elif last:  # the root's default is ``root_default``: the seventh digit is a case
                default = switch(key, cases_j[MAX_CASES:], root_default, f"{label}_{DIGITS[-1]}")
            else:  # the seventh digit is the default child: one comparison fewer
                default = cases_j[MAX_CASES][1]
            nodes.append(switch(key, cases_j[:MAX_CASES], default, label))
    assert len(nodes) == 1
    return nodes[0]


def event_switch(
    name: str, exits: list[tuple[str, BTNode]], default: Callable[[], BTNode]
) -> BTNode:
    """A ``Switch`` on ``{event}`` over ``exits`` (a chain of ``Switch6`` when more than six,
    each the default of the previous) whose default ``default()`` makes; a one-case chunk's
    padding case gets another such node. No exits: ``default()`` itself."""
    node = default()
    chunks = [exits[k : k + MAX_CASES] for k in range(0, len(exits), MAX_CASES)]
    for c, chunk in reversed(list(enumerate(chunks))):
        node = switch(EVENT_KEY, chunk, node, f"{name}_events{c or ''}", pad=default)
    return node


def check_event(event: str, state: str) -> None:
    """Refuse an event name a ``Switch`` would not compare as a plain string.

    Raises:
        UnsupportedError: a number, a ``{..}`` blackboard reference, a quote, empty (the
        state named).
    """
    if not event or "{" in event or "'" in event or _NUMBER.fullmatch(event):
        raise UnsupportedError(
            f"event {event!r} cannot be a Switch case (BehaviorTree.CPP compares numbers "
            "numerically and reads {..} as a blackboard entry); use --style lebt",
            element=f"state '{state}'",
        )


def size(root: BTNode) -> tuple[int, int]:
    """(nodes, depth) of one tree, iteratively (root = depth 1)."""
    count = depth = 0
    stack = [(root, 1)]
    while stack:
        node, d = stack.pop()
        count += 1
        depth = max(depth, d)
        stack.extend((child, d + 1) for child in node.children)
    return count, depth
