"""Every reason the interpreter would refuse a BT document, found at once (not only the first).

``CompiledTree`` stops at the first node it cannot give a meaning to; a user fixing a file wants
the whole list. ``conversion_blockers`` walks the main tree and every SubTree it reaches (explicit
stack, each tree once per SubTree chain) and runs the same per-node check the compiler runs
(``CompiledTree.check_node``), collecting each ``InputError`` / ``UnsupportedError`` with its
location. ``validate``, ``info``, ``render`` and ``convert`` all report this list, so they agree
on what conversion refuses (docs/cli.md).

Costs: O(N) checks for N nodes once SubTrees are expanded, each tree walked once per distinct
SubTree chain that reaches it (bounded by ``MAX_CHECKED``).
"""

from __future__ import annotations

from dataclasses import dataclass

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.dispatch_runtime import DispatchMachine, is_dispatch_bt
from fsmbt.semantics.nodes import SUBTREE_TYPE

#: Stop after this many node checks (a tree whose SubTrees multiply beyond it is refused
#: anyway, by the compiler's own node limit).
MAX_CHECKED = 200_000


@dataclass(frozen=True)
class Blocker:
    """One refusal: the message, where it is, which node, and whether it is a feature fsmbt
    does not model (``UnsupportedError``) rather than an invalid model (``InputError``)."""

    message: str
    location: SourceLocation | None
    element: str | None
    unsupported: bool = True

    def __str__(self) -> str:
        where = f"{self.location}: " if self.location is not None else ""
        element = f"{self.element}: " if self.element else ""
        return f"{where}{element}{self.message}"


def conversion_blockers(doc: BTDocument) -> list[Blocker]:
    """Every node of ``doc``'s main tree (SubTrees expanded) the interpreter refuses.

    Args:
        doc: the document.

    Returns:
        The blockers in tree order (empty: the tree compiles).
    """
    found: list[Blocker] = []
    try:
        tree = doc.main
    except KeyError:
        return [Blocker("the document holds no behavior tree", None, None, False)]
    if tree.root is None:
        return [
            Blocker("the main behavior tree is empty", tree.location, f"tree '{tree.id}'", False)
        ]
    if is_dispatch_bt(doc):  # the dispatch form's own model (docs/semantics.md section 12)
        return _dispatch_blockers(doc)
    checker = CompiledTree.checker(doc)
    seen: set[tuple[str, tuple[str, ...]]] = set()
    stack: list[tuple[BTNode, tuple[str, ...]]] = [(tree.root, (tree.id,))]
    checked = 0
    while stack and checked < MAX_CHECKED:
        node, chain = stack.pop()
        checked += 1
        try:
            ctype, _kind, _params, _internal, kids = checker.check_node(node, chain)
        except InputError as exc:  # UnsupportedError is an InputError
            found.append(
                Blocker(exc.message, exc.location, exc.element, isinstance(exc, UnsupportedError))
            )
            kids = [] if node.is_leaf else list(node.children)
            ctype = None
        if ctype == SUBTREE_TYPE:
            target = node.attrs["ID"]
            key = (target, chain)
            if key not in seen:
                seen.add(key)
                sub = doc.trees[target].root
                if sub is not None:
                    stack.append((sub, chain + (target,)))
            continue
        stack.extend((child, chain) for child in reversed(kids))
    return found


def _dispatch_blockers(doc: BTDocument) -> list[Blocker]:
    """What the dispatch form's macro-step model refuses in ``doc`` (its first refusal: the
    blackboard model compiles the whole tree at once)."""
    try:
        DispatchMachine(doc, ())
    except InputError as exc:
        return [Blocker(exc.message, exc.location, exc.element, isinstance(exc, UnsupportedError))]
    return []
