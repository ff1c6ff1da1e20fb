"""Model metrics: the paper's graphical/active element counts, depth, node counts, sub-FSMs,
tree and graph edit distances, and the paper's size formulas (docs/metrics.md)."""

from fsmbt.metrics.edit_distance import Distance, graph_edit_distance, tree_edit_distance
from fsmbt.metrics.elements import Elements, bt_elements, elements, fsm_elements
from fsmbt.metrics.formulas import FORMULA_TEXT, FORMULAS, Comparison

__all__ = ["Elements", "elements", "bt_elements", "fsm_elements", "Distance",
           "tree_edit_distance", "graph_edit_distance", "FORMULAS", "FORMULA_TEXT", "Comparison"]
