"""A verification report in the words of the models' authors (docs/cli.md, "Glossary").

The checkers name a BT's leaf-execution states ``label@path`` (child indices from the root, e.g.
``MovetoCube2@1/1/0/1/0/1``) and, in leaf-execution mode, call a leaf's outcome an *input*
(``on input 'failure'``). Both are exact but nobody finds ``1/1/0/1/0/1`` in their file.
``readable(report, source, result)`` rewrites a report's texts for people:

- ``label@path`` -> ``label`` when that label names one leaf of the tree, else
  ``label (line N)`` (and ``tree 'T'`` when the leaf comes from a SubTree's tree), using the
  compiled tree the checker ran (``fsmbt.semantics.bt_interpreter.CompiledTree``);
- ``on input 'failure'`` (leaf-execution mode) -> ``when the previous leaf returned FAILURE``.

The verdict, the properties and the traces' shapes are unchanged; only display strings (property
details, the states in counterexample steps) are rewritten, and JSON keys stay the same.
Cost: O(N) to compile the tree once, then O(length of the texts).
"""

from __future__ import annotations

import re
from collections import Counter

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.verify.report import Report

_OUTCOME_INPUT = re.compile(r"on input '(success|failure|running)'")
_NODE_NAME = re.compile(r"([^\s,;:'()\[\]/]+)@((?:\d+(?:/\d+)*)|root)")


def leaf_names(doc: BTDocument) -> dict[str, str]:
    """The checker's ``label@path`` of every leaf of ``doc``'s main tree -> a readable name.

    Args:
        doc: the BT document (SubTrees expanded as the checker expands them).

    Returns:
        ``{"MovetoCube2@1/1/0/1/0/1": "MovetoCube2", ...}``; empty when the tree cannot be
        compiled (the checker then refused it before any report existed).
    """
    from fsmbt.semantics.bt_interpreter import CompiledTree

    try:
        tree = CompiledTree(doc)
    except (InputError, KeyError):
        return {}
    leaves = [n for n in tree.nodes if not n.children]
    counts = Counter(n.label for n in leaves)
    main_id = doc.main.id
    owner = _owning_trees(doc)
    names: dict[str, str] = {}
    for node in leaves:
        key = f"{node.label}@{node.path or 'root'}"
        if counts[node.label] == 1:
            names[key] = node.label
            continue
        parts = []
        tree_id = owner.get(id(node.source))
        if tree_id is not None and tree_id != main_id:
            parts.append(f"tree '{tree_id}'")
        location = node.source.location
        if location is not None and location.line is not None:
            parts.append(f"line {location.line}")
        else:
            parts.append(f"node {node.path or 'root'}")
        names[key] = f"{node.label} ({', '.join(parts)})"
    return names


def _owning_trees(doc: BTDocument) -> dict[int, str]:
    return {id(node): tree_id for tree_id, node in doc.nodes()}


def _rename(text: str, names: dict[str, str]) -> str:
    if "@" not in text or not names:
        return text
    return _NODE_NAME.sub(lambda m: names.get(m.group(0), m.group(0)), text)


def _outcome_words(text: str) -> str:
    return _OUTCOME_INPUT.sub(
        lambda m: f"when the previous leaf returned {m.group(1).upper()}", text
    )


def readable(report: Report, source: FSM | BTDocument, result: FSM | BTDocument) -> Report:
    """``report`` with its display strings in the models' own names (see the module doc).

    Args:
        report: a report of ``source`` against ``result`` (changed in place).
        source, result: the two models the report compares, in its order.

    Returns:
        The same ``report``.
    """
    source_names = leaf_names(source) if isinstance(source, BTDocument) else {}
    result_names = leaf_names(result) if isinstance(result, BTDocument) else {}
    both = {**result_names, **source_names}
    leaf_mode = report.mode == "leaf-execution"
    for prop in report.properties.values():
        detail = _rename(prop.detail, both)
        prop.detail = _outcome_words(detail) if leaf_mode else detail
        for step in prop.counterexample or []:
            step.source_state = _rename(step.source_state, source_names)
            step.result_state = _rename(step.result_state, result_names)
            step.note = _rename(step.note, both)
    return report
