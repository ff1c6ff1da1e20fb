"""A state machine's picture made to fit 4 096 x 4 096 pixels at 100 % (issue 29).

``fsm_to_dot`` draws a machine left to right, every composite state open; Graphviz's ``size``
cap then scales a layout longer than 42.6 inches down, and the labels with it. ``fit_fsm_dot``
measures the layout (``dot -Tplain``) and, while it does not fit, tries in this order:

1. the same picture top down (``rankdir=TB``): a long chain of wide states is often shorter that
   way;
2. **wrapped rows**: the top machine cut into 2, 3, ... rows (``TB``: columns) at the positions
   the first layout gave its states; transitions between rows do not rank their ends
   (``fsm_to_dot``'s ``rows``), so each row starts again at the left;
3. **folded levels** (only when the caller gave no ``level``): the composite states nested
   deeper than level ``d`` closed into ``[k states inside]`` boxes, ``d`` from the deepest
   down to the top machine, each tried as in 1-2; a note says what was folded and how to see it
   (``composite=NAME`` / ``focus=NAME``, every level with ``render_pages``).

The first layout that fits is drawn; when none does, the one Graphviz scales down least, and a
note gives the scale. Costs: one layout for a picture that fits (all of the corpus's small
machines), at most ``MAX_LAYOUTS`` otherwise, each O(layout of the drawn machine). The
force-directed pictures of big flat machines (``sfdp``) have no ranks to wrap: one too big is
laid out again with less margin around its nodes (``SPREAD_MARGINS``, labels unchanged).
"""

from __future__ import annotations

import math
import re

from fsmbt.model.fsm import FSM
from fsmbt.model.stats import fsm_stats
from fsmbt.render.dot import DEFAULT_MAX_NODES, DOT_TIMEOUT_S, GraphvizError, run_dot
from fsmbt.render.fsm_graph import (
    composite_paths,
    drawn_machine,
    fsm_to_dot,
    layered_size_fits,
    visible_size,
)

#: The side (inches) a layout must fit in to be drawn at 100 % (4 096 px at 96 dpi).
FIT_INCHES = 42.6
#: Most layouts tried for one picture (each a fraction of a second for a corpus machine).
MAX_LAYOUTS = 16
#: The margins (points) around a force-directed picture's nodes tried, after Graphviz's
#: default ``+4``, when it is too big: ``sfdp`` removes overlaps by pushing nodes this far apart.
SPREAD_MARGINS = ("+2", "+1")
#: Most rows a top machine is wrapped into.
MAX_ROWS = 6

_NODE = re.compile(r'^node ("(?:[^"\\]|\\.)*"|\S+) (\S+) (\S+) (\S+) (\S+)')


#: Two states whose layout starts within this many inches along the rank axis share a rank.
SAME_RANK = 0.2


def _layout(
    source: str, timeout: float
) -> tuple[float, float, dict[str, tuple[float, float, float, float]]]:
    """(width, height, node id -> (x, y, width, height) of its box) of dot's layout of
    ``source``, inches (``x``, ``y``: the centre, ``y`` up), before any ``size`` scaling (``dot
    -Tplain`` reports the scale separately)."""
    lines = run_dot(source, "plain", timeout=timeout).decode("utf-8", "replace").splitlines()
    head = lines[0].split() if lines else []
    if len(head) < 4 or head[0] != "graph":
        raise GraphvizError("Graphviz gave no layout size")
    scale = float(head[1]) or 1.0
    boxes: dict[str, tuple[float, float, float, float]] = {}
    for line in lines[1:]:
        found = _NODE.match(line)
        if found:
            x, y, w, h = (float(found.group(i)) / scale for i in range(2, 6))
            boxes[found.group(1).strip('"')] = (x, y, w, h)
    return float(head[2]), float(head[3]), boxes


def _rows(
    owners: dict[str, str],
    boxes: dict[str, tuple[float, float, float, float]],
    extent: float,
    rankdir: str,
    count: int,
) -> dict[str, int] | None:
    """The row of each top-level state when its ranks (in the measured layout, along ``LR``: x,
    ``TB``: y from the top) are cut into ``count`` runs of about equal length: every state
    whose first node starts at the same place is in one rank, a rank as long as its longest
    state, and a rank goes to the row its middle falls in; ``None`` when one rank alone is longer
    than ``FIT_INCHES`` (a composite state that big: no wrapping makes it fit). O(N log N) for
    N drawn nodes."""
    span: dict[str, tuple[float, float]] = {}  # owner -> (start, end) along the rank axis
    for node, owner in owners.items():
        if node not in boxes:
            continue
        x, y, w, h = boxes[node]
        low, high = (
            (x - w / 2, x + w / 2) if rankdir == "LR" else (extent - y - h / 2, extent - y + h / 2)
        )
        first, last = span.get(owner, (low, high))
        span[owner] = (min(first, low), max(last, high))
    ranks: list[tuple[float, float, list[str]]] = []  # (start, length, owners)
    for owner, (first, last) in sorted(span.items(), key=lambda item: item[1][0]):
        if ranks and first - ranks[-1][0] <= SAME_RANK:
            start, length, members = ranks[-1]
            ranks[-1] = (start, max(length, last - first), [*members, owner])
        else:
            ranks.append((first, last - first, [owner]))
    if any(length > FIT_INCHES for _, length, _ in ranks):
        return None
    total = sum(length for _, length, _ in ranks) or 1.0
    rows: dict[str, int] = {}
    done = 0.0
    for _, length, members in ranks:
        row = min(count - 1, int((done + length / 2) / total * count))
        rows.update((owner, row) for owner in members)
        done += length
    return rows


def fit_fsm_dot(
    fsm: FSM,
    *,
    notes: list[str] | None = None,
    timeout: float = DOT_TIMEOUT_S,
    max_nodes: int = DEFAULT_MAX_NODES,
    level: int | None = None,
    composite: str | None = None,
    anchors: bool = False,
) -> str:
    """The DOT source of ``fsm``'s picture (``fsm_to_dot`` with these options), laid out until
    it fits ``FIT_INCHES`` on both sides (see the module docstring); ``notes`` gets the notes of
    the picture returned. Without Graphviz, the first source (nothing measured)."""
    drawn, lowest = drawn_machine(fsm, composite)
    stats = fsm_stats(drawn)
    levels: list[int | None] = [level]
    if level is None and stats.hierarchical:  # folding: deepest level first
        levels += list(range(stats.nesting_depth - 2, lowest - 1, -1))
    best: tuple[float, str, list[str]] | None = None
    layouts = 0
    for fold in levels:
        if fold is not None and fold != level and not layered_size_fits(drawn, fold):
            continue  # still drawn force-directed: folding this far does not help
        fold_note = _fold_note(drawn, fold, level, _path_prefix(composite, lowest))
        for rankdir in ("LR", "TB"):
            if layouts >= MAX_LAYOUTS:
                break
            owners: dict[str, str] = {}
            attempt: list[str] = []
            source = fsm_to_dot(
                fsm,
                max_nodes=max_nodes,
                level=fold,
                composite=composite,
                anchors=anchors,
                notes=attempt,
                rankdir=rankdir,
                owners=owners,
            )
            try:
                width, height, centres = _layout(source, timeout)
            except GraphvizError:  # no dot: the first source, unmeasured
                if notes is not None:
                    notes.extend(attempt)
                return source
            layouts += 1
            tried = [(source, width, height, attempt)]
            spread = "layout=sfdp" in source  # force-directed: no ranks to wrap
            for margin in SPREAD_MARGINS if spread else ():
                if max(width, height) <= FIT_INCHES or layouts >= MAX_LAYOUTS:
                    break
                brace = source.index("{")  # the first, the graph's own (``_safe_name``)
                source = f'{source[: brace + 1]}\n\tsep="{margin}"{source[brace + 1 :]}'
                width, height, _ = _layout(source, timeout)
                layouts += 1
                tried.append((source, width, height, attempt))
            extent = width if rankdir == "LR" else height
            count = max(2, math.ceil(extent / FIT_INCHES))
            while (
                not spread
                and max(width, height) > FIT_INCHES
                and count <= MAX_ROWS
                and layouts < MAX_LAYOUTS
            ):
                rows = _rows(owners, centres, extent, rankdir, count)
                if rows is None or len(set(rows.values())) < 2:
                    break  # one state or composite alone is too long
                attempt = []
                source = fsm_to_dot(
                    fsm,
                    max_nodes=max_nodes,
                    level=fold,
                    composite=composite,
                    anchors=anchors,
                    notes=attempt,
                    rankdir=rankdir,
                    rows=rows,
                )
                count += 1
                layouts += 1
                try:
                    width, height, _ = _layout(source, timeout)
                except GraphvizError:  # dot can fail on a wrapped hierarchy ("lost edge")
                    continue
                tried.append((source, width, height, attempt))
            for source, width, height, attempt in tried:
                fit = min(1.0, FIT_INCHES / max(width, height, 1e-6))
                if best is None or fit > best[0]:
                    best = (fit, source, [*attempt, *([fold_note] if fold_note else [])])
                if fit >= 1.0:
                    return _finish(best, notes)
            if spread and best is not None:
                return _finish(best, notes)
    assert best is not None
    return _finish(best, notes)


def _finish(best: tuple[float, str, list[str]], notes: list[str] | None) -> str:
    """The chosen source; its notes, and its scale when Graphviz must shrink it, into
    ``notes``."""
    fit, source, attempt = best
    if notes is not None:
        notes.extend(attempt)
        if fit < 1.0:
            notes.append(
                f"picture scaled to {fit:.0%} to fit 4096 x 4096 pixels; draw parts with "
                "composite=NAME or level=N, every level with pages=DIR"
            )
    return source


def _fold_note(drawn: FSM, fold: int | None, asked: int | None, prefix: str) -> str | None:
    """What folding the ``drawn`` machine to level ``fold`` left out, when it was not the
    caller's ``level``; composite paths start with ``prefix`` (the composite drawn)."""
    if fold is None or fold == asked:
        return None
    closed = [prefix + path for path in composite_paths(drawn) if path.count("/") == fold]
    names = ", ".join(closed[:6]) + (f", ... (+{len(closed) - 6})" if len(closed) > 6 else "")
    shown, _ = visible_size(drawn, fold)
    return (
        f"picture folded to fit 4096 x 4096 pixels at 100 %: drew {shown} states, composite "
        f"states nested deeper than level {fold} closed ({names}); draw one with composite=NAME "
        "(or focus=PATH), every level with pages=DIR"
    )


def _path_prefix(composite: str | None, lowest: int) -> str:
    """What turns a composite path of the drawn machine into one of the whole machine: the
    drawn composite's path (its sub-machine is drawn) or its parent's (a parallel state is drawn
    inside a machine of its own, ``drawn_machine``)."""
    if composite is None:
        return ""
    if lowest == 0:
        return f"{composite}/"
    parent = composite.rpartition("/")[0]
    return f"{parent}/" if parent else ""
