"""The composite states of a hierarchical dispatch tree's machine, recovered (docs/semantics.md
§12a, "Back to a state machine").

``fsmbt.convert.dispatch_fsm`` reads a dispatch tree as the flat machine of its macro steps.
For a tree of the hierarchical form its states are named by their configurations (``A/a1``,
``model.flatten``'s names), and ``lift_hierarchy`` rebuilds the hierarchical machine those names
describe:

1. every name split at ``/`` is a path; every proper prefix is a composite state, the last part
   an atomic state (a name that is also a prefix of another gives up);
2. a composite's initial child is read off the configurations it is entered at (from the start
   and by every transition from outside it): they must all be one configuration, and the
   entries of the composites on its path must agree;
3. a flat transition ``X --e--> Y`` becomes the transition ``x --e--> y`` of the level where the
   paths of ``X`` and ``Y`` part (``x``, ``y`` their states there; a self-loop stays on the
   atomic state), which needs ``Y`` to be the configuration ``y`` is entered at; ``x`` composite
   makes it the composite's own transition, written once for all the configurations inside it
   (two different targets give up);
4. nested states are not final (a final sub-state without a completion handles no event, as an
   atomic state without transitions does); a top-level state is final as in the flat machine.

The result is kept only when its flattening (``model.flatten``) is the flat machine itself -
the same initial state and event, states (names, actions, finality) and transitions - so the
lift never changes the behaviour (the checker proves the pair as for the flat machine); any
other case returns ``None`` and the flat machine stands. Completions (``done.state``) are not
recovered: the tree resolved them into the transitions they end.

Cost: O(states · depth + transitions · depth) plus one flattening of the result.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from fsmbt.model.errors import InputError
from fsmbt.model.flatten import PATH_SEPARATOR, flatten
from fsmbt.model.fsm import FSM, State

_Path = tuple[str, ...]


@dataclass
class _Node:
    """A composite state (or the top machine, path ``()``) being rebuilt."""

    machine: FSM
    children: dict[str, None] = field(default_factory=dict)  # in first-seen order
    entry: _Path | None = None  # the configuration it is entered at


def lift_hierarchy(flat: FSM) -> FSM | None:
    """The hierarchical machine whose flattening is ``flat``, or ``None`` (module docstring)."""
    if flat.initial is None or not any(PATH_SEPARATOR in n for n in flat.states):
        return None
    paths = {name: tuple(name.split(PATH_SEPARATOR)) for name in flat.states}
    leaves = set(paths.values())
    nodes: dict[_Path, _Node] = {(): _Node(FSM(name=flat.name))}
    for path in paths.values():
        if any(not part for part in path):
            return None
        for k in range(1, len(path)):
            prefix = path[:k]
            if prefix in leaves:
                return None  # a state that is also a composite
            nodes.setdefault(prefix, _Node(FSM(name=PATH_SEPARATOR.join(prefix))))
        for k in range(len(path)):
            nodes[path[:k]].children.setdefault(path[k], None)
    # entries: the start, and every transition from outside a composite into it
    assert flat.initial is not None
    entries: list[tuple[_Path, _Path]] = [((), paths[flat.initial])]
    entries.extend((paths[t.source], paths[t.target]) for t in flat.transitions)
    for source, target in entries:
        for k in range(1, len(target)):
            if source[:k] == target[:k]:
                continue  # entered from inside
            node = nodes[target[:k]]
            if node.entry is None:
                node.entry = target
            elif node.entry != target:
                return None  # entered at two configurations: history or a completion
    top = nodes[()].machine
    top.initial = paths[flat.initial][0]
    top.start_name, top.initial_event = flat.start_name, flat.initial_event

    def entered(path: _Path) -> _Path:
        """The configuration entering the state at ``path`` leads to."""
        node = nodes.get(path)
        if node is None:
            return path
        return node.entry or path

    own: dict[tuple[_Path, str], _Path] = {}
    for t in flat.transitions:
        source, target = paths[t.source], paths[t.target]
        event = t.event
        if event is None:
            return None
        common = 0
        while common < min(len(source), len(target)) and source[common] == target[common]:
            common += 1
        if common == len(source) == len(target):  # a self-loop of an atomic state
            common -= 1
        if common >= min(len(source), len(target)):
            return None  # one path inside the other: not a configuration change we can name
        x, y = source[: common + 1], target[: common + 1]
        if entered(y) != target:
            return None
        if own.setdefault((x, event), y) != y:
            return None  # the composite's configurations leave it two ways
    for path, node in sorted(nodes.items(), key=lambda item: len(item[0])):
        for child in node.children:
            full = (*path, child)
            sub = nodes.get(full)
            if sub is None:
                leaf = flat.states[PATH_SEPARATOR.join(full)]
                node.machine.add_state(
                    State(child, action=leaf.action, final=leaf.final and not path)
                )
            else:
                node.machine.add_state(State(child, action=None, regions=[sub.machine]))
        if path:
            if node.entry is None:
                return None
            node.machine.initial = node.entry[len(path)]
    for (x, event), y in own.items():
        nodes[x[:-1]].machine.add_transition(x[-1], event, y[-1])
    try:
        again = flatten(top)
    except InputError:
        return None
    return top if _same(again, flat) else None


def _same(a: FSM, b: FSM) -> bool:
    """Same initial state and event, states (name, action, finality) and transitions."""

    def shape(fsm: FSM) -> tuple[object, ...]:
        states = sorted((s.name, s.action or "", s.final) for s in fsm.states.values())
        edges = sorted((t.source, str(t.event), t.target) for t in fsm.transitions)
        return fsm.initial, fsm.initial_event, states, edges

    return shape(a) == shape(b)
