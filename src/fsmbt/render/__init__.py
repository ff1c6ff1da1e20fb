"""Pictures of models through Graphviz: DOT source (testable without Graphviz) and SVG/PNG files.

``model_to_dot`` gives the DOT source of either model; ``render_model`` writes the picture the
output file's suffix names (``.svg``, ``.png``, ``.pdf``, or ``.dot`` for the source), never
replacing an existing file unless ``overwrite``. Models with more than ``max_nodes`` states or
nodes (default 5 000) are refused with a ``TooLargeError``.
"""

from __future__ import annotations

from pathlib import Path

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.render.anchor_ids import trace_anchors
from fsmbt.render.bt_graph import Ghost, bt_to_dot
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


def model_to_dot(
    model: FSM | BTDocument,
    *,
    expand_subtrees: bool = False,
    max_nodes: int = DEFAULT_MAX_NODES,
    level: int | None = None,
    composite: str | None = None,
    tree: str | None = None,
    notes: list[str] | None = None,
    anchors: bool = False,
) -> str:
    """The DOT source of ``model``'s picture.

    Args:
        model: an FSM or a BT document.
        expand_subtrees: BT: the main (or ``tree``) tree with its SubTrees inlined.
        max_nodes: refuse models with more states/nodes than this.
        level: FSM: composite states nested deeper than this are drawn closed.
        composite: FSM: draw only this composite state (path ``A/B``).
        tree: BT: draw only this tree.
        notes: told what a capped picture left out and how to draw it.
        anchors: give every state / node a predictable SVG id (``fsmbt.render.anchor_ids``).

    Returns:
        The DOT source.

    Raises:
        TooLargeError: past ``max_nodes``; InputError: an unknown ``composite`` / ``tree``, or
        an option of the other model kind.
    """
    if isinstance(model, FSM):
        if tree is not None or expand_subtrees:
            raise InputError("tree and expand_subtrees are for behavior trees; this is an FSM")
        return fsm_to_dot(
            model,
            max_nodes=max_nodes,
            level=level,
            composite=composite,
            notes=notes,
            anchors=anchors,
        )
    if level is not None or composite is not None:
        raise InputError(
            "level and composite are for hierarchical FSMs; this is a behavior "
            "tree (draw one tree with tree=ID)"
        )
    return bt_to_dot(
        model,
        expand_subtrees=expand_subtrees,
        max_nodes=max_nodes,
        tree=tree,
        notes=notes,
        anchors=anchors,
    )


def svg_text(
    model: FSM | BTDocument,
    *,
    expand_subtrees: bool = False,
    max_nodes: int = DEFAULT_MAX_NODES,
    anchors: bool = True,
    timeout: float = DOT_TIMEOUT_S,
) -> str:
    """The picture of ``model`` as an SVG document to embed in a page (no XML prolog).

    Args:
        model: an FSM or a BT document.
        expand_subtrees, max_nodes, anchors: as for ``model_to_dot`` (``expand_subtrees`` is
            ignored for an FSM, so one call serves either kind).
        timeout: seconds Graphviz may take.

    Returns:
        The ``<svg>`` element's text.

    Raises:
        TooLargeError: the model is over ``max_nodes``; GraphvizError: Graphviz is missing,
        failed or took longer than ``timeout``.
    """
    expand = expand_subtrees and not isinstance(model, FSM)  # an FSM has no SubTrees
    source = model_to_dot(model, expand_subtrees=expand, max_nodes=max_nodes, anchors=anchors)
    text = run_dot(source, "svg", timeout=timeout).decode("utf-8")
    start = text.find("<svg")
    return text[start:] if start >= 0 else text


def render_model(
    model: FSM | BTDocument,
    path: str | Path,
    *,
    overwrite: bool = False,
    expand_subtrees: bool = False,
    max_nodes: int = DEFAULT_MAX_NODES,
    level: int | None = None,
    composite: str | None = None,
    tree: str | None = None,
    notes: list[str] | None = None,
) -> Path:
    """Draw ``model`` into ``path`` (format from the suffix) and return the path.

    Args:
        model, expand_subtrees, max_nodes, level, composite, tree, notes: as for
            ``model_to_dot``.
        path: the picture file.
        overwrite: replace an existing file.

    Returns:
        The path written.
    """
    check_output(Path(path), overwrite=overwrite)  # fail before laying out a picture
    source = model_to_dot(
        model,
        expand_subtrees=expand_subtrees,
        max_nodes=max_nodes,
        level=level,
        composite=composite,
        tree=tree,
        notes=notes,
    )
    return write_picture(source, path, overwrite=overwrite)


__all__ = [
    "model_to_dot",
    "svg_text",
    "trace_anchors",
    "fsm_to_dot",
    "bt_to_dot",
    "Ghost",
    "render_model",
    "run_dot",
    "write_picture",
    "GraphvizError",
    "TooLargeError",
    "DEFAULT_MAX_NODES",
    "OUTPUT_FORMATS",
]
