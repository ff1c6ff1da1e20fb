"""The C++ skeleton of an event-driven machine's tree: fsmbt's runtime, your actions, a main.

A tree ``fsmbt convert`` writes for an event-driven machine - the dispatch form (the default,
docs/semantics.md section 12) or an LEBT (``--style lebt``, section 5) - has no leaf class of
the user's own to write: its one leaf type (``DispatchEntry``, or ``LebtGuard``/``LebtState``) is
fsmbt's, defined by the C++ runtime ``fsmbt/lebt.hpp``, whose ``LebtRunner`` tells the two forms
apart. What the user writes is the code behind each state's *action*. So for such a tree
``fsmbt runtime cpp DIR MODEL`` writes (docs/runtime.md, "An event-driven machine"):

- ``generated/include/fsmbt/lebt.hpp``: the runtime header (rewritten: it follows fsmbt);
- ``generated/actions_base.hpp``: ``generated::ActionsBase``, one virtual method per action
  name of the tree's leaves (``on_<action>``, called with the entered state's label and its
  parameters; the default prints the entry) and ``registerActions(registry)``;
- ``tree.xml``: the tree (rewritten);
- ``actions.hpp`` (yours, written once): ``class Actions : generated::ActionsBase``, where the
  overrides go;
- ``main.cpp``, ``CMakeLists.txt`` (yours, written once): load ``tree.xml`` with the actions,
  ``start()``, one ``post(event)`` per event given (or read from stdin), print each state.

``generated/skeleton.json`` records the actions; a rerun reports an action added (printed by the
base class until overridden) or gone (its override in ``actions.hpp`` no longer compiles: delete
it). Method names are the action names made C++ identifiers (``on_`` + letters, digits and
``_``; a clash gets ``_2``, ``_3`` ...).

Cost: O(nodes) to collect the actions and events, O(actions) to render.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.runtime.skeleton.files import SkeletonFile
from fsmbt.runtime.skeleton.render import one_line, render
from fsmbt.semantics.dispatch_runtime import ENTRY, DispatchMachine
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE, decode_pairs

NAMESPACE = "fsmbt_actions"
#: The runtime header inside the skeleton folder.
HEADER_PATH = "generated/include/fsmbt/lebt.hpp"
_NOT_IDENTIFIER = re.compile(r"[^0-9A-Za-z_]")


@dataclass
class Action:
    """One action name of the tree's state leaves, its C++ method and the states running it."""

    name: str
    method: str
    states: list[str] = field(default_factory=list)


def machine_form(doc: BTDocument) -> str | None:
    """``"dispatch"`` or ``"lebt"`` for a tree whose every leaf is one of fsmbt's runtime leaves
    (or a built-in), else ``None``: a tree of the user's own leaves, or a mix, which the leaf
    skeleton refuses (``leaves.leaf_kinds``)."""
    types: set[str] = set()
    for _tree, node in doc.nodes():
        if node.is_leaf and not node.is_builtin:
            types.add(node.type)
    if types == {ENTRY}:
        return "dispatch"
    if types and types <= {GUARD_TYPE, STATE_TYPE}:
        return "lebt"
    return None


def actions_of(doc: BTDocument) -> list[Action]:
    """The distinct non-empty ``action`` ports of the state leaves, first use first, each with
    the labels (``state`` ports) of the states running it."""
    found: dict[str, Action] = {}
    methods: set[str] = set()
    for _tree, node in doc.nodes():
        if node.type not in (ENTRY, STATE_TYPE):
            continue
        name = node.attrs.get("action", "")
        if not name:
            continue
        action = found.get(name)
        if action is None:
            base = "on_" + _NOT_IDENTIFIER.sub("_", name)
            method, k = base, 1
            while method in methods:
                k += 1
                method = f"{base}_{k}"
            methods.add(method)
            action = found[name] = Action(name, method)
        state = node.attrs.get("state", "") or node.label
        if state not in action.states:
            action.states.append(state)
    return list(found.values())


def events_of(doc: BTDocument, form: str) -> list[str]:
    """The events the tree reacts to, sorted (for the main's comment)."""
    if form == "dispatch":
        return DispatchMachine(doc, ()).events()
    events: set[str] = set()
    for _tree, node in doc.nodes():
        if node.type == GUARD_TYPE:
            try:
                events.update(e for _s, e in decode_pairs(node.attrs.get("pairs", "")) if e)
            except ValueError as exc:
                raise InputError(
                    f"port 'pairs': {exc}",
                    location=node.location,
                    element=f"<{GUARD_TYPE}> '{node.label}'",
                ) from None
    return sorted(events)


def manifest(form: str, actions: list[Action]) -> dict[str, object]:
    """The JSON record of the actions (what the next run compares with); no leaf types."""
    return {
        "language": "cpp",
        "form": form,
        "leaves": {},
        "actions": {a.name: {"method": a.method, "states": a.states} for a in actions},
    }


def action_changes(old: dict[str, object], actions: list[Action]) -> list[str]:
    """One line per action added or gone since the manifest ``old`` was written."""
    before = old.get("actions")
    if not isinstance(before, dict):
        return []
    lines: list[str] = []
    for action in actions:
        if action.name not in before:
            lines.append(
                f"action {action.name}: new; generated::ActionsBase::{action.method} prints "
                "its entries until actions.hpp overrides it"
            )
    now = {a.name for a in actions}
    for name, entry in before.items():
        if name not in now:
            method = entry.get("method", "") if isinstance(entry, dict) else ""
            lines.append(
                f"action {name}: no longer in the tree; actions.hpp is yours and was kept: "
                f"delete its override of {method} (it no longer compiles)"
            )
    return lines


def machine_files(
    doc: BTDocument,
    form: str,
    tree_text: str,
    header_text: str,
    *,
    source: str,
    project: str,
) -> tuple[list[SkeletonFile], list[Action]]:
    """Every file of the skeleton (see the module doc) and the actions rendered."""
    actions = actions_of(doc)
    common: dict[str, object] = {
        "source": source,
        "namespace": NAMESPACE,
        "project": project,
        "form": "dispatch" if form == "dispatch" else "LEBT",
        "actions": actions,
        "events": events_of(doc, form),
    }
    marker = (
        f"// GENERATED by `fsmbt runtime cpp` from {one_line(source)}: fsmbt's C++ runtime, "
        "rewritten by "
        "every run.\n"
    )
    files = [
        SkeletonFile("tree.xml", tree_text, user=False),
        SkeletonFile(HEADER_PATH, marker + header_text, user=False),
        SkeletonFile(
            "generated/actions_base.hpp", render("cpp_actions_base.hpp.j2", **common), False
        ),
        SkeletonFile("actions.hpp", render("cpp_actions.hpp.j2", **common), True),
        SkeletonFile("main.cpp", render("cpp_machine_main.cpp.j2", **common), True),
        SkeletonFile("CMakeLists.txt", render("cpp_machine_CMakeLists.txt.j2", **common), True),
    ]
    return files, actions
