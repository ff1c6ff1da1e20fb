"""An FSM (flat or hierarchical) as a Graphviz picture.

Drawing rules: states are circles, final states double circles; the initial state gets an arrow
from a point (labelled with the initial event when the model has a start pseudo-state);
transitions are labelled with their events, parallel transitions between the same two states
share one arrow. A composite state is a cluster holding its sub-machine (with its own initial
point); a parallel state is a cluster with one dashed sub-cluster per region. Arrows into or out
of a composite state end at its cluster's border (``compound=true`` with ``lhead``/``ltail``).
Eventless transitions are labelled ``ε`` (from an atomic state) or ``done`` / ``done(x)`` (from a
composite state when its sub-machine reaches a final state, ``x`` if only that one).

Levels: ``level=N`` draws the composite states nested at most N deep as clusters and deeper
ones closed (a bold rounded box saying how many states it holds); ``composite="A/B"`` draws that
composite state alone (its cluster, its sub-machines). A hierarchical machine too large for the
layered layout (more than ``LAYERED_MAX_STATES`` states or ``LAYERED_MAX_ARROWS`` arrows) is drawn
to the deepest level that fits, and ``notes`` says so and names the composites to draw next.
``fsmbt.render.fsm_fit`` measures a picture and draws it again (``rankdir``, ``rows``, a
``level``) until it fits 4 096 pixels at 100 %. In pictures, names longer than ``NAME_LINE``
are broken into lines.
A flat machine that large uses the force-directed ``sfdp`` layout (seconds for thousands of
states; dot's layered layout with edge labels needs minutes from about a hundred states).

The same builder writes the DOT *file format* (``fsmbt convert --to dot``, registered by
``fsmbt.formats.diagrams.dot``) with ``exchange=True``: node ids are the state names (``Parent/child``
paths inside composite states, ``Parent/0:child`` in parallel regions), each carrying an
``action`` attribute when its action differs from its name; every transition is its own edge
labelled with its exact event (eventless: no label); the initial point is named after the start
pseudo-state (else ``__start__``); the layered layout is always used and no size limit applies.
That is what ``fsmbt.formats.diagrams.dot``'s reader reads back (docs/formats/dot.md). Pictures also
carry the ``action`` attribute (Graphviz ignores attributes it does not know).

Built without recursion: clusters are created in pre-order and written out by one pre-order
walk (``render.dot.assemble``). Complexity O(S + T) for S states (every level) and T transitions.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import graphviz

from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.fsm_data import ASSIGN, COND, parse_lines
from fsmbt.model.stats import fsm_stats
from fsmbt.render.anchor_ids import START_ANCHOR, state_anchor
from fsmbt.render.dot import (
    DEFAULT_MAX_NODES,
    FONT,
    TooLargeError,
    assemble,
    check_size,
    dot_id,
    edge_line,
    label_text,
)

#: The initial point's id in exchange DOT when the model names no start pseudo-state; the
#: reader (``fsmbt.formats.diagrams.dot``) takes a node of this name as the start marker.
START_NODE = "__start__"

#: The SVG class of a closed composite state's box (with anchors; its id is the state's
#: ``s@`` anchor): what a page clicks to draw that composite alone.
CLOSED_CLASS = "fold"
#: Nested clusters beyond this depth make dot slow and the picture unreadable.
MAX_NESTING = 60
#: Beyond these sizes the layered ``dot`` layout is too slow; ``sfdp`` is used, without clusters.
LAYERED_MAX_STATES = 60
LAYERED_MAX_ARROWS = 150
#: At most this many event names per arrow label line.
EVENTS_PER_LINE = 3
#: Graphviz ``size``: a picture larger than this (inches) is scaled down to fit, so a PNG
#: (96 dpi) stays within 4096 x 4096 pixels and an SVG within 4096 x 4096 px at 96 px/inch.
MAX_PICTURE_INCHES = "42.6,42.6"


#: How a diff's removed states and transitions look: dashed and grey.
GHOST_STATE_STYLE = {"shape": "circle", "style": "dashed", "color": "gray55", "fontcolor": "gray45"}
GHOST_EDGE_STYLE = {"style": "dashed", "color": "gray55", "fontcolor": "gray45"}


@dataclass
class _Level:
    """One machine being drawn: where its nodes go and how its state names map to node ids."""

    machine: FSM
    graph: graphviz.Digraph
    ids: dict[str, str] = field(default_factory=dict)
    anchors: dict[str, tuple[str, str]] = field(
        default_factory=dict
    )  # composite -> (node, cluster)
    prefix: str = ""  # large pictures: nested states are named by their path
    entry: str | None = None  # large pictures: the composite state's box, drawn instead of a point
    path: str = ""  # exchange DOT: the node-id prefix of this level's states
    anchor: str = ""  # anchors: the composite-state path of this level ("Parent/"), no regions
    aliases: dict[str, str] = field(default_factory=dict)  # data variable -> its short name
    owner: str = ""  # the top-level state this level is inside ("": the top machine)


def _find_composite(fsm: FSM, path: str) -> State:
    """The composite state at ``path`` (``A/B``: B inside A), else a located error."""
    machines, state = [fsm], None
    for part in path.split("/"):
        state = next((m.states[part] for m in machines if part in m.states), None)
        if state is None:
            break
        machines = list(state.regions)
    if state is None or state.is_atomic:
        known = ", ".join(composite_paths(fsm)[:20]) or "none"
        raise InputError(f"no composite state '{path}' (composite states: {known})", element=path)
    return state


def composite_paths(fsm: FSM) -> list[str]:
    """Every composite state's path (``A``, ``A/B``), pre-order, explicit stack."""
    found: list[str] = []
    stack: list[tuple[FSM, str]] = [(fsm, "")]
    while stack:
        machine, prefix = stack.pop()
        inner: list[tuple[FSM, str]] = []
        for state in machine.states.values():
            if not state.is_atomic:
                found.append(prefix + state.name)
                inner.extend((region, f"{prefix}{state.name}/") for region in state.regions)
        stack.extend(reversed(inner))
    return found


def _inner_states(state: State) -> int:
    """How many states (all levels) a composite state holds."""
    count = 0
    stack = list(state.regions)
    while stack:
        machine = stack.pop()
        count += len(machine.states)
        stack.extend(r for s in machine.states.values() for r in s.regions)
    return count


def visible_size(fsm: FSM, level: int) -> tuple[int, int]:
    """(states, transitions) drawn when composites deeper than ``level`` are closed. O(S + T)."""
    states = transitions = 0
    stack: list[tuple[FSM, int]] = [(fsm, 0)]
    while stack:
        machine, depth = stack.pop()
        states += len(machine.states)
        transitions += len(machine.transitions)
        if depth < level:
            stack.extend(
                (region, depth + 1) for state in machine.states.values() for region in state.regions
            )
    return states, transitions


def _layered(states: int, transitions: int) -> bool:
    return states <= LAYERED_MAX_STATES and transitions <= LAYERED_MAX_ARROWS


def layered_size_fits(fsm: FSM, level: int) -> bool:
    """Whether ``fsm`` with its composites nested deeper than ``level`` closed is small enough
    for the layered layout (else it is drawn force-directed). O(S + T)."""
    return _layered(*visible_size(fsm, level))


def drawn_machine(fsm: FSM, composite: str | None) -> tuple[FSM, int]:
    """The machine a picture of ``composite`` (``None``: the whole of ``fsm``) draws, and the
    level its own states are at: a composite state's sub-machine (level 0), or for a parallel
    state a machine holding that state alone (level 1: its regions are one level down).

    Raises:
        InputError: ``composite`` names no composite state (the message lists them).
    """
    if composite is None:
        return fsm, 0
    state = _find_composite(fsm, composite)
    if len(state.regions) == 1:  # its sub-machine is the picture
        return state.regions[0], 0
    return FSM(name=composite, states={state.name: state}, initial=state.name), 1


def fsm_to_dot(
    fsm: FSM,
    *,
    max_nodes: int | None = DEFAULT_MAX_NODES,
    exchange: bool = False,
    level: int | None = None,
    composite: str | None = None,
    notes: list[str] | None = None,
    anchors: bool = False,
    marks: Mapping[str, Mapping[str, str]] | None = None,
    ghosts: Sequence[str] = (),
    ghost_edges: Sequence[tuple[str, str, str]] = (),
    rankdir: str = "LR",
    rows: Mapping[str, int] | None = None,
    owners: dict[str, str] | None = None,
) -> str:
    """DOT source of ``fsm``.

    Args:
        fsm: the machine (flat or hierarchical).
        max_nodes: refuse (``TooLargeError``) more states than this (and more than five times
            as many transitions), and nesting deeper than ``MAX_NESTING``; ``None``: no limit.
        exchange: write the DOT file format that ``fsmbt.formats.diagrams.dot`` reads back (see the
            module docstring) instead of the picture's DOT.
        level: draw composite states nested at most this deep as clusters (0: the top machine
            only, composites closed); default: all, or the deepest that fits (see above).
        composite: draw only this composite state (path ``A/B``).
        notes: told what was left out of the picture and how to draw it.
        anchors: give every state an SVG id from its name (``fsmbt.render.anchors``): atomic
            and composite states ``s@Parent/child``, the top initial point ``start@``.
        marks: extra Graphviz attributes per atomic state, keyed by its anchor id (whether or
            not ``anchors`` is set): how a diff highlights changed states.
        ghosts: states that are not in ``fsm`` (a diff's removed states), drawn dashed and grey.
        ghost_edges: transitions that are not in ``fsm`` as ``(tail anchor, head anchor,
            label)`` between drawn atomic states or ghosts (``s@`` + the ghost's name), dashed.
        rankdir: pictures: ``LR`` (transitions left to right) or ``TB`` (top down).
        rows: pictures, layered layout: wrap the top machine into rows (``TB``: columns), the
            row of each top-level state by name (missing: 0). A transition between two rows
            does not rank its ends (``constraint=false``), so every row starts again at the
            left: a long chain becomes a block of shorter rows. (Rows are not clusters: dot
            fails with "lost edge" on such edges between clusters.)
        owners: filled with each drawn node's DOT id -> the top-level state it belongs to (the
            state itself, or the composite state holding it): what ``fsm_fit`` needs to
            choose rows from a measured layout.

    Returns:
        The DOT source text.

    Raises:
        InputError: ``composite`` names no composite state (the message lists them).
    """
    first_level = 0
    if composite is not None and not exchange:
        fsm, first_level = drawn_machine(fsm, composite)
        if level is not None:  # a parallel state's level counts from its regions: open them
            level += first_level
    stats = fsm_stats(fsm)
    if max_nodes is not None:
        check_size(stats.all_states, max_nodes, "states")
        check_size(stats.all_transitions, 5 * max_nodes, "transitions")
        if stats.nesting_depth > MAX_NESTING:
            raise TooLargeError(
                f"too deeply nested to draw: {stats.nesting_depth} levels (limit {MAX_NESTING})"
            )

    if (
        not exchange
        and level is None
        and stats.hierarchical
        and not _layered(stats.all_states, stats.all_transitions)
    ):
        level = first_level
        while level + 1 < stats.nesting_depth and _layered(*visible_size(fsm, level + 1)):
            level += 1
        if notes is not None:
            shown, _ = visible_size(fsm, level)
            closed = [p for p in composite_paths(fsm) if p.count("/") == level]
            names = ", ".join(closed[:6]) + (
                f", ... (+{len(closed) - 6})" if len(closed) > 6 else ""
            )
            notes.append(
                f"picture capped: {stats.all_states} states are too many for one "
                f"readable picture; drew {shown} states, composite states nested "
                f"deeper than level {level} closed ({names}); draw one with "
                "composite=NAME or more levels with level=N"
            )
    visible = (
        visible_size(fsm, level) if level is not None else (stats.all_states, stats.all_transitions)
    )
    layered = exchange or _layered(*visible)
    if not layered and notes is not None and level is None:
        notes.append(
            f"{visible[0]} states without hierarchy to split into levels: drawn with "
            "a force-directed layout (no clusters); fsmbt info lists its structure"
        )
    root = graphviz.Digraph(name=dot_id(fsm.name) if exchange else _safe_name(fsm.name))
    if not exchange:  # at most 4096 x 4096 pixels at 96 dpi (scaled down, never up)
        root.attr(size=MAX_PICTURE_INCHES)
    if layered:
        root.attr(
            rankdir="LR" if exchange else rankdir,
            compound="true",
            fontname=FONT,
            nodesep="0.35",
            ranksep="0.5",
        )
    else:
        root.attr(
            layout="sfdp", overlap="prism", splines="false", outputorder="edgesfirst", fontname=FONT
        )
    root.attr("node", fontname=FONT, fontsize="12")
    root.attr("edge", fontname=FONT, fontsize="10", arrowsize="0.8")
    counter = _Counter(exchange)
    edges: list[tuple[str, str, dict[str, str]]] = []
    clusters: list[tuple[graphviz.Digraph, graphviz.Digraph]] = []  # (cluster, parent), pre-order

    owner_of: dict[str, str] = {} if owners is None else owners
    owner_of.clear()

    marks = marks or {}
    drawn: dict[str, str] = {}  # anchor id -> DOT node id of atomic states, for ghost edges
    level_cap = level  # the drawing loop below names each machine being drawn ``lv``
    # a composite drawn alone keeps its states' full paths in their anchors (s@A/B/x)
    top_anchor = ""
    if composite is not None and not exchange:
        parent = composite.rpartition("/")[0]  # a parallel one is drawn as its parent's state
        top_anchor = f"{composite}/" if first_level == 0 else (f"{parent}/" if parent else "")
    top = _Level(fsm, root, anchor=top_anchor)
    depth_of: dict[int, int] = {id(top): 0}
    pending: list[_Level] = [top]
    levels: list[_Level] = []
    while pending:
        lv = pending.pop()
        levels.append(lv)
        for state in lv.machine.states.values():
            title = lv.prefix + state.name
            owner = lv.owner or state.name
            is_closed = (
                not exchange
                and level_cap is not None
                and not state.is_atomic
                and depth_of[id(lv)] >= level_cap
            )
            if is_closed:
                node_id = counter.state_id(lv, state.name)
                lv.ids[state.name] = node_id
                owner_of[node_id] = owner
                inside = _inner_states(state)
                # anchors: the closed box carries the composite's id and the class a page
                # clicks to draw it (composite=PATH)
                closed_id = (
                    {"id": state_anchor(lv.anchor + state.name), "class": CLOSED_CLASS}
                    if anchors
                    else {}
                )
                lv.graph.node(
                    node_id,
                    **closed_id,
                    label=label_text(
                        *_name_lines(_state_title(state, title)), f"[{inside} states inside]"
                    ),
                    shape="box",
                    style="rounded,bold,filled",
                    fillcolor="gray95",
                )
                continue
            if state.is_atomic:
                node_id = counter.state_id(lv, state.name)
                lv.ids[state.name] = node_id
                owner_of[node_id] = owner
                attrs = _state_attrs(state, title, compact=not layered, wrap=not exchange)
                anchor = state_anchor(lv.anchor + state.name)
                drawn[anchor] = node_id
                if anchors:
                    attrs["id"] = anchor
                attrs.update(marks.get(anchor, {}))
                lv.graph.node(node_id, **attrs)
                continue
            if not layered:  # a box standing for the composite state, no cluster
                node_id = counter.next("c")
                owner_of[node_id] = owner
                extra = {"id": state_anchor(lv.anchor + state.name)} if anchors else {}
                lv.graph.node(
                    node_id,
                    label=label_text(*_name_lines(_state_title(state, title))),
                    shape="box",
                    style="rounded,bold",
                    **extra,
                )
                inner = [
                    _Level(
                        region,
                        lv.graph,
                        prefix=f"{title}/",
                        entry=node_id,
                        anchor=f"{lv.anchor}{state.name}/",
                        owner=owner,
                    )
                    for region in state.regions
                ]
                lv.anchors[state.name] = (node_id, "")
                depth_of.update((id(x), depth_of[id(lv)] + 1) for x in inner)
                pending.extend(reversed(inner))
                continue
            cluster = graphviz.Digraph(name=counter.next("cluster_"))
            cluster.attr(
                label=label_text(
                    *(
                        [_state_title(state, state.name)]
                        if exchange
                        else _name_lines(_state_title(state, state.name), 2 * NAME_LINE)
                    )
                ),
                style="rounded",
                color="gray30",
                fontname=FONT,
                fontsize="12",
                labeljust="l",
            )
            if anchors:
                cluster.attr(id=state_anchor(lv.anchor + state.name))
            clusters.append((cluster, lv.graph))
            inner = []
            for index, region in enumerate(state.regions):
                region_graph = cluster
                path = f"{lv.path}{state.name}/"
                if state.is_parallel:
                    region_graph = graphviz.Digraph(name=counter.next("cluster_"))
                    region_graph.attr(
                        label=label_text(_region_title(region, index)),
                        style="dashed",
                        color="gray50",
                        fontname=FONT,
                        fontsize="10",
                    )
                    clusters.append((region_graph, cluster))
                    path = f"{path}{index}:"
                inner.append(
                    _Level(
                        region,
                        region_graph,
                        path=path,
                        anchor=f"{lv.anchor}{state.name}/",
                        owner=owner,
                    )
                )
            # Arrows to/from the composite state end at its cluster, through its first initial point.
            point = _initial_point_id(inner[0], counter)
            owner_of[point] = owner
            lv.anchors[state.name] = (point, cluster.name)
            depth_of.update((id(x), depth_of[id(lv)] + 1) for x in inner)
            pending.extend(reversed(inner))

    aliases = {} if exchange else _aliases(fsm)
    if aliases:  # the legend: short names keep the guards on the arrows short
        lines = [f"{short} = {name}" for name, short in aliases.items()]
        root.node("__data__", label=label_text("data", *lines), shape="note", fontsize="11")
    for lv in levels:
        lv.aliases = aliases
        _draw_initial(lv, edges, counter, is_top=lv is top, anchors=anchors)
        _draw_transitions(lv, edges, exact=exchange)
    if fsm.initial is not None and "__initial_point__" in top.ids:
        owner_of[top.ids["__initial_point__"]] = fsm.initial
    for name in ghosts:
        ghost_id = counter.next("g")
        drawn.setdefault(state_anchor(name), ghost_id)
        root.node(ghost_id, label=label_text(name), **GHOST_STATE_STYLE)
    for tail, head, text in ghost_edges:
        if tail in drawn and head in drawn:
            edges.append(
                (drawn[tail], drawn[head], {"label": label_text(text), **GHOST_EDGE_STYLE})
            )

    if rows and layered and not exchange:  # an arrow between rows does not rank its ends
        row_of = rows
        for tail, head, attrs in edges:
            if row_of.get(owner_of.get(tail, ""), 0) != row_of.get(owner_of.get(head, ""), 0):
                attrs["constraint"] = "false"
    return assemble(root, clusters, [edge_line(tail, head, attrs) for tail, head, attrs in edges])


class _Counter:
    """Node ids: serial numbers in pictures, state-name paths in exchange DOT."""

    def __init__(self, exchange: bool = False) -> None:
        self.value = 0
        self.exchange = exchange

    def next(self, prefix: str) -> str:
        self.value += 1
        return f"{prefix}{self.value}"

    def state_id(self, level: _Level, name: str) -> str:
        return dot_id(level.path + name) if self.exchange else self.next("s")

    def point_id(self, level: _Level, *, is_top: bool) -> str:
        """The id of ``level``'s initial point (exchange DOT: named after the start
        pseudo-state, which the reader takes back as ``start_name``)."""
        if self.exchange:
            return dot_id(level.path + (level.machine.start_name or START_NODE))
        return self.next("init") if not is_top else f"init_{level.graph.name or 'root'}"


def _safe_name(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch == "_" else "_" for ch in name) or "fsm"


def _state_title(state: State, title: str) -> str:
    if state.action is not None and state.action != state.name:
        return f"{title} / {state.action}"
    return title


#: Pictures: a state name longer than this many characters is broken into lines (a circle is
#: as wide as its longest line, so one long name makes the whole rank wide).
NAME_LINE = 18
_STRONG_BREAK = re.compile(r"(?<=[/#;, ])")
_WEAK_BREAK = re.compile(r"(?<=[_.\-])|(?<=[a-z0-9])(?=[A-Z])")


def _name_lines(text: str, width: int = NAME_LINE) -> list[str]:
    """``text`` as lines of at most ``width`` characters where it can be: broken after ``/ # ;
    ,`` and spaces first, then (inside a longer piece) after ``_ . -`` and between a lower-case
    letter and a capital; a piece without such a place stays whole. Nothing is shortened: the
    lines joined give ``text`` back but for the spaces at the breaks. O(len(text))."""
    if len(text) <= width:
        return [text]
    pieces: list[str] = []
    for piece in _STRONG_BREAK.split(text):
        pieces.extend(_WEAK_BREAK.split(piece) if len(piece) > width else [piece])
    lines: list[str] = []
    current = ""
    for piece in pieces:
        if current and len(current) + len(piece.rstrip()) > width:
            lines.append(current.rstrip())
            current = ""
        current += piece
    if current:
        lines.append(current)
    return lines


def _says_action(title: str, action: str) -> bool:
    """Whether a state's drawn name already shows its action: ``q3:Move``, a flattened path
    ``on/ready/begin`` running ``begin``, or a data-expanded name ``off#timer=1`` running
    ``off`` - then the ``/ action`` line is left out."""
    base = title.split("#", 1)[0]
    return base == action or base.endswith((f"/{action}", f":{action}"))


def _region_title(region: FSM, index: int) -> str:
    return region.name if region.name and region.name != "fsm" else f"region {index + 1}"


def _state_attrs(
    state: State, title: str, *, compact: bool = False, wrap: bool = False
) -> dict[str, str]:
    """Circles (double for final states); ellipses in large pictures, where long path names
    would make circles huge. ``wrap`` (pictures): long names broken into lines
    (``_name_lines``), the action line left out when the name shows it (``_says_action``)."""
    lines = _name_lines(title) if wrap else [title]
    if state.action is not None and state.action != state.name:
        if not wrap and not title.endswith(f":{state.action}"):  # ``q3:Move`` already says it
            lines.append(f"/ {state.action}")
        elif wrap and not _says_action(title, state.action):
            action_lines = _name_lines(state.action)
            lines += [f"/ {action_lines[0]}", *action_lines[1:]]
    attrs = {"label": label_text(*lines), "shape": "doublecircle" if state.final else "circle"}
    if state.action != state.name:  # read back by fsmbt.formats.diagrams.dot; Graphviz ignores it
        attrs["action"] = dot_id(state.action or "")
    if compact:
        attrs.update(shape="ellipse", peripheries="2" if state.final else "1")
    if state.final:
        attrs.update(style="filled", fillcolor="gray92")
    return attrs


def _initial_point_id(level: _Level, counter: _Counter) -> str:
    point = level.ids.get("__initial_point__")
    if point is None:
        point = counter.point_id(level, is_top=False)
        level.ids["__initial_point__"] = point
        level.graph.node(point, label="", shape="point", width="0.12")
    return point


def _draw_initial(
    level: _Level, edges: list, counter: _Counter, *, is_top: bool, anchors: bool = False
) -> None:
    """The arrow from a point into the level's initial state (a composite state's point is
    its anchor and already exists)."""
    fsm = level.machine
    if fsm.initial is None or fsm.initial not in fsm.states:
        return
    head, head_attrs = _endpoint(level, fsm.initial, "lhead")
    if level.entry is not None:  # large pictures: from the composite state's box
        edges.append((level.entry, head, {"style": "dotted", "arrowhead": "empty"}))
        return
    point = level.ids.get("__initial_point__")
    if point is None:
        point = counter.point_id(level, is_top=True)
        level.ids["__initial_point__"] = point
        extra = {"xlabel": label_text(fsm.start_name)} if is_top and fsm.start_name else {}
        if is_top and anchors:
            extra["id"] = START_ANCHOR
        level.graph.node(point, label="", shape="point", width="0.12", **extra)
    attrs: dict[str, str] = {}
    if is_top and fsm.initial_event is not None:
        attrs["label"] = (
            _exact_label(fsm.initial_event) if counter.exchange else label_text(fsm.initial_event)
        )
    edges.append((point, head, {**attrs, **head_attrs}))


def _draw_transitions(level: _Level, edges: list, *, exact: bool = False) -> None:
    """Pictures: one arrow per (source, target) pair listing its events; ``exact`` (exchange
    DOT): one edge per transition labelled with its event as written, eventless unlabelled."""
    grouped: dict[tuple[str, ...], list[str]] = {}
    for index, t in enumerate(level.machine.transitions):
        if t.source not in level.machine.states or t.target not in level.machine.states:
            continue  # a dangling transition is `validate`'s business; draw what exists
        if exact:
            grouped[(t.source, t.target, str(index))] = [] if t.event is None else [t.event]
        else:
            grouped.setdefault((t.source, t.target), []).append(_event_label(level, t))
    for (source, target, *_), labels in grouped.items():
        tail, tail_attrs = _endpoint(level, source, "ltail")
        head, head_attrs = _endpoint(level, target, "lhead")
        attrs = {**tail_attrs, **head_attrs}
        if tail == head and tail_attrs and head_attrs:
            attrs = {}
        if exact:
            if labels:
                attrs["label"] = _exact_label(labels[0])
            edges.append((tail, head, attrs))
            continue
        # dot places a mid-edge label on the unclipped spline, i.e. inside the cluster an arrow
        # leaves; a head label stays next to the arrow's visible end.
        label_key = "headlabel" if "ltail" in attrs else "label"
        attrs[label_key] = _wrap(labels)
        if label_key == "headlabel":
            attrs.update(labeldistance="3", labelangle="-25")
        edges.append((tail, head, attrs))


def _exact_label(text: str) -> str:
    """An event as an exchange-DOT label: the text as written (line breaks kept), backslashes
    doubled so DOT escapes (``\\n``, ``\\N``) stay text."""
    return graphviz.nohtml(text.replace("\\", "\\\\"))


def _endpoint(level: _Level, state: str, side: str) -> tuple[str, dict[str, str]]:
    if state in level.anchors:
        node, cluster = level.anchors[state]
        return node, ({side: cluster} if cluster else {})
    return level.ids[state], {}


def _event_label(level: _Level, t) -> str:
    if t.event is not None:
        return t.event + _data_label(t, level.aliases)
    if level.machine.states[t.source].is_atomic:
        return "ε"
    return f"done({t.exit})" if t.exit is not None else "done"


_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_WORDS = frozenset({"and", "or", "not", "True", "False", "None", "In", "true", "false"})


def _aliases(fsm: FSM) -> dict[str, str]:
    """The data variables the drawn machines' guards and updates name, each with a short name
    (``v1``, ``v2``, ... in order of first use) for the arrows; the legend gives the full one."""
    found: dict[str, None] = {}
    for machine in fsm.machines():
        for t in machine.transitions:
            texts = [t.attrs.get(COND, "")]
            texts += [f"{n} {e}" for n, e in parse_lines(t.attrs.get(ASSIGN, ""))]
            for text in texts:
                for name in _IDENTIFIER.findall(re.sub(r"'[^']*'", "", text)):
                    if name not in _WORDS:
                        found.setdefault(name, None)
    return {name: f"v{n}" for n, name in enumerate(found, 1)}


def _short(text: str, aliases: dict[str, str]) -> str:
    if not aliases:
        return text
    return _IDENTIFIER.sub(lambda m: aliases.get(m.group(0), m.group(0)), text)


def _data_label(t, aliases: dict[str, str] | None = None) -> str:
    """A data guard and its updates (``fsmbt.model.fsm_data``) as UML writes them,
    ``event [cond] / x := e``, one conjunct and one update per line (a picture stays narrow)."""
    text = ""
    if COND in t.attrs:
        guard = _short(t.attrs[COND], aliases or {})
        for word in (" and ", " or ", " && ", " || "):
            guard = guard.replace(word, word.rstrip() + "\n  ")
        text += f" [{guard}]"
    updates = parse_lines(t.attrs.get(ASSIGN, ""))
    if updates:
        shown = [(_short(n, aliases or {}), _short(e, aliases or {})) for n, e in updates]
        text += " /\n  " + "\n  ".join(f"{name} := {expr}" for name, expr in shown)
    return text


def _wrap(labels: list[str]) -> str:
    if any("[" in label or " /" in label for label in labels):  # guards: one line each
        return label_text(*(line for label in labels for line in label.split("\n")))
    lines = [
        ", ".join(labels[i : i + EVENTS_PER_LINE]) for i in range(0, len(labels), EVENTS_PER_LINE)
    ]
    return label_text(*lines)
