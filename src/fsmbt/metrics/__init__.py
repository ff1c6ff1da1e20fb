"""Model metrics: the paper's graphical/active element counts, depth, node counts, sub-FSMs,
tree and graph edit distances, and the paper's size formulas (docs/metrics.md)."""

from __future__ import annotations

from typing import Any

from fsmbt.metrics.edit_distance import Distance, graph_edit_distance, tree_edit_distance
from fsmbt.metrics.elements import Elements, bt_elements, elements, fsm_elements
from fsmbt.metrics.formulas import FORMULA_TEXT, FORMULAS, Comparison
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM


def edit_distance(
    first: FSM | BTDocument, second: FSM | BTDocument, *, timeout: float = 5.0
) -> dict[str, Any]:
    """The edit distance between two models of the same kind.

    Args:
        first: a model.
        second: a model of the same kind.
        timeout: seconds for the FSM graph edit distance search (an upper bound when cut).

    Returns:
        ``{"type": "tree edit distance" | "graph edit distance", **Distance.to_dict()}``.

    Raises:
        InputError: the two models are not of the same kind.
    """
    if isinstance(first, BTDocument) and isinstance(second, BTDocument):
        return {"type": "tree edit distance", **tree_edit_distance(first, second).to_dict()}
    if isinstance(first, FSM) and isinstance(second, FSM):
        return {
            "type": "graph edit distance",
            **graph_edit_distance(first, second, timeout=timeout).to_dict(),
        }
    raise InputError("an edit distance needs two models of the same kind (two FSMs or two BTs)")


__all__ = [
    "Elements",
    "elements",
    "bt_elements",
    "fsm_elements",
    "Distance",
    "tree_edit_distance",
    "graph_edit_distance",
    "edit_distance",
    "FORMULAS",
    "FORMULA_TEXT",
    "Comparison",
]
