"""Profiles found by themselves: what a BehaviorTree.CPP file's own nodes and folder say.

Why: a new user types ``fsmbt convert nav2_tree.xml -o out.scxml`` and should get the result a
Nav2 user gets with ``--nodes nav2 --node-models nav2_tree_nodes.xml``: fsmbt applies what it
finds, without being asked, and says so in one line per find (a warning of the read, so every
verdict and ``validate`` show it); ``--no-profiles`` (``ReadOptions.no_profiles``) refuses them
all. The rules (docs/semantics.md §10, "Profiles found by themselves"):

- **project profiles**: the file uses a node of a known project - a registered kind whose
  ``library`` is Nav2 or MoveIt Pro (``RateController``, ``PipelineSequence``, ``ForEach``) or one
  of Nav2's own leaves (``fsmbt.model.nodes.nav2_leaves``) - and is not declared by the file's
  own ``<TreeNodesModel>``: that profile (``nav2``, ``moveit_pro``) is enabled as if given with
  ``--nodes``. Its abstractions stay abstractions, named in every verdict and in the line;
- **Nav2's leaves**: with the Nav2 profile on (found or given), the Nav2 leaves the file uses are
  declared with their kind (Action / Condition) and ports, after the file's own models and the
  ``--node-models`` files;
- **node-model files beside the file**: ``*tree_nodes*.xml`` files holding a
  ``<TreeNodesModel>``, in the file's folder and its ``models/`` subfolder, then in each parent
  folder up to and including the package's root (the first folder holding ``package.xml``, at
  most ``SEARCH_LEVELS`` levels up): their declarations of the types the file uses and declares
  nowhere else are applied (the nearest file first);
- **bundled node libraries** (``node_libraries/*.yaml`` of the source tree): a library applies
  when the file uses one of the custom controls or decorators it declares (``alias`` /
  ``semantics`` entries: ``RealParallel``, ``LoopPose``), which nothing else declares.

A found declaration that does not fit - the file's node uses a port the declaration does not
list, or has children where a leaf is declared - is a warning naming both files (a leaf with
children is then not declared by it). Nothing found is ever executed; only names are read.

Costs: O(n) over the file's elements, plus one directory listing per searched folder
(``2 * (SEARCH_LEVELS + 1)`` at most) and the parse of each candidate model file.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from lxml import etree

from fsmbt.model.bt import NodeModel, PortModel
from fsmbt.model.bt_nodes import builtin_spec, canonical_type
from fsmbt.model.errors import InputError
from fsmbt.model.files import read_bounded
from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes.library import build_library
from fsmbt.model.nodes.nav2_leaves import nav2_leaf
from fsmbt.model.nodes.registry import all_nodes

#: How many parent folders are searched for node-model files (stopping at a package root).
SEARCH_LEVELS = 3
#: The source tree's bundled node libraries (present in a checkout and an editable install).
BUNDLED_LIBRARIES = Path(__file__).resolve().parents[4] / "node_libraries"
#: Registered kinds' ``library`` -> the profile that enables them.
PROJECT_PROFILES = {"Nav2": "nav2", "MoveIt Pro": "moveit_pro"}
PROFILE_TITLES = {"nav2": "Nav2", "moveit_pro": "MoveIt Pro"}
#: Node attributes that are not ports (BehaviorTree.CPP's own).
_NOT_PORTS = ("name", "ID")
_EXPLICIT = ("Action", "Condition", "Control", "Decorator")


@dataclass
class Usage:
    """One node type as the file uses it: where first, its attributes, whether with children."""

    where: str
    ports: dict[str, None] = field(default_factory=dict)
    with_children: bool = False


@dataclass
class Found:
    """What was found: profiles and library files to add to ``--nodes``, declarations to add
    to the external models (type -> (model, the file or profile it came from)), the one-line
    notes and the fit warnings."""

    profiles: list[str] = field(default_factory=list)
    libraries: list[str] = field(default_factory=list)
    library_hits: dict[str, list[str]] = field(default_factory=dict)
    models: dict[str, tuple[NodeModel, str]] = field(default_factory=dict)
    model_files: dict[str, list[str]] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def used_types(files: Iterable[tuple[str, etree._Element]]) -> dict[str, Usage]:
    """Every non-built-in node type used in the ``<BehaviorTree>`` s of ``(name, root)``
    files (lxml iterates: no recursion)."""
    used: dict[str, Usage] = {}
    for name, root in files:
        for tree in root:
            if tree.tag != "BehaviorTree":
                continue
            for element in tree.iterdescendants():
                if not isinstance(element.tag, str):
                    continue
                tag = element.tag
                type_id = element.get("ID") if tag in _EXPLICIT else tag
                if not type_id:
                    continue
                type_name = canonical_type(type_id)
                spec = builtin_spec(type_name)
                project_kind = spec is not None and spec.library in PROJECT_PROFILES
                if (spec is not None and not project_kind) or type_name == "SubTree":
                    continue  # BehaviorTree.CPP's own kinds say nothing about a project
                usage = used.setdefault(type_name, Usage(f"{name}:{element.sourceline}"))
                for key in element.attrib:
                    if key not in _NOT_PORTS and not key.startswith("_"):
                        usage.ports.setdefault(str(key), None)
                if any(isinstance(c.tag, str) for c in element):
                    usage.with_children = True
    return used


def _project_of(type_name: str) -> str | None:
    if nav2_leaf(type_name) is not None:
        return "nav2"
    for node in all_nodes():
        if node.name == type_name and node.library in PROJECT_PROFILES:
            return PROJECT_PROFILES[node.library]
    return None


def _search_folders(path: Path) -> list[Path]:
    folders: list[Path] = []
    folder = path.resolve().parent
    for _level in range(SEARCH_LEVELS + 1):
        folders += [folder, folder / "models"]
        if (folder / "package.xml").is_file() or folder.parent == folder:
            break
        folder = folder.parent
    return [f for f in folders if f.is_dir()]


def _model_files(path: Path) -> list[Path]:
    found: list[Path] = []
    for folder in _search_folders(path):
        found += sorted(
            p for p in folder.glob("*tree_nodes*.xml") if p.is_file() and p.resolve() != path
        )
    return found


def _read_models(path: Path) -> dict[str, NodeModel]:
    """The leaf/control/decorator declarations of a model file (``{}`` if it is not one).

    The file is read as any input is (``read_bounded``: a regular file within
    ``max_input_bytes``; the hardened XML parser); one these refuse (too big, an entity
    declaration, too deep, not UTF-8) is passed over, as an unreadable one is: a found file
    never stops the read of the file the user gave."""
    from fsmbt.formats.xml_safe import parse_xml  # the hardened parser of every reader

    try:
        root = parse_xml(read_bounded(path).decode("utf-8"), str(path))
    except (OSError, UnicodeDecodeError, ValueError, InputError):
        return {}
    models: dict[str, NodeModel] = {}
    for container in root.iter("TreeNodesModel"):
        for entry in container:
            if not isinstance(entry.tag, str) or entry.tag not in _EXPLICIT:
                continue
            type_id = entry.get("ID")
            if not type_id:
                continue
            ports = [
                PortModel(str(p.get("name")))
                for p in entry
                if isinstance(p.tag, str) and p.get("name")
            ]
            kind = NodeKind(entry.tag)
            models.setdefault(canonical_type(type_id), NodeModel(type_id, kind, ports))
    return models


def _fits(type_name: str, usage: Usage, model: NodeModel, source: str, found: Found) -> bool:
    """Warn when the file's node does not fit the found declaration; False: do not apply it."""
    if model.kind in (NodeKind.ACTION, NodeKind.CONDITION) and usage.with_children:
        found.warnings.append(
            f"{usage.where}: '{type_name}' has children, but {source} declares it a "
            f"{model.kind.value} (a profile guess that does not fit: not applied)"
        )
        return False
    declared = {p.name for p in model.ports}
    extra = [p for p in usage.ports if p not in declared]
    if extra:
        found.warnings.append(
            f"{usage.where}: '{type_name}' uses port(s) {', '.join(extra)} that {source} does "
            "not declare (a profile guess that does not fit: another release of its project?)"
        )
    return True


@lru_cache(maxsize=1)
def _bundled_custom_types() -> tuple[tuple[str, frozenset[str]], ...]:
    """(library file, its custom control/decorator types) of each bundled library, read once
    per process (fsmbt's own files; one the input limits refuse is passed over)."""
    out: list[tuple[str, frozenset[str]]] = []
    if not BUNDLED_LIBRARIES.is_dir():
        return ()
    for path in sorted(BUNDLED_LIBRARIES.glob("*.yaml")):
        try:
            library = build_library([str(path)])
        except InputError:
            continue
        out.append((str(path), frozenset(library.aliases) | frozenset(library.semantics)))
    return tuple(out)


def _given_library_types(given_nodes: tuple[str, ...]) -> set[str]:
    """The control/decorator types the user's ``--nodes`` libraries alias or give semantics to
    (none when they cannot be read: the reader reports that itself, located)."""
    if not given_nodes:
        return set()
    try:
        library = build_library(list(given_nodes))
    except InputError:
        return set()
    return set(library.aliases) | set(library.semantics)


def _bundled_libraries(used: dict[str, Usage], known: set[str]) -> list[tuple[str, list[str]]]:
    out: list[tuple[str, list[str]]] = []
    for path, custom in _bundled_custom_types():
        hits = sorted(t for t in custom if t in used and t not in known)
        if hits:
            out.append((path, hits))
    return out


def discover(
    path: Path | None,
    files: Iterable[tuple[str, etree._Element]],
    declared: set[str],
    given_nodes: list[str],
    given_models: set[str],
) -> Found:
    """What fsmbt applies by itself to the file at ``path`` (see the module docstring).

    Args:
        path: the file read (``None``: text; then nothing is searched beside it).
        files: ``(name, root)`` of the file and the files it includes.
        declared: the types the files' own ``<TreeNodesModel>`` declare.
        given_nodes: the ``--nodes`` values the user gave (their profiles are not "found").
        given_models: the types the ``--node-models`` files declare.
    """
    found = Found()
    used = used_types(files)
    known = declared | given_models
    registered = {n.name for n in all_nodes()}
    # project profiles, by the project nodes used
    by_profile: dict[str, list[str]] = {}
    for type_name in used:
        profile = _project_of(type_name)
        is_leaf = nav2_leaf(type_name) is not None
        if profile is not None and not (is_leaf and type_name in declared):
            by_profile.setdefault(profile, []).append(type_name)
    found.profiles = [p for p in by_profile if p not in given_nodes]
    # node-model files beside the file or in its package, nearest first
    if path is not None:
        for model_path in _model_files(path):
            shown = str(model_path)
            applied: list[str] = []
            for type_name, model in _read_models(model_path).items():
                usage = used.get(type_name)
                if usage is None or type_name in known or type_name in found.models:
                    continue
                if type_name in registered and nav2_leaf(type_name) is None:
                    continue  # a registered control/decorator: its kind's rules are fsmbt's
                if _fits(type_name, usage, model, shown, found):
                    found.models[type_name] = (model, shown)
                    applied.append(type_name)
            if applied:
                found.model_files[shown] = applied
    # Nav2's own leaves, with the Nav2 profile on (found or given)
    if "nav2" in found.profiles or "nav2" in given_nodes:
        for type_name, usage in used.items():
            leaf = nav2_leaf(type_name)
            if leaf is None or type_name in known or type_name in found.models:
                continue
            kind, ports = leaf
            model = NodeModel(type_name, kind, [PortModel(p) for p in ports])
            if _fits(
                type_name, usage, model, "the Nav2 profile (Nav2's nav2_tree_nodes.xml)", found
            ):
                found.models[type_name] = (model, "the Nav2 profile")
    # a bundled library is found only for types the user's own --nodes libraries leave open:
    # what the user said about a type wins over what a bundled file guesses
    for library_path, hits in _bundled_libraries(used, _given_library_types(tuple(given_nodes))):
        if library_path not in given_nodes:
            found.libraries.append(library_path)
            found.library_hits[library_path] = hits
    return found


def notes(found: Found, abstractions: dict[str, list[str]], display: str) -> list[str]:
    """The one-line notes of what was applied: ``abstractions`` maps a profile name or library
    file to the node types read as environment inputs through it."""
    refuse = " — --no-profiles to refuse"
    lines: list[str] = []
    for profile in found.profiles:
        title = PROFILE_TITLES.get(profile, profile)
        gated = abstractions.get(profile, [])
        leaves = sorted(t for t, (_m, src) in found.models.items() if src == "the Nav2 profile")
        parts = []
        if gated:
            parts.append(f"{', '.join(gated)} as environment inputs")
        if profile == "nav2" and leaves:
            parts.append(
                f"{len(leaves)} Nav2 leaves declared ({', '.join(leaves[:4])}"
                + (", ..." if len(leaves) > 4 else "")
                + ")"
            )
        detail = "; ".join(parts) or "its exact node kinds"
        lines.append(f"{display}: read with the {title} profile: {detail}{refuse}")
    for model_file, types in found.model_files.items():
        lines.append(
            f"{display}: read with the node models of {model_file} (found beside it): "
            f"{', '.join(sorted(types)[:6])}" + (", ..." if len(types) > 6 else "") + refuse
        )
    for library in found.libraries:
        gated = abstractions.get(library, [])
        detail = f": {', '.join(gated)} as environment inputs" if gated else ""
        lines.append(
            f"{display}: read with the node library {library} (its "
            f"{', '.join(found.library_hits.get(library, []))} used here){detail}{refuse}"
        )
    return lines
