"""Skeletons for the migration path: the leaf classes of a behavior tree, for the user to fill.

``write_skeleton(model, directory, language)`` reads a BehaviorTree.CPP v4 document (a tree
``fsmbt convert`` wrote in the structured style, a hand-written tree, any tree with or without a
``<TreeNodesModel>``), finds its leaf types (``leaves.leaf_kinds``) and writes, for C++
(``cpp.py``) or Python (``python.py``), a generated base class per type, a user class per type
that is written once and never overwritten, the registration or tree builder, and a main that
loads and ticks the tree (``files.py`` holds the writing rules and the change report).
docs/runtime.md and docs/runtime-python.md, "The migration path".
"""

from __future__ import annotations

from pathlib import Path

from fsmbt.formats import dumps, read_model
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.runtime.skeleton.cpp import cpp_files, project_name
from fsmbt.runtime.skeleton.cpp import user_file as cpp_user_file
from fsmbt.runtime.skeleton.files import WriteReport, manifest, write_files
from fsmbt.runtime.skeleton.leaves import LeafKind, leaf_kinds
from fsmbt.runtime.skeleton.python import python_files
from fsmbt.runtime.skeleton.python import user_file as py_user_file

LANGUAGES = ("cpp", "python")

__all__ = ["LANGUAGES", "LeafKind", "WriteReport", "leaf_kinds", "load_tree", "write_skeleton"]


def load_tree(model: Path) -> BTDocument:
    """The behavior tree in ``model``; a state machine is refused with the command to run.

    Raises:
        InputError: unreadable, not a BehaviorTree.CPP document.
    """
    doc = read_model(model)
    if not isinstance(doc, BTDocument):
        raise InputError(
            f"{model} is a state machine, not a behavior tree: convert it first "
            f"(fsmbt convert {model} -o tree.xml) and give the tree",
        )
    return doc


def write_skeleton_for(
    doc: BTDocument, directory: Path, language: str, *, source: str, force: bool = False
) -> WriteReport:
    """Write the skeleton of ``doc`` (see the package doc); ``source`` names the tree."""
    if language not in LANGUAGES:
        raise InputError(f"unknown language '{language}' (known: {', '.join(LANGUAGES)})")
    leaves = leaf_kinds(doc)
    tree_text = dumps(doc, "btcpp")
    if language == "cpp":
        files = cpp_files(
            doc, leaves, tree_text, source=source, project=project_name(Path(source).stem)
        )
        users = {leaf.type: cpp_user_file(leaf) for leaf in leaves}
    else:
        files = python_files(doc, leaves, tree_text, source=source)
        users = {leaf.type: py_user_file(leaf) for leaf in leaves}
    return write_files(directory, files, manifest(language, leaves), users, force=force)


def write_skeleton(
    model: Path, directory: Path, language: str, *, force: bool = False
) -> WriteReport:
    """Read ``model`` and write its skeleton into ``directory`` (see ``write_skeleton_for``)."""
    return write_skeleton_for(load_tree(model), directory, language, source=model.name, force=force)
