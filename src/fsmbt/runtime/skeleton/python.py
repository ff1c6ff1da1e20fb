"""The Python skeleton of a behavior tree: py_trees behaviours, the tree builder, a main.

For every leaf type of the tree (``leaves.leaf_kinds``):

- ``generated/bases.py``: one ``py_trees.behaviour.Behaviour`` base class per type, built with
  the leaf's label and its parameters (the ports the tree writes), with ``get_input`` /
  ``set_output`` over py_trees' blackboard for ``{key}`` ports and BehaviorTree.CPP's action
  protocol (``on_start`` / ``on_running`` / ``on_halted``; ``on_tick`` for a Condition).
- ``nodes/<type>.py``: the user's class (a working default body: log and succeed); written
  once, never rewritten.
- ``generated/tree.py``: ``create_tree()``, the tree as py_trees composites, one statement per
  node (leaves first: no nesting, so a deep tree is no deep expression); SubTrees inlined.
- ``main.py`` (written once): build the tree and tick it until it ends.

Control nodes: those py_trees runs with BehaviorTree.CPP v4's meaning
(``fsmbt.semantics.engines.pytrees_engine.SUPPORTED_TYPES``: Sequence, ReactiveSequence,
Fallback, ReactiveFallback, Inverter, ForceSuccess, ForceFailure, AlwaysSuccess,
AlwaysFailure, SubTree) and BehaviorTree.CPP's ``RetryUntilSuccessful`` and ``Repeat``, which
``generated/bases.py`` defines with v4's rules (a tick is BehaviorTree.CPP's
``tickExactlyOnce()``: no wake-up re-tick). Any other node is refused with its name and line (py_trees has no
node with the same semantics; the C++ skeleton runs every BehaviorTree.CPP built-in).

Cost: O(nodes after SubTree expansion) to render.
"""

from __future__ import annotations

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.nodes import SUBTREE_TYPE
from fsmbt.runtime.skeleton.files import SkeletonFile
from fsmbt.runtime.skeleton.leaves import LeafKind
from fsmbt.runtime.skeleton.render import render
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.engines.pytrees_engine import SUPPORTED_TYPES

_COMPOSITES = {
    "Sequence": "py_trees.composites.Sequence({name}, memory=True, children=[{kids}])",
    "ReactiveSequence": "py_trees.composites.Sequence({name}, memory=False, children=[{kids}])",
    "Fallback": "py_trees.composites.Selector({name}, memory=True, children=[{kids}])",
    "ReactiveFallback": "py_trees.composites.Selector({name}, memory=False, children=[{kids}])",
    "Inverter": "py_trees.decorators.Inverter({name}, child={kids})",
    "ForceSuccess": "py_trees.decorators.FailureIsSuccess({name}, child={kids})",
    "ForceFailure": "py_trees.decorators.SuccessIsFailure({name}, child={kids})",
    "AlwaysSuccess": "py_trees.behaviours.Success({name})",
    "AlwaysFailure": "py_trees.behaviours.Failure({name})",
    "RetryUntilSuccessful": "RetryUntilSuccessful({name}, {kids}, {limit})",
    "Repeat": "Repeat({name}, {kids}, {limit})",
}
#: The loop decorators of generated/bases.py (BehaviorTree.CPP's rules, not py_trees' own).
LOOPS = frozenset({"RetryUntilSuccessful", "Repeat"})


def user_file(leaf: LeafKind) -> str:
    return f"nodes/{leaf.file_stem}.py"


def tree_statements(doc: BTDocument, leaves: list[LeafKind]) -> tuple[list[str], str]:
    """The statements building the main tree, and the root's variable.

    Raises:
        InputError: a node py_trees cannot run with its BehaviorTree.CPP meaning (named, with
            its line), or a ROS 2 leaf (the Python skeleton has no ROS client).
    """
    by_type = {leaf.type: leaf for leaf in leaves}
    compiled = CompiledTree(doc)
    for node in compiled.nodes:  # document order: the first offending node is named
        source = node.source
        leaf = by_type.get(source.type) if node.is_env_leaf else None
        if leaf is not None and leaf.ros is not None:
            raise InputError(
                f"<{source.type}> is a ROS 2 {leaf.ros.kind} leaf: the Python skeleton "
                "has no ROS client (use fsmbt runtime cpp DIR MODEL: behaviortree_ros2)",
                location=source.location,
                element=f"<{source.type}> '{source.label}'",
            )
        runnable = node.type == SUBTREE_TYPE or (
            node.type in _COMPOSITES and (node.type in SUPPORTED_TYPES or node.type in LOOPS)
        )
        if leaf is None and not runnable:
            raise InputError(
                f"<{node.type}> has no py_trees equivalent with BehaviorTree.CPP's meaning (the "
                "Python skeleton runs Sequence, Fallback, their reactive forms, Inverter, "
                "ForceSuccess, ForceFailure, RetryUntilSuccessful, Repeat, AlwaysSuccess, "
                "AlwaysFailure, SubTree); the C++ "
                "skeleton (fsmbt runtime cpp DIR MODEL) runs every built-in",
                location=source.location,
                element=f"<{source.type}> '{source.label}'",
            )
    lines: list[str] = []
    for node in reversed(compiled.nodes):
        var = f"n{node.id}"
        name = repr(node.label)
        source = node.source
        if node.is_env_leaf and source.type in by_type:
            leaf = by_type[source.type]
            params = {k: v for k, v in source.attrs.items() if not k.startswith("_")}
            lines.append(f"{var} = {leaf.class_name}({name}, **{params!r})")
            continue
        if node.type == SUBTREE_TYPE:
            lines.append(f"{var} = n{node.children[0]}  # SubTree {source.attrs.get('ID')}")
            continue
        template = _COMPOSITES[node.type]
        kids = ", ".join(f"n{c}" for c in node.children)
        limit = node.params[0] if node.type in LOOPS else None
        lines.append(f"{var} = " + template.format(name=name, kids=kids, limit=limit))
    return lines, "n0"


def python_files(
    doc: BTDocument, leaves: list[LeafKind], tree_text: str, *, source: str
) -> list[SkeletonFile]:
    """Every file of the Python skeleton (see the module doc)."""
    statements, root = tree_statements(doc, leaves)
    common: dict[str, object] = {"source": source, "leaves": leaves}
    files = [
        SkeletonFile("tree.xml", tree_text, user=False),
        SkeletonFile(
            "generated/__init__.py",
            f'"""GENERATED by `fsmbt runtime python` from {source} - do not edit."""\n',
            False,
        ),
        SkeletonFile("generated/bases.py", render("py_bases.py.j2", **common), False),
        SkeletonFile(
            "generated/tree.py",
            render("py_tree.py.j2", statements=statements, root=root, **common),
            False,
        ),
        SkeletonFile(
            "nodes/__init__.py",
            '"""Your leaf classes, one module per leaf type (fsmbt never overwrites them)."""\n',
            True,
        ),
    ]
    for leaf in leaves:
        files.append(SkeletonFile(user_file(leaf), render("py_user_node.py.j2", leaf=leaf), True))
    files.append(SkeletonFile("main.py", render("py_main.py.j2", **common), True))
    return files
