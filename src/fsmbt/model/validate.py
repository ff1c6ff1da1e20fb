"""Structural validation of FSMs (every level of a hierarchical one) and BT documents.

``validate(model)`` lists every problem as an ``Issue``; ``check(model)`` raises ``InputError``
when there is an error (the message lists them all). Errors are models fsmbt cannot give a
meaning to (docs/semantics.md, 'Models'); warnings are legal models that are probably not what the author meant,
or whose parts fsmbt cannot model exactly. The rules, with their reasons, are in
docs/semantics.md and below at each check.

Complexity: O(S + T) for an FSM with S states and T transitions over all levels;
O(N + R) for a BT document with N nodes and R SubTree references (cycle search included).
Every traversal uses an explicit stack, so 100 000-deep trees and deep hierarchies are fine.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Literal

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind, builtin_spec
from fsmbt.model.errors import InputError, SourceLocation
from fsmbt.model.fsm import FSM, State, Transition

Severity = Literal["error", "warning"]


@dataclass(frozen=True)
class Issue:
    """One finding: ``location`` is file:line:col where the format has them; ``element`` names
    the state, transition or node (with its path in the model); ``code`` names the check, stable
    across versions (the list: docs/cli.md, "Diagnostics")."""

    severity: Severity
    message: str
    location: SourceLocation | None = None
    element: str | None = None
    code: str = ""

    def __str__(self) -> str:
        prefix = f"{self.location}: " if self.location is not None else ""
        where = f"{self.element}: " if self.element else ""
        return f"{prefix}{where}{self.severity}: {self.message}"

    def to_dict(self) -> dict[str, object]:
        loc = self.location
        return {
            "severity": self.severity,
            "code": self.code,
            "message": self.message,
            "element": self.element,
            "file": loc.file if loc else None,
            "line": loc.line if loc else None,
            "column": loc.column if loc else None,
        }


def validate(model: FSM | BTDocument) -> list[Issue]:
    """Every issue of ``model``, errors and warnings, in model order."""
    if isinstance(model, FSM):
        return _FsmValidator().run(model)
    if isinstance(model, BTDocument):
        return _BtValidator(model).run()
    raise TypeError(f"not a model: {type(model).__name__}")


def collapse_repeated_warnings(issues: list[Issue]) -> list[Issue]:
    """``issues`` with each warning whose message repeats (one per node of the same undeclared
    type, say) kept once, at its first place, with the count: ``... (12 nodes; the first is
    here)``. Errors are all kept. O(n) for n issues."""
    counts: dict[str, int] = {}
    for issue in issues:
        if issue.severity == "warning":
            counts[issue.message] = counts.get(issue.message, 0) + 1
    kept: list[Issue] = []
    seen: set[str] = set()
    for issue in issues:
        if issue.severity != "warning" or counts[issue.message] == 1:
            kept.append(issue)
        elif issue.message not in seen:
            seen.add(issue.message)
            kept.append(
                Issue(
                    "warning",
                    f"{issue.message} ({counts[issue.message]} nodes; the first is here)",
                    issue.location,
                    issue.element,
                    code=issue.code,
                )
            )
    return kept


def errors(issues: list[Issue]) -> list[Issue]:
    return [i for i in issues if i.severity == "error"]


def check(model: FSM | BTDocument) -> list[Issue]:
    """Raise ``InputError`` (located at the first error) when ``model`` has errors; else return
    its warnings."""
    issues = validate(model)
    found = errors(issues)
    if found:
        first = found[0]
        message = first.message
        if len(found) > 1:
            rest = "; ".join(str(i) for i in found[1:])
            message = f"{message} (and {len(found) - 1} more error(s): {rest})"
        raise InputError(message, location=first.location, element=first.element)
    return issues


# -- FSM ------------------------------------------------------------------------------------
class _FsmValidator:
    def __init__(self) -> None:
        self.issues: list[Issue] = []

    def add(
        self,
        severity: Severity,
        message: str,
        location: SourceLocation | None,
        element: str | None,
        *,
        code: str,
    ) -> None:
        self.issues.append(Issue(severity, message, location, element, code))

    def run(self, fsm: FSM) -> list[Issue]:
        if not fsm.states:
            self.add(
                "error", "the state machine has no states", None, fsm.name, code="fsm-no-states"
            )
            return self.issues
        seen_at: dict[str, str] = {}  # state name -> path of its first occurrence
        # explicit stack of (machine, path prefix, an enclosing state has an event transition)
        stack: list[tuple[FSM, str, bool]] = [(fsm, "", False)]
        while stack:
            machine, prefix, can_leave = stack.pop()
            outgoing = _outgoing(machine)
            self.level(machine, prefix, can_leave, outgoing)
            for state in machine.states.values():
                path = f"{prefix}{state.name}"
                earlier = seen_at.setdefault(state.name, path)
                if earlier != path:
                    self.add(
                        "warning",
                        f"state name '{state.name}' is also used at "
                        f"'{earlier}'; formats with global names (Mermaid, DOT, tables) "
                        "would merge them",
                        state.location,
                        path,
                        code="state-name-reused",
                    )
                leaves = can_leave or any(t.event is not None for t in outgoing.get(state.name, ()))
                for index, region in enumerate(state.regions):
                    if not region.states:
                        self.add(
                            "error",
                            "composite state has an empty sub-machine",
                            state.location,
                            path,
                            code="empty-submachine",
                        )
                        continue
                    sub = f"{path}/" if state.is_composite else f"{path}/{index}:"
                    stack.append((region, sub, leaves))
        return self.issues

    def level(
        self, machine: FSM, prefix: str, can_leave: bool, outgoing: dict[str, list[Transition]]
    ) -> None:
        """Checks of one machine level (``prefix`` is its path, e.g. ``C/``)."""
        where = prefix.rstrip("/") or machine.name
        states = machine.states
        if machine.initial is None:
            self.add("error", "no initial state", None, where, code="no-initial")
        elif machine.initial not in states:
            self.add(
                "error",
                f"initial state '{machine.initial}' is not a state",
                None,
                where,
                code="bad-initial",
            )
        targets_by_key: dict[
            tuple[str, str | None, str | None], tuple[str, SourceLocation | None]
        ] = {}
        for t in machine.transitions:
            label = f"{prefix}{t.source} --{t.event if t.event is not None else '(eventless)'}--> {t.target}"
            for end, name in (("source", t.source), ("target", t.target)):
                if name not in states:
                    self.add(
                        "error",
                        f"transition {end} '{name}' is not a state at this level",
                        t.location,
                        label,
                        code="unknown-state",
                    )
            key = (t.source, t.event, t.exit)
            earlier = targets_by_key.get(key)
            if earlier is None:
                targets_by_key[key] = (t.target, t.location)
            elif earlier[0] != t.target:
                event = f"event '{t.event}'" if t.event is not None else "no event (eventless)"
                self.add(
                    "error",
                    f"nondeterministic: state '{t.source}' goes to both "
                    f"'{earlier[0]}' and '{t.target}' on {event}",
                    t.location,
                    label,
                    code="nondeterministic",
                )
            else:
                self.add(
                    "warning",
                    "duplicate transition",
                    t.location,
                    label,
                    code="duplicate-transition",
                )
            source = states.get(t.source)
            if source is not None and source.final:
                self.add(
                    "error",
                    f"final state '{t.source}' has an outgoing transition; a final "
                    "state accepts no event",
                    t.location,
                    label,
                    code="final-has-transition",
                )
        for state in states.values():
            self.state(state, outgoing.get(state.name, []), prefix, can_leave)
        self.reachability(machine, prefix, outgoing)

    def state(self, state: State, outgoing: list[Transition], prefix: str, can_leave: bool) -> None:
        path = f"{prefix}{state.name}"
        if state.regions and state.action is not None:
            self.add(
                "error",
                f"composite state has its own action '{state.action}'; only atomic "
                "states run actions (the flat state's action is its sub-states')",
                state.location,
                path,
                code="composite-action",
            )
        if state.is_atomic and not state.final and not outgoing and not can_leave:
            self.add(
                "warning",
                "no way out and not marked final: the machine gets stuck here",
                state.location,
                path,
                code="dead-end",
            )
        if state.is_atomic and state.action is not None and any(t.event is None for t in outgoing):
            self.add(
                "warning",
                f"transient state (eventless transition out): its action "
                f"'{state.action}' is never observed",
                state.location,
                path,
                code="transient-state",
            )

    def reachability(
        self, machine: FSM, prefix: str, outgoing: dict[str, list[Transition]]
    ) -> None:
        """Breadth-first from the initial state over every transition of this level."""
        if machine.initial not in machine.states:
            return
        seen = {machine.initial}
        queue = deque([machine.initial])
        while queue:
            for t in outgoing.get(queue.popleft(), []):
                if t.target not in seen and t.target in machine.states:
                    seen.add(t.target)
                    queue.append(t.target)
        for state in machine.states.values():
            if state.name not in seen:
                self.add(
                    "warning",
                    "unreachable from the initial state",
                    state.location,
                    f"{prefix}{state.name}",
                    code="unreachable",
                )


def _path(trail: list[tuple[str, int]], index: int, keep: int = 4) -> str:
    """``tree/…/parent/node`` from parent links: the last ``keep`` labels and the tree id."""
    labels: list[str] = []
    while index >= 0:
        label, index = trail[index]
        labels.append(label)
    labels.reverse()
    if len(labels) > keep + 1:
        labels = [labels[0], "…", *labels[-keep:]]
    return "/".join(labels)


def _outgoing(machine: FSM) -> dict[str, list[Transition]]:
    table: dict[str, list[Transition]] = {}
    for t in machine.transitions:
        table.setdefault(t.source, []).append(t)
    return table


# -- BT -------------------------------------------------------------------------------------
class _BtValidator:
    def __init__(self, doc: BTDocument) -> None:
        self.doc = doc
        self.issues: list[Issue] = []

    def add(
        self, severity: Severity, message: str, node: BTNode | None, element: str, *, code: str
    ) -> None:
        self.issues.append(Issue(severity, message, node.location if node else None, element, code))

    def run(self) -> list[Issue]:
        doc = self.doc
        if not doc.trees:
            self.issues.append(
                Issue("error", "the document holds no behavior tree", code="no-tree")
            )
            return self.issues
        if doc.main_tree is not None and doc.main_tree not in doc.trees:
            self.issues.append(
                Issue(
                    "error",
                    f"main tree '{doc.main_tree}' is not defined (trees: {', '.join(doc.trees)})",
                    None,
                    doc.main_tree,
                    code="unknown-main-tree",
                )
            )
        elif doc.main_tree is None and len(doc.trees) > 1:
            first = next(iter(doc.trees))
            self.issues.append(
                Issue(
                    "warning",
                    f"{len(doc.trees)} trees and no main tree named; '{first}' is executed",
                    None,
                    first,
                    code="no-main-tree",
                )
            )
        references: dict[str, list[str]] = {tree_id: [] for tree_id in doc.trees}
        for tree in doc.trees.values():
            if tree.root is None:
                self.issues.append(
                    Issue(
                        "error",
                        "the tree is empty",
                        tree.location,
                        f"tree '{tree.id}'",
                        code="empty-tree",
                    )
                )
                continue
            self.tree(tree.id, tree.root, references[tree.id])
        self.cycles(references)
        return collapse_repeated_warnings(self.issues)

    def tree(self, tree_id: str, root: BTNode, referenced: list[str]) -> None:
        """Pre-order with an explicit stack; element paths are built only for nodes with an
        issue, from parent links (a full path per node would be quadratic in the depth)."""
        trail: list[tuple[str, int]] = [(tree_id, -1)]  # (label, index of the parent entry)
        stack: list[tuple[BTNode, int]] = [(root, 0)]
        while stack:
            node, parent = stack.pop()
            trail.append((node.label, parent))
            here = len(trail) - 1
            self.node(node, here, trail, referenced)
            stack.extend((child, here) for child in reversed(node.children))

    def node(
        self, node: BTNode, here: int, trail: list[tuple[str, int]], referenced: list[str]
    ) -> None:
        def where() -> str:
            return _path(trail, here)

        count = len(node.children)
        # a project node read with a library's semantics (--nodes, or a profile found by
        # itself) follows that built-in's rules, as conversion does
        spec = builtin_spec(node.semantics or node.type)
        if not node.kind_declared:
            if count:
                self.add(
                    "error",
                    f"unknown node type '{node.type}' (not built in, not declared "
                    f"in TreeNodesModel) with {count} child(ren)",
                    node,
                    where(),
                    code="unknown-node",
                )
                return
            self.add(
                "warning",
                f"leaf type '{node.type}' is not declared; assumed to be an "
                "Action (it may return RUNNING)",
                node,
                where(),
                code="undeclared-leaf",
            )
        if spec is None and node.kind in (NodeKind.CONTROL, NodeKind.DECORATOR):
            # declared (TreeNodesModel or a <Control ID=..> / <Decorator ID=..> tag)
            kind = "control" if node.kind is NodeKind.CONTROL else "decorator"
            self.add(
                "warning",
                f"custom {kind} '{node.type}' has no known semantics; it cannot "
                "be converted or verified",
                node,
                where(),
                code="unknown-semantics",
            )
        if node.kind is NodeKind.CONTROL:
            if count == 0 and spec is not None and spec.allows_children(0):
                self.add(
                    "warning",
                    f"'{node.type}' without children: its own rule ({spec.source}) is modelled, "
                    "but BehaviorTree.CPP 4.8.2's loader refuses a control node without children",
                    node,
                    where(),
                    code="childless-node",
                )
            elif count == 0:
                self.add(
                    "error",
                    f"control node '{node.type}' has no children",
                    node,
                    where(),
                    code="no-children",
                )
            elif spec is not None and spec.children is not None and count != spec.children:
                self.add(
                    "error",
                    f"'{node.type}' needs exactly {spec.children} children, has {count}",
                    node,
                    where(),
                    code="child-count",
                )
            elif spec is not None and not spec.allows_children(count):
                allowed = " or ".join(str(c) for c in spec.child_counts or ())
                self.add(
                    "error",
                    f"'{node.type}' needs {allowed} children, has {count}",
                    node,
                    where(),
                    code="child-count",
                )
        elif node.kind is NodeKind.DECORATOR:
            if count != 1:
                self.add(
                    "error",
                    f"decorator '{node.type}' needs exactly one child, has {count}",
                    node,
                    where(),
                    code="child-count",
                )
        elif node.kind is NodeKind.SUBTREE:
            if count:
                self.add(
                    "error",
                    f"SubTree node has {count} child(ren); it takes none",
                    node,
                    where(),
                    code="subtree-children",
                )
            target = node.subtree_id
            if not target:
                self.add(
                    "error",
                    "SubTree node without an ID naming the tree",
                    node,
                    where(),
                    code="subtree-no-id",
                )
            elif builtin_spec(target) is not None and target not in self.doc.trees:
                # xml_parsing.cpp VerifyXML: a SubTree ID must not be a registered node's name
                self.add(
                    "error",
                    f"SubTree ID '{target}' is the name of a built-in node; BehaviorTree.CPP "
                    "refuses it",
                    node,
                    where(),
                    code="subtree-builtin-id",
                )
            elif target not in self.doc.trees:
                severity: Severity = "warning" if self.doc.includes else "error"
                hint = (
                    " (it may come from an included file)"
                    if self.doc.includes
                    else " (a tree of another file: name it with --trees PATH)"
                )
                self.add(
                    severity,
                    f"SubTree references missing tree '{target}'{hint}",
                    node,
                    where(),
                    code="missing-subtree",
                )
            else:
                referenced.append(target)
        elif count:
            kind = "condition" if node.kind is NodeKind.CONDITION else "action"
            self.add(
                "error",
                f"{kind} leaf '{node.type}' has {count} child(ren); leaves take none",
                node,
                where(),
                code="leaf-children",
            )
        if spec is not None and spec.time_based:
            self.add(
                "warning",
                f"time-based node '{node.type}': fsmbt does not model time; its "
                "timing is ignored when converting or verifying",
                node,
                where(),
                code="time-based",
            )

    def cycles(self, references: dict[str, list[str]]) -> None:
        """Recursive SubTree references (a tree that reaches itself) via iterative DFS."""
        colour: dict[str, int] = {}  # 0/absent white, 1 on the stack, 2 done
        reported: set[frozenset[str]] = set()
        for start in references:
            if colour.get(start):
                continue
            path: list[str] = []
            stack: list[tuple[str, int]] = [(start, 0)]
            while stack:
                tree_id, index = stack.pop()
                if index == 0:
                    colour[tree_id] = 1
                    path.append(tree_id)
                children = references.get(tree_id, [])
                if index < len(children):
                    stack.append((tree_id, index + 1))
                    child = children[index]
                    if colour.get(child) == 1:
                        cycle = path[path.index(child) :] + [child]
                        key = frozenset(cycle)
                        if key not in reported:
                            reported.add(key)
                            tree = self.doc.trees[child]
                            self.issues.append(
                                Issue(
                                    "error",
                                    "recursive SubTree: " + " -> ".join(cycle),
                                    tree.location,
                                    f"tree '{child}'",
                                    code="recursive-subtree",
                                )
                            )
                    elif not colour.get(child):
                        stack.append((child, 0))
                else:
                    colour[tree_id] = 2
                    path.pop()
