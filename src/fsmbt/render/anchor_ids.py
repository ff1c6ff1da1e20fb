"""Predictable SVG ids for the states and nodes of a picture, and the ids a trace step is at.

A picture drawn with ``anchors=True`` (``model_to_dot``, ``svg_text``) gives every element an
``id`` that Graphviz copies onto its SVG ``<g>`` element, built from the model, never from a
serial number, so a front end can find "the state the machine is in" without laying anything
out again:

- FSM state: ``s@`` + its path of composite-state names, ``s@Door/Closed`` (parallel regions
  add nothing to the path); a composite state's cluster (or box) carries its own path. The top
  initial point (the start pseudo-state) is ``start@``.
- BT node: ``n@`` + the child-index path from the main tree's root joined by ``/`` (``n@root``
  for the root) when SubTrees are drawn expanded - the same path the interpreter uses
  (``CompiledNode.path``, docs/semantics.md 'Leaf execution'), where a SubTree node has its
  tree's root as child 0; drawn without expansion, ``n@<tree id>@<path in that tree>``.

``trace_anchors`` maps the state names a verification trace uses (``TraceStep.source_state``
and ``result_state``: a flat FSM configuration such as ``C/x`` or ``P/[x|y]`` in either mode,
the LEBT state-variable value of a loop-execution BT in macro-step mode, ``label@path`` or a
root result in leaf-execution mode; docs/verification.md) to the ids present in such a picture.

Costs: building an id is O(length); ``trace_anchors`` is O(size of the model) for one name
(one walk with an explicit stack, no recursion on user data).
"""

from __future__ import annotations

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM

#: The id of the top initial point of an FSM picture.
START_ANCHOR = "start@"
#: What a root result (the tree returned) is called in leaf-execution traces.
ROOT_RESULTS = ("SUCCESS", "FAILURE")


def state_anchor(path: str) -> str:
    """The id of the FSM state at ``path`` (``Parent/child``)."""
    return f"s@{path}"


def child_path(parent: str, index: int) -> str:
    """The path of child ``index`` under the node at ``parent`` (``""`` is the root)."""
    return f"{parent}/{index}" if parent else str(index)


def node_anchor(path: str, tree: str | None = None) -> str:
    """The id of the BT node at ``path`` (``""`` for the root) in ``tree``, or from the main
    root through expanded SubTrees when ``tree`` is ``None``."""
    where = path or "root"
    return f"n@{where}" if tree is None else f"n@{tree}@{where}"


def trace_anchors(model: FSM | BTDocument, state: str, *, expanded: bool = True) -> list[str]:
    """The ids of the picture elements a trace's state name stands for.

    Args:
        model: the model the trace runs on.
        state: ``TraceStep.source_state`` or ``result_state`` for that model.
        expanded: BT pictures only: drawn with ``expand_subtrees`` (ids from the main root).

    Returns:
        The ids, most specific first (an atomic state before its parents); empty when the
        name matches nothing drawn.
    """
    if isinstance(model, FSM):
        return _fsm_anchors(model, state)
    return _bt_anchors(model, state, expanded)


# -- FSM ------------------------------------------------------------------------------------


def _configuration_paths(name: str) -> list[str]:
    """The atomic-state paths of a flat configuration name (docs/semantics.md 'Models'):
    ``C/x`` -> ``[C/x]``, ``P/[x|Q/[y|z]]`` -> ``[P/x, P/Q/y, P/Q/z]``. Explicit stack."""
    paths: list[str] = []
    prefixes: list[str] = [""]  # the prefix of each open bracket
    current = ""
    for char in name:
        if char == "[":
            prefixes.append(prefixes[-1] + current)
            current = ""
        elif char == "|":
            if current:
                paths.append(prefixes[-1] + current)
            current = ""
        elif char == "]":
            if current:
                paths.append(prefixes[-1] + current)
            prefixes.pop()
            if not prefixes:
                prefixes = [""]
            current = ""
        else:
            current += char
    if current:
        paths.append(prefixes[-1] + current)
    return paths


def _fsm_state_paths(fsm: FSM) -> dict[str, str]:
    """Every state's path (``Parent/child``), and the last segment of each path that is not
    ambiguous, mapped to the path."""
    paths: dict[str, str] = {}
    by_name: dict[str, list[str]] = {}
    stack: list[tuple[FSM, str]] = [(fsm, "")]
    while stack:
        machine, prefix = stack.pop()
        for state in machine.states.values():
            path = prefix + state.name
            paths[path] = path
            by_name.setdefault(state.name, []).append(path)
            for region in state.regions:
                stack.append((region, f"{path}/"))
    for name, found in by_name.items():
        if len(found) == 1 and name not in paths:
            paths[name] = found[0]
    return paths


def _fsm_anchors(fsm: FSM, state: str) -> list[str]:
    if fsm.start_name is not None and state == fsm.start_name and state not in fsm.states:
        return [START_ANCHOR]
    known = _fsm_state_paths(fsm)
    found: list[str] = []
    for path in _configuration_paths(state):
        resolved = known.get(path)
        if resolved is None:
            continue
        found.append(state_anchor(resolved))
        parts = resolved.split("/")
        found.extend(state_anchor("/".join(parts[:end])) for end in range(len(parts) - 1, 0, -1))
    return list(dict.fromkeys(found))


# -- BT -------------------------------------------------------------------------------------


def _bt_walk(doc: BTDocument) -> list[tuple[BTNode, str, str, str]]:
    """Every node reachable from the main root through SubTrees, once per place it is
    executed: (node, path from the main root, its tree's id, path inside that tree)."""
    main = doc.main
    if main.root is None:
        return []
    out: list[tuple[BTNode, str, str, str]] = []
    stack: list[tuple[BTNode, str, str, str, tuple[str, ...]]] = [
        (main.root, "", main.id, "", (main.id,))
    ]
    while stack:
        node, path, tree, local, chain = stack.pop()
        out.append((node, path, tree, local))
        ref = node.subtree_id
        if ref is not None and ref in doc.trees and ref not in chain:
            sub = doc.trees[ref].root
            if sub is not None:
                stack.append((sub, child_path(path, 0), ref, "", (*chain, ref)))
        for index in range(len(node.children) - 1, -1, -1):
            stack.append(
                (
                    node.children[index],
                    child_path(path, index),
                    tree,
                    child_path(local, index),
                    chain,
                )
            )
    return out


def _bt_anchors(doc: BTDocument, state: str, expanded: bool) -> list[str]:
    places = _bt_walk(doc)
    if not places:
        return []

    def anchor(place: tuple[BTNode, str, str, str]) -> str:
        _, path, tree, local = place
        return node_anchor(path) if expanded else node_anchor(local, tree)

    if state in ROOT_RESULTS:
        return [anchor(places[0])]
    label, at, path = state.rpartition("@")
    if at:  # leaf-execution: label@path
        wanted = "" if path == "root" else path
        hits = [p for p in places if p[1] == wanted and p[0].label == label]
        if hits:
            return [anchor(hits[0])]
    # macro-step on a loop-execution BT: the state variable's value names the FSM state; the
    # leaves that act for it carry it as a port (LebtState state=..., guards target=...).
    leaves = [p for p in places if p[0].kind in (NodeKind.ACTION, NodeKind.CONDITION)]
    hits = [p for p in leaves if p[0].attrs.get("state") == state]
    hits += [p for p in leaves if p[0].attrs.get("target") == state]
    if not hits:
        hits = [p for p in leaves if state in (p[0].label, p[0].name)]
    if hits:
        return list(dict.fromkeys(anchor(p) for p in hits))
    return [anchor(places[0])]  # the start: the tree has not entered any state yet
