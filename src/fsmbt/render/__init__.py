"""Pictures of models through Graphviz: DOT source (testable without Graphviz) and SVG/PNG files.

``model_to_dot`` gives the DOT source of either model; ``render_model`` writes the picture the
output file's suffix names (``.svg``, ``.png``, ``.pdf``, or ``.dot`` for the source), never
replacing an existing file unless ``overwrite``. Models with more than ``max_nodes`` states or
nodes (default 5 000) are refused with a ``TooLargeError``.

Pictures are made to be read at 100 %: a behavior tree too big for 4 096 x 4 096 pixels is
folded (subtrees past a node budget drawn as a ``[k nodes]`` box, wide levels wrapped into rows,
``fsmbt.render.bt_fold``; ``depth`` and ``focus`` choose what to show), an FSM is measured and
laid out again - top down, its top machine wrapped into rows, its composites folded into
``[k states inside]`` boxes (``fsmbt.render.fsm_fit``; ``level`` and ``composite``/``focus``
choose what to show); either is scaled down to fit only as a last resort. A PNG or
SVG whose long side is more than 4 times its short side is laid out again with Graphviz's
``ratio``, which spreads the nodes apart along the short side (node and label sizes unchanged).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.render.anchor_ids import trace_anchors
from fsmbt.render.bt_fold import TARGET_INCHES
from fsmbt.render.bt_graph import Ghost, bt_to_dot
from fsmbt.render.dot import (
    DEFAULT_MAX_NODES,
    DOT_TIMEOUT_S,
    MAX_ASPECT,
    OUTPUT_FORMATS,
    GraphvizError,
    TooLargeError,
    check_output,
    fit_aspect,
    layout_extent,
    run_dot,
    write_picture,
)
from fsmbt.render.fsm_fit import fit_fsm_dot
from fsmbt.render.fsm_graph import composite_paths, fsm_to_dot

#: The sides (inches) a behavior tree's fold plan is tried with until its layout fits
#: (``picture_dot``), largest first.
FIT_TARGETS = (36.0, 30.0, 24.0, 18.0, 13.0)
#: The side (inches) a layout must fit in to be drawn at 100 % (4 096 px at 96 dpi).
FIT_INCHES = 42.6


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
    focus: str | None = None,
    fold: bool = True,
    target: float = TARGET_INCHES,
) -> str:
    """The DOT source of ``model``'s picture.

    Args:
        model: an FSM or a BT document.
        expand_subtrees: BT: the main (or ``tree``) tree with its SubTrees inlined.
        max_nodes: refuse models with more states/nodes than this.
        level: FSM: composite states nested deeper than this are drawn closed. BT: nodes more
            than this many levels below the drawn root are folded (``bt_to_dot``'s ``depth``).
        composite: FSM: draw only this composite state (path ``A/B``).
        tree: BT: draw only this tree.
        notes: told what a capped picture left out and how to draw it.
        anchors: give every state / node a predictable SVG id (``fsmbt.render.anchor_ids``).
        focus: BT: draw only the subtree under this node (a path ``0/2/1`` or a node name).
            FSM: ``composite``'s other name (the composite state whose inside is drawn).
        fold: BT: fold a tree too big to read at 100 % (``bt_to_dot``'s ``fold``).
        target: BT: the side (inches) the folded picture is estimated to fit (``bt_to_dot``).

    Returns:
        The DOT source.

    Raises:
        TooLargeError: past ``max_nodes``; InputError: an unknown ``composite`` / ``tree``, or
        an option of the other model kind.
    """
    if isinstance(model, FSM):
        return fsm_to_dot(
            model,
            max_nodes=max_nodes,
            level=level,
            composite=_fsm_composite(tree, expand_subtrees, composite, focus),
            notes=notes,
            anchors=anchors,
        )
    if composite is not None:
        raise InputError(
            "composite is for hierarchical FSMs; this is a behavior "
            "tree (draw one tree with tree=ID, one subtree with focus=PATH)"
        )
    return bt_to_dot(
        model,
        expand_subtrees=expand_subtrees,
        max_nodes=max_nodes,
        tree=tree,
        notes=notes,
        anchors=anchors,
        fold=fold,
        depth=level,
        focus=focus,
        target=target,
    )


def _fsm_composite(
    tree: str | None, expand_subtrees: bool, composite: str | None, focus: str | None
) -> str | None:
    """The composite state an FSM picture draws (``composite``, or ``focus``: the same for an
    FSM); refuses the behavior-tree options and two different composites."""
    if tree is not None or expand_subtrees:
        raise InputError("tree and expand_subtrees are for behavior trees; this is an FSM")
    if focus is not None and composite is not None and focus != composite:
        raise InputError(
            f"focus '{focus}' and composite '{composite}' name two parts of one FSM; give one"
        )
    return composite if composite is not None else focus


def picture_dot(
    model: FSM | BTDocument,
    *,
    notes: list[str] | None = None,
    timeout: float = DOT_TIMEOUT_S,
    **options: Any,
) -> str:
    """``model_to_dot(model, **options)``, measured: the fold plan of a behavior tree only
    estimates label sizes and dot's spacing, so its layout is measured (``dot -Tplain``) and, if
    still larger than ``FIT_INCHES`` or more elongated than ``MAX_ASPECT``, planned again for the
    next smaller side in ``FIT_TARGETS``; the first that fits is kept, else the one Graphviz has
    to scale down least. At most ``len(FIT_TARGETS)`` extra layouts (a fraction of a second each
    for a folded picture), one for a tree that fits at once. ``notes`` gets the notes of the
    picture returned. Without Graphviz, the first plan (from the estimate alone)."""
    if isinstance(model, FSM):  # measured and laid out again by fsm_fit
        return fit_fsm_dot(
            model,
            notes=notes,
            timeout=timeout,
            max_nodes=options.get("max_nodes", DEFAULT_MAX_NODES),
            level=options.get("level"),
            composite=_fsm_composite(
                options.get("tree"),
                bool(options.get("expand_subtrees")),
                options.get("composite"),
                options.get("focus"),
            ),
            anchors=bool(options.get("anchors")),
        )
    attempt_notes: list[str] = []
    source = model_to_dot(model, notes=attempt_notes, **options)
    if not options.get("fold", True):
        if notes is not None:
            notes.extend(attempt_notes)
        return source
    best: tuple[float, str, list[str]] | None = None
    for index, target in enumerate(FIT_TARGETS):
        if index:
            attempt_notes = []
            source = model_to_dot(model, notes=attempt_notes, target=target, **options)
        try:
            _, width, height = layout_extent(source, timeout=timeout)
        except GraphvizError:  # no dot (a .dot file needs none): the estimate's plan
            best = (1.0, source, attempt_notes)
            break
        long, short = max(width, height), max(0.01, min(width, height))
        if long <= FIT_INCHES and long <= MAX_ASPECT * short:
            best = (2.0, source, attempt_notes)
            break
        fit = min(1.0, FIT_INCHES / long)
        if best is None or fit > best[0]:
            best = (fit, source, attempt_notes)
        if not attempt_notes and long <= FIT_INCHES:
            break  # nothing folded and within the cap: only the aspect is off (fit_aspect)
    assert best is not None
    if notes is not None:
        notes.extend(best[2])
    return best[1]


def svg_text(
    model: FSM | BTDocument,
    *,
    expand_subtrees: bool = False,
    max_nodes: int = DEFAULT_MAX_NODES,
    anchors: bool = True,
    timeout: float = DOT_TIMEOUT_S,
    focus: str | None = None,
    composite: str | None = None,
) -> str:
    """The picture of ``model`` as an SVG document to embed in a page (no XML prolog).

    Args:
        model: an FSM or a BT document.
        expand_subtrees, max_nodes, anchors: as for ``model_to_dot`` (``expand_subtrees`` is
            ignored for an FSM, so one call serves either kind).
        timeout: seconds Graphviz may take.
        focus, composite: as for ``model_to_dot``: a BT's subtree under ``focus`` alone (what
            a fold box opens), an FSM's composite state ``composite`` alone (what a closed
            composite's box opens); each is refused (``InputError``) for the other kind.

    Returns:
        The ``<svg>`` element's text.

    Raises:
        TooLargeError: the model is over ``max_nodes``; GraphvizError: Graphviz is missing,
        failed or took longer than ``timeout``.
    """
    expand = expand_subtrees and not isinstance(model, FSM)  # an FSM has no SubTrees
    source = picture_dot(
        model,
        expand_subtrees=expand,
        max_nodes=max_nodes,
        anchors=anchors,
        timeout=timeout,
        focus=focus,
        composite=composite,
    )
    data = fit_aspect(source, "svg", run_dot(source, "svg", timeout=timeout), timeout=timeout)
    text = data.decode("utf-8")
    start = text.find("<svg")
    return text[start:] if start >= 0 else text


def picture_bytes(model: FSM | BTDocument, fmt: str, *, timeout: float = DOT_TIMEOUT_S) -> bytes:
    """The default picture of ``model`` in ``fmt`` (``png``, ``svg``, ``pdf``) as
    ``render_model`` draws it: measured (``picture_dot``), elongated pictures laid out again
    (``fit_aspect``)."""
    source = picture_dot(model, timeout=timeout)
    return fit_aspect(source, fmt, run_dot(source, fmt, timeout=timeout), timeout=timeout)


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
    focus: str | None = None,
) -> Path:
    """Draw ``model`` into ``path`` (format from the suffix) and return the path.

    Args:
        model, expand_subtrees, max_nodes, level, composite, tree, notes, focus: as for
            ``model_to_dot``.
        path: the picture file.
        overwrite: replace an existing file.

    Returns:
        The path written.
    """
    check_output(Path(path), overwrite=overwrite)  # fail before laying out a picture
    source = picture_dot(
        model,
        expand_subtrees=expand_subtrees,
        max_nodes=max_nodes,
        level=level,
        composite=composite,
        tree=tree,
        notes=notes,
        focus=focus,
    )
    return write_picture(source, path, overwrite=overwrite, max_aspect=MAX_ASPECT)


def render_pages(
    model: FSM | BTDocument,
    directory: str | Path,
    *,
    fmt: str = "svg",
    overwrite: bool = False,
    max_nodes: int = DEFAULT_MAX_NODES,
    notes: list[str] | None = None,
) -> list[Path]:
    """One picture per level of a hierarchical FSM: ``top.<fmt>`` (the top machine, every
    composite closed into a box) and one per composite state, its own machine with the
    composites inside it closed (``A.<fmt>``, ``A__B.<fmt>`` for ``A/B``); data guards and
    updates label the arrows; each state is drawn on the page of the machine it belongs to
    (every page laid out to fit at 100 % as ``fit_fsm_dot`` does, never folded further), file
    names made unique. A behavior tree gets one picture per ``<BehaviorTree>``, the main one
    first, each drawn alone (its SubTrees as references, big ones folded; file names from
    the tree IDs, made unique). Each picture is capped at 4096 x 4096 pixels.

    Returns:
        The pictures written, top (main tree) first.
    """
    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(model, BTDocument):
        return _tree_pages(model, folder, fmt, overwrite, max_nodes, notes)
    pages: list[tuple[str, str | None]] = [("top", None)]
    pages += [(path.replace("/", "__"), path) for path in composite_paths(model)]
    paths = _page_paths(folder, [stem for stem, _ in pages], fmt, "page")
    for path in paths:  # refuse before writing any, so a refusal leaves the folder as it was
        check_output(path, overwrite=overwrite)
    written: list[Path] = []
    for (_, composite), path in zip(pages, paths, strict=True):
        source = fit_fsm_dot(model, max_nodes=max_nodes, level=0, composite=composite, notes=notes)
        written.append(write_picture(source, path, overwrite=overwrite, max_aspect=MAX_ASPECT))
    return written


def _page_stem(name: str) -> str:
    """A page's file name from a composite path or tree ID: plain characters only."""
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name)


def _page_paths(folder: Path, names: list[str], fmt: str, fallback: str) -> list[Path]:
    """One file per name in ``folder``, from ``_page_stem`` made unique (``-2``, ``-3``, ...):
    two names that differ only in unsafe characters or case (``A B`` and ``A_B``, ``Main``
    and ``main`` on a case-insensitive disk) never share a page."""
    taken: set[str] = set()
    paths: list[Path] = []
    for name in names:
        stem = _page_stem(name) or fallback
        unique, count = stem, 1
        while unique.lower() in taken:
            count += 1
            unique = f"{stem}-{count}"
        taken.add(unique.lower())
        paths.append(folder / f"{unique}.{fmt}")
    return paths


def _tree_pages(
    doc: BTDocument,
    folder: Path,
    fmt: str,
    overwrite: bool,
    max_nodes: int,
    notes: list[str] | None,
) -> list[Path]:
    """``render_pages`` for a behavior tree: one picture per tree, the main one first."""
    main = doc.main.id
    order = [main, *(tree_id for tree_id in doc.trees if tree_id != main)]
    paths = _page_paths(folder, order, fmt, "tree")
    for path in paths:  # refuse before writing any, so a refusal leaves the folder as it was
        check_output(path, overwrite=overwrite)
    written: list[Path] = []
    for tree_id, path in zip(order, paths, strict=True):
        source = picture_dot(doc, max_nodes=max_nodes, tree=tree_id, notes=notes)
        written.append(write_picture(source, path, overwrite=overwrite, max_aspect=MAX_ASPECT))
    return written


__all__ = [
    "render_pages",
    "model_to_dot",
    "picture_dot",
    "picture_bytes",
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
