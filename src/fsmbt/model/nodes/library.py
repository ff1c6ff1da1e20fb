"""Node libraries: what ``--nodes`` and ``--abstract`` make of a BT document's node types.

A library is built from profile names (``nav2``, ``moveit_pro``) and user files (YAML or JSON,
``--nodes FILE``); ``--abstract time,blackboard`` adds the abstraction families. Applying it to
a document (``apply_library``, called by the BehaviorTree.CPP reader) sets each node's
``BTNode.semantics`` - the registered kind that gives it its meaning - and renames aliases:

- a registered kind that ``requires`` an enabled profile or family gets ``semantics = kind``
  (without it the interpreter refuses the node and names the option);
- a user entry ``alias: <built-in>`` renames the type to that kind (a warning says so);
- a user entry ``semantics: <registered kind>`` keeps the user's type name (it is written back
  unchanged) and gives it that kind's rules, exact or abstraction;
- a user entry ``kind: action|condition`` declares a leaf's kind;
- a type that matches a built-in up to letter case (Nav2's ``<inverter>``) is read as that
  built-in, always, with a warning: never silently.

A user file::

    profiles: [nav2]               # optional: profiles to enable as well
    nodes:
      MyRetry: {alias: RetryUntilSuccessful}
      MyPipeline: {semantics: PipelineSequence}
      ThrottledReplan: {semantics: RateController}   # an abstraction: named in the verdict
      IsBatteryLow: {kind: condition}

Costs: building a library is O(entries); applying it is O(N) for N nodes (explicit walk).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from fsmbt.model.errors import InputError, SourceLocation
from fsmbt.model.files import read_bounded
from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes.registry import ABSTRACTIONS, PROFILES, all_nodes, node_semantics
from fsmbt.model.yaml_guarded import load_guarded_yaml

if TYPE_CHECKING:  # only an annotation: model.bt reads the registry, not the reverse
    from fsmbt.model.bt import BTDocument

_LEAF_KINDS = {"action": NodeKind.ACTION, "condition": NodeKind.CONDITION}
#: Warn(message, location) - the reader's warning sink.
Warn = Callable[[str, SourceLocation | None], None]


@dataclass
class NodeLibrary:
    """The enabled options and the user's declarations.

    Attributes:
        enabled: profile names and abstraction families that are on.
        aliases: custom type -> the registered kind it is renamed to.
        semantics: custom type -> the registered kind whose rules it follows.
        leaf_kinds: custom leaf type -> its kind.
        sources: where each user entry came from (for messages).
    """

    enabled: set[str] = field(default_factory=set)
    aliases: dict[str, str] = field(default_factory=dict)
    semantics: dict[str, str] = field(default_factory=dict)
    leaf_kinds: dict[str, NodeKind] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)


def _split(values: object) -> list[str]:
    if values is None:
        return []
    items = [values] if isinstance(values, (str, Path)) else list(values)  # type: ignore[call-overload]
    out: list[str] = []
    for item in items:
        out += [part.strip() for part in str(item).split(",") if part.strip()]
    return out


def build_library(nodes: object = None, abstract: object = None) -> NodeLibrary:
    """The library of ``--nodes`` values (profile names or files) and ``--abstract`` families.

    Args:
        nodes: profile names (``nav2``, ``moveit_pro``) and/or paths of YAML/JSON node files;
            a string may hold several, comma-separated.
        abstract: abstraction families (``time``, ``blackboard``).

    Returns:
        The ``NodeLibrary``.

    Raises:
        InputError: an unknown profile or family, an unreadable or malformed node file, an
            entry naming an unknown kind (each located in its file).
    """
    library = NodeLibrary()
    for family in _split(abstract):
        if family not in ABSTRACTIONS:
            raise InputError(
                f"unknown abstraction '{family}' (known: {', '.join(ABSTRACTIONS)})",
                element="--abstract",
            )
        library.enabled.add(family)
    pending = _split(nodes)
    seen: set[str] = set()
    while pending:
        item = pending.pop(0)
        if item in seen:
            continue
        seen.add(item)
        if item in PROFILES:
            library.enabled.add(item)
            continue
        path = Path(item)
        if not path.suffix and not path.exists():
            raise InputError(
                f"unknown node profile '{item}' (profiles: {', '.join(PROFILES)}; "
                "or give a YAML/JSON node file)",
                element="--nodes",
            )
        pending += _read_file(path, library)
    return library


def _read_file(path: Path, library: NodeLibrary) -> list[str]:
    """Read one node file into ``library``; returns the profiles it asks for."""
    where = SourceLocation(str(path))
    try:
        text = read_bounded(path).decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read node file: {exc}", location=where) from None
    try:
        if path.suffix.lower() == ".json":
            data = json.loads(text)
        else:  # aliases refused, depth bounded (model.yaml_guarded; docs/security.md)
            data = load_guarded_yaml(
                text, lambda line, column: SourceLocation(str(path), line, column)
            )
    except InputError as exc:
        raise InputError(f"malformed node file: {exc.message}", location=exc.location) from None
    except Exception as exc:  # noqa: BLE001 - any parse error is the user's file: report it
        raise InputError(
            f"malformed node file: {str(exc).splitlines()[0]}", location=where
        ) from None
    if not isinstance(data, dict):
        raise InputError(
            "a node file is a mapping with 'nodes' (and optional 'profiles')", location=where
        )
    unknown = set(data) - {"nodes", "profiles"}
    if unknown:
        raise InputError(
            f"unknown key(s) {', '.join(sorted(map(str, unknown)))} (expected 'nodes', 'profiles')",
            location=where,
        )
    entries = data.get("nodes") or {}
    if not isinstance(entries, dict):
        raise InputError("'nodes' must map node types to declarations", location=where)
    for type_name, entry in entries.items():
        element = f"nodes.{type_name}"
        if not isinstance(entry, dict) or len(entry) != 1:
            raise InputError(
                "a declaration is one of {alias: KIND}, {semantics: KIND}, "
                "{kind: action|condition}",
                location=where,
                element=element,
            )
        ((key, value),) = entry.items()
        value = str(value)
        if key in ("alias", "semantics"):
            target = node_semantics(value)
            if target is None:
                known = ", ".join(sorted(n.name for n in all_nodes()))
                raise InputError(
                    f"unknown node kind '{value}' (known: {known})", location=where, element=element
                )
            (library.aliases if key == "alias" else library.semantics)[str(type_name)] = target.name
        elif key == "kind":
            if value.lower() not in _LEAF_KINDS:
                raise InputError(
                    f"kind must be action or condition, not '{value}' (a control "
                    "or decorator needs 'alias' or 'semantics')",
                    location=where,
                    element=element,
                )
            library.leaf_kinds[str(type_name)] = _LEAF_KINDS[value.lower()]
        else:
            raise InputError(
                f"unknown declaration '{key}' (alias, semantics or kind)",
                location=where,
                element=element,
            )
        library.sources[str(type_name)] = str(path)
    profiles = data.get("profiles") or []
    return _split(profiles)


def _case_matches() -> dict[str, str]:
    table: dict[str, list[str]] = {}
    for node in all_nodes():
        table.setdefault(node.name.lower(), []).append(node.name)
    return {low: names[0] for low, names in table.items() if len(names) == 1}


def apply_library(doc: BTDocument, library: NodeLibrary, warn: Warn) -> None:
    """Resolve every node of ``doc`` against ``library`` (see the module docstring).

    Args:
        doc: the document, changed in place.
        library: from ``build_library``.
        warn: told each rename (alias, letter-case typo), with the node's location.
    """
    by_case = _case_matches()
    for _tree, node in doc.nodes():
        original = node.type
        if original in library.aliases:
            target = library.aliases[original]
            warn(
                f"node type '{original}' read as {target} (alias declared in "
                f"{library.sources[original]})",
                node.location,
            )
            node.type = target
        elif (
            node_semantics(original) is None
            and original.lower() in by_case
            and original not in library.semantics
            and original not in doc.node_models
        ):
            target = by_case[original.lower()]
            warn(
                f"node type '{original}' is not a BehaviorTree.CPP type; read as {target} "
                "(same name up to letter case)",
                node.location,
            )
            node.type = target
        spec = node_semantics(node.type)
        if node.type != original and spec is not None:
            node.kind = spec.kind
            node.kind_declared = True
        if original in library.semantics:
            target = library.semantics[original]
            spec = node_semantics(target)
            assert spec is not None
            node.semantics = target
            if spec.kind in (NodeKind.CONTROL, NodeKind.DECORATOR) or not node.is_leaf:
                node.kind = spec.kind
            node.kind_declared = True
        elif node.type in library.leaf_kinds and not node.children:
            node.kind = library.leaf_kinds[node.type]
            node.kind_declared = True
        elif spec is not None and spec.requires is not None and spec.requires in library.enabled:
            node.semantics = spec.name
