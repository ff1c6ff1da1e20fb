"""Pictures of models through Graphviz: DOT source (testable without Graphviz) and SVG/PNG files.

``model_to_dot`` gives the DOT source of either model; ``render_model`` writes the picture the
output file's suffix names (``.svg``, ``.png``, ``.pdf``, or ``.dot`` for the source), never
replacing an existing file unless ``overwrite``. Models with more than ``max_nodes`` states or
nodes (default 5 000) are refused with a ``TooLargeError``.
"""

from __future__ import annotations

from pathlib import Path

from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.render.anchor_ids import trace_anchors
from fsmbt.render.bt_graph import bt_to_dot
from fsmbt.render.dot import (
    DEFAULT_MAX_NODES,
    DOT_TIMEOUT_S,
    OUTPUT_FORMATS,
    GraphvizError,
    TooLargeError,
    check_output,
    run_dot,
    write_picture,
)
from fsmbt.render.fsm_graph import fsm_to_dot


def model_to_dot(model: FSM | BTDocument, *, expand_subtrees: bool = False,
                 max_nodes: int = DEFAULT_MAX_NODES, anchors: bool = False) -> str:
    """The DOT source of the picture of ``model``.

    Args:
        model: an FSM or a BT document.
        expand_subtrees: BT: draw the main tree with each SubTree's tree below its reference.
        max_nodes: refuse (``TooLargeError``) larger models.
        anchors: give every state / node a predictable SVG id (``fsmbt.render.anchor_ids``).

    Returns:
        The DOT source.
    """
    if isinstance(model, FSM):
        return fsm_to_dot(model, max_nodes=max_nodes, anchors=anchors)
    return bt_to_dot(model, expand_subtrees=expand_subtrees, max_nodes=max_nodes,
                     anchors=anchors)


def svg_text(model: FSM | BTDocument, *, expand_subtrees: bool = False,
             max_nodes: int = DEFAULT_MAX_NODES, anchors: bool = True,
             timeout: float = DOT_TIMEOUT_S) -> str:
    """The picture of ``model`` as an SVG document to embed in a page (no XML prolog).

    Args:
        model: an FSM or a BT document.
        expand_subtrees, max_nodes, anchors: as for ``model_to_dot``.
        timeout: seconds Graphviz may take.

    Returns:
        The ``<svg>`` element's text.

    Raises:
        TooLargeError: the model is over ``max_nodes``; GraphvizError: Graphviz is missing,
        failed or took longer than ``timeout``.
    """
    source = model_to_dot(model, expand_subtrees=expand_subtrees, max_nodes=max_nodes,
                          anchors=anchors)
    text = run_dot(source, "svg", timeout=timeout).decode("utf-8")
    start = text.find("<svg")
    return text[start:] if start >= 0 else text


def render_model(model: FSM | BTDocument, path: str | Path, *, overwrite: bool = False,
                 expand_subtrees: bool = False, max_nodes: int = DEFAULT_MAX_NODES) -> Path:
    """Draw ``model`` into ``path`` (format from the suffix) and return the path."""
    check_output(Path(path), overwrite=overwrite)  # fail before laying out a picture
    source = model_to_dot(model, expand_subtrees=expand_subtrees, max_nodes=max_nodes)
    return write_picture(source, path, overwrite=overwrite)


__all__ = ["model_to_dot", "svg_text", "trace_anchors", "fsm_to_dot", "bt_to_dot", "render_model", "run_dot", "write_picture",
           "GraphvizError", "TooLargeError", "DEFAULT_MAX_NODES", "OUTPUT_FORMATS"]
