"""BehaviorTree.CPP XML: read v4 and v3 files, write v4 (docs/formats/btcpp.md).

Reading maps everything to BehaviorTree.CPP v4 meaning (docs/semantics.md, 'Names'): v3 names through
``V3_ALIASES``, both the compact style (``<Sequence>``, ``<MyAction/>``) and Groot's explicit style
(``<Action ID="MyAction"/>``). ``<include path=...>`` files are merged into one document; the
writer writes that document inline, so a written file is self-contained and never includes.

How a node's kind is decided (first rule that applies): a BehaviorTree.CPP built-in; a
``<TreeNodesModel>`` declaration (the file's, its includes', or the extra model files of
``ReadContext.options["node_models"]``); the explicit-style tag; otherwise it is *assumed*
(``kind_declared=False``): a childless element is an Action, one with one child a Decorator, one
with more a Control. Validation reports undeclared non-leaf types as unknown node types.
Then the node library of ``options["nodes"]`` / ``options["abstract"]`` is applied
(``fsmbt.model.nodes.library``: project kinds, aliases, letter-case typos, abstractions).

Everything is iterative: trees 10 000 levels deep read and write without recursion.
Complexity: O(n) in the number of elements.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from fsmbt import limits
from fsmbt.formats.btcpp import profiles as btcpp_profiles
from fsmbt.formats.btcpp import trees as btcpp_trees
from fsmbt.formats.btcpp import v3_ticks as btcpp_v3_ticks
from fsmbt.formats.btcpp import versions as btcpp_versions
from fsmbt.formats.registry import Format, ReadContext, decode, register
from fsmbt.formats.xml_safe import parse_xml, root_tag
from fsmbt.model import Model
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode, NodeModel, PortModel
from fsmbt.model.bt_nodes import NodeKind, builtin_spec, canonical_type
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.model.files import note_read, read_located
from fsmbt.model.nodes.library import apply_library, build_library
from fsmbt.model.nodes.registry import node_semantics

#: Tags of Groot's explicit style and of ``<TreeNodesModel>`` entries, with the kind they declare.
EXPLICIT_TAGS: dict[str, NodeKind] = {
    "Action": NodeKind.ACTION,
    "Condition": NodeKind.CONDITION,
    "Control": NodeKind.CONTROL,
    "Decorator": NodeKind.DECORATOR,
    "SubTree": NodeKind.SUBTREE,
}
PORT_TAGS = {
    "input_port": "input",
    "output_port": "output",
    "inout_port": "inout",
    "bidirectional_port": "inout",
}
PORT_ELEMENT = {"input": "input_port", "output": "output_port", "inout": "inout_port"}
#: Written on ``<TreeNodesModel>`` entries fsmbt had to assume (kind not declared anywhere); the
#: reader does not take such an entry as a declaration, so the assumption survives a round trip.
ASSUMED_MARK = "_fsmbt_assumed"
#: How the writer marks such an entry: a ``<description>`` (the one child BehaviorTree.CPP's XSD
#: allows besides ports; an attribute would break it). ``ASSUMED_MARK="true"`` is read too.
ASSUMED_DESCRIPTION = "fsmbt: kind assumed, declared nowhere (it may be a Condition)"
#: ``NodeModel.attrs`` key holding a model entry's non-port children (Groot2 metadata) as XML.
EXTRA_XML_KEY = "_fsmbt_extra_xml"
#: Deeper trees are written without indentation (indentation alone would be O(depth²) bytes).
PRETTY_MAX_DEPTH = 200
_XML_NAME = re.compile(r"^[A-Za-z_][\w.-]*$")


# -- reading -------------------------------------------------------------------------------------
@dataclass
class _File:
    path: str
    root: etree._Element
    version: str
    source: Path | None = None  # the file read (resolved), None for text
    extra: bool = False  # read to resolve a SubTree (btcpp.trees), not given or included


@dataclass
class _Loader:
    ctx: ReadContext
    files: list[_File] = field(default_factory=list)
    loaded: set[Path] = field(default_factory=set)
    declared: dict[str, NodeModel] = field(default_factory=dict)  # the document's own models
    external: dict[str, NodeModel] = field(default_factory=dict)  # options["node_models"]

    # files and includes ------------------------------------------------------------------------
    def load(
        self, text: str, path: Path | None, chain: tuple[Path, ...], *, extra: bool = False
    ) -> None:
        name = str(path) if path is not None else self.ctx.display_name
        root = parse_xml(text, name, self.ctx.warnings)
        if root.tag != "root":
            raise InputError(
                f"not a BehaviorTree.CPP file: root element is <{str(root.tag)}>, expected <root>",
                location=SourceLocation(name, root.sourceline),
            )
        version = root.get("BTCPP_format", "3")
        if version not in ("3", "4"):
            raise UnsupportedError(
                f'BTCPP_format="{version}" (fsmbt reads 3 and 4)',
                location=SourceLocation(name, root.sourceline),
                element="root",
            )
        source = path.resolve() if path is not None else None
        self.files.append(_File(name, root, version, source, extra))
        for child in _elements(root):
            if child.tag == "include":
                self.include(child, path, name, chain, extra=extra)

    def include(
        self,
        element: etree._Element,
        path: Path | None,
        name: str,
        chain: tuple[Path, ...],
        *,
        extra: bool = False,
    ) -> None:
        where = SourceLocation(name, element.sourceline)
        if element.get("ros_pkg") is not None:
            raise UnsupportedError(
                "<include ros_pkg=...> needs a ROS installation to resolve",
                location=where,
                element="include",
            )
        target = element.get("path")
        if not target:
            raise InputError(
                "<include> without a path attribute", location=where, element="include"
            )
        if path is None:
            raise InputError(
                "<include> needs the including file's path to resolve "
                f"'{target}' (read the file, not text)",
                location=where,
                element="include",
            )
        resolved = (path.parent / target).resolve()
        # includes are confined to the folder of the file the user gave, or to the folder the
        # caller names with the option include_root (docs/security.md): "../x.xml" from a
        # subfolder is fine, "/etc/passwd" or a symlink out of the folder is not
        root_option = self.ctx.options.get("include_root")
        top_folder = (
            Path(str(root_option)).resolve()
            if root_option
            else (chain[0] if chain else path.resolve()).parent
        )
        if not resolved.is_relative_to(top_folder):
            raise InputError(
                f"include '{target}' resolves to {resolved}, outside the folder of "
                f"the file read ({top_folder}); refused (allow a wider folder "
                "with --include-root DIR, reader option include_root)",
                location=where,
                element="include",
            )
        if resolved in chain:
            cycle = " -> ".join(str(p) for p in (*chain, resolved))
            raise InputError(f"include cycle: {cycle}", location=where, element="include")
        max_include_depth = limits.current().max_include_depth
        if len(chain) >= max_include_depth:
            raise InputError(
                limits.exceeded(
                    f"an include chain of {len(chain) + 1} files",
                    "max_include_depth",
                    max_include_depth,
                ),
                location=where,
                element="include",
            )
        if resolved in self.loaded:
            return  # included twice (diamond): BehaviorTree.CPP registers it once
        self.loaded.add(resolved)
        note_read(resolved)  # a dependency even when it is missing
        if not resolved.is_file():  # a FIFO or a device could block or never end
            raise InputError(
                f"included '{target}' is not a regular file", location=where, element="include"
            )
        text = read_located(
            resolved, f"included file '{target}' ({resolved})", location=where, element="include"
        )
        self.load(decode(text, str(resolved)), resolved, (*chain, resolved), extra=extra)

    # trees in other files (fsmbt.formats.btcpp.trees) -----------------------------------------
    def resolve_subtrees(self) -> None:
        """Load the files that define the trees the SubTrees name and no loaded file defines:
        from the ``trees`` option, else from the referencing file's own folder."""
        option = self.ctx.options.get(btcpp_trees.TREES_OPTION)
        named = btcpp_trees.index_option(option) if option else None
        folders: dict[Path, btcpp_trees.TreeIndex] = {}
        defined: set[str] = set()
        pending: list[tuple[str, _File, etree._Element]] = []
        scanned = 0
        while True:
            for f in self.files[scanned:]:
                defined.update(btcpp_trees.tree_ids(f.root))
                pending.extend((tree_id, f, el) for tree_id, el in _subtree_refs(f.root))
            scanned = len(self.files)
            pending = [p for p in pending if p[0] not in defined]
            if not pending:
                return
            tree_id, f, element = pending[0]
            where = SourceLocation(f.path, element.sourceline)
            if named is not None:
                index, looked = named, f"the {btcpp_trees.TREES_FLAG} files"
            elif f.source is not None:
                folder = f.source.parent
                if folder not in folders:
                    folders[folder] = btcpp_trees.index_folder(folder)
                index, looked = folders[folder], f"the other .xml files of its folder {folder}"
            else:
                index, looked = btcpp_trees.TreeIndex(), "any other file (the input is a text)"
            found = index.defined.get(tree_id, [])
            if not found:
                # left dangling: validation and the interpreter refuse it, naming --trees
                skipped = (
                    f" ({len(index.skipped)} unreadable, skipped: {', '.join(index.skipped[:3])})"
                    if index.skipped
                    else ""
                )
                self.ctx.warnings.append(
                    f"{where}: SubTree '{tree_id}': no tree with that ID in the file, its "
                    f"includes or {looked}{skipped}; name the file (or folder) that defines it "
                    f"with {btcpp_trees.TREES_FLAG} PATH (reader option trees)"
                )
                defined.add(tree_id)
                continue
            if len(found) > 1:
                raise InputError(
                    f"SubTree refers to tree '{tree_id}', defined in {found[0]} and in "
                    f"{found[1]}; refused (name the one meant with {btcpp_trees.TREES_FLAG})",
                    location=where,
                    element="SubTree",
                )
            target = found[0]
            if named is None:
                self.ctx.warnings.append(
                    f"{where}: SubTree '{tree_id}' is taken from {target}, another file of the "
                    f"folder (name it with {btcpp_trees.TREES_FLAG} to make this explicit)"
                )
            if target in self.loaded:  # loaded, yet without that ID: a stale index
                raise InputError(
                    f"SubTree refers to tree '{tree_id}', which {target} no longer defines",
                    location=where,
                    element="SubTree",
                )
            self.loaded.add(target)
            data = read_located(
                target, f"{target} (it defines tree '{tree_id}')", location=where, element="SubTree"
            )
            self.load(decode(data, str(target)), target, (target,), extra=True)

    def prune_extra_trees(self, doc: BTDocument) -> None:
        """Keep, of the trees read from other files, only those the file's own trees reach."""
        extra = {f.path for f in self.files if f.extra}
        if not extra:
            return
        reached = [
            t.id for t in doc.trees.values() if t.location is None or t.location.file not in extra
        ]
        seen = set(reached)
        while reached:
            root = doc.trees[reached.pop()].root
            for node in root.walk() if root is not None else ():
                target = node.subtree_id
                if target is not None and target in doc.trees and target not in seen:
                    seen.add(target)
                    reached.append(target)
        for tree_id in [t for t in doc.trees if t not in seen]:
            del doc.trees[tree_id]

    def load_external_models(self) -> None:
        option = self.ctx.options.get("node_models") or []
        for model_path in btcpp_trees.option_paths(option, "node_models"):
            data = read_located(model_path, "node model file")
            root = parse_xml(decode(data, str(model_path)), str(model_path))
            for models in root.iter("TreeNodesModel"):
                for model in _read_models(models, str(model_path)):
                    self.external.setdefault(model.type, model)

    # the document ---------------------------------------------------------------------------------
    def document(self) -> BTDocument:
        main = self.files[0]
        doc = BTDocument(format_version=main.version)
        doc.attrs = {
            k: v
            for k, v in main.root.attrib.items()
            if k not in ("BTCPP_format", "main_tree_to_execute")
        }
        doc.includes = [f.path for f in self.files[1:]]  # includes and other tree files
        for f in self.files:
            for child in _elements(f.root):
                if child.tag == "TreeNodesModel":
                    for model in _read_models(child, f.path):
                        if model.attrs.get(ASSUMED_MARK) != "true":
                            self.declared.setdefault(model.type, model)
                elif child.tag not in ("BehaviorTree", "include"):
                    raise UnsupportedError(
                        f"unknown element <{str(child.tag)}> under <root>",
                        location=SourceLocation(f.path, child.sourceline),
                        element=str(child.tag),
                    )
        doc.node_models = dict(self.declared)
        ports_seen: dict[str, dict[str, None]] = {}
        implied: dict[str, NodeKind] = {}
        for f in self.files:
            for child in _elements(f.root):
                if child.tag == "BehaviorTree":
                    tree = self.tree(child, f, ports_seen, implied)
                    if tree.id in doc.trees and f.extra:
                        # a file read for another of its trees: the reader's own tree wins
                        self.ctx.warnings.append(
                            f"{tree.location}: tree '{tree.id}' of {f.path} is not taken: "
                            f"{doc.trees[tree.id].location} defines it already"
                        )
                        continue
                    if tree.id in doc.trees:
                        raise InputError(
                            f"duplicate BehaviorTree ID '{tree.id}'",
                            location=tree.location,
                            element="BehaviorTree",
                        )
                    doc.trees[tree.id] = tree
        # Complete the declarations for every used type whose kind is known (so the writer's
        # <TreeNodesModel> lets Groot2 know it and a re-read gives the same document).
        for type_name, kind in implied.items():
            if type_name in doc.node_models:
                continue
            if type_name in self.external:
                doc.node_models[type_name] = self.external[type_name]
            else:
                ports = [PortModel(p) for p in ports_seen.get(type_name, {})]
                doc.node_models[type_name] = NodeModel(type_name, kind, ports)
        doc.main_tree = self.main_tree_id(doc, main)
        return doc

    def main_tree_id(self, doc: BTDocument, main: _File) -> str | None:
        named = main.root.get("main_tree_to_execute")
        if named is not None:
            return named
        own = [c.get("ID") for c in _elements(main.root) if c.tag == "BehaviorTree"]
        if len(own) > 1:
            self.ctx.warn(
                f"no main_tree_to_execute and {len(own)} trees; the first, "
                f"'{own[0]}', is taken as the main tree",
                line=main.root.sourceline,
            )
        if own:
            return own[0]
        return next(iter(doc.trees), None)

    def tree(
        self,
        element: etree._Element,
        f: _File,
        ports_seen: dict[str, dict[str, None]],
        implied: dict[str, NodeKind],
    ) -> BehaviorTree:
        where = SourceLocation(f.path, element.sourceline)
        tree_id = element.get("ID")
        if not tree_id:
            if len([c for c in _elements(f.root) if c.tag == "BehaviorTree"]) > 1:
                raise InputError(
                    "<BehaviorTree> without ID in a file with several trees",
                    location=where,
                    element="BehaviorTree",
                )
            tree_id = "MainTree"
        attrs = {k: v for k, v in element.attrib.items() if k != "ID"}
        roots = _elements(element)
        if len(roots) > 1:
            raise InputError(
                f"BehaviorTree '{tree_id}' has {len(roots)} root nodes; "
                "BehaviorTree.CPP allows exactly one",
                location=where,
                element="BehaviorTree",
            )
        root = self.nodes(roots[0], f, ports_seen, implied) if roots else None
        return BehaviorTree(tree_id, root, attrs, where)

    def nodes(
        self,
        top: etree._Element,
        f: _File,
        ports_seen: dict[str, dict[str, None]],
        implied: dict[str, NodeKind],
    ) -> BTNode:
        """Build the node tree with an explicit stack (pre-order, children kept in order)."""
        result: BTNode | None = None
        stack: list[tuple[etree._Element, BTNode | None]] = [(top, None)]
        while stack:
            element, parent = stack.pop()
            children = _elements(element)
            node = self.node(element, len(children), f, ports_seen, implied)
            if parent is None:
                result = node
            else:
                parent.children.append(node)
            stack.extend((child, node) for child in reversed(children))
        assert result is not None
        return result

    def node(
        self,
        element: etree._Element,
        n_children: int,
        f: _File,
        ports_seen: dict[str, dict[str, None]],
        implied: dict[str, NodeKind],
    ) -> BTNode:
        where = SourceLocation(f.path, element.sourceline)
        tag = str(element.tag)
        attrs = dict(element.attrib)
        name = attrs.pop("name", None)
        explicit: NodeKind | None = None
        if tag in EXPLICIT_TAGS and tag != "SubTree":
            type_id = attrs.pop("ID", None)
            if not type_id:
                raise InputError(
                    f"<{tag}> without ID (explicit style names the node type in ID)",
                    location=where,
                    element=tag,
                )
            explicit = EXPLICIT_TAGS[tag]
            type_name = canonical_type(type_id)
        else:
            type_name = canonical_type(tag)
        if f.version == "3":  # v3 ports and SubTree remaps in v4 terms (btcpp.versions)
            attrs = btcpp_versions.v4_attrs(tag, type_name, attrs)
        if element.text and element.text.strip():
            self.ctx.warn("text inside a node is ignored", line=element.sourceline, element=tag)
        spec = builtin_spec(type_name)
        if spec is not None:
            if spec.kind is NodeKind.SUBTREE and not attrs.get("ID"):
                raise InputError("<SubTree> without ID", location=where, element=tag)
            if spec.kind is NodeKind.CONTROL and n_children == 0 and spec.allows_children(0):
                self.ctx.warnings.append(
                    f"{where}: {tag}: without children it follows its own rule "
                    f"({spec.source}), but BehaviorTree.CPP 4.8.2's loader refuses a control "
                    "node without children"
                )
            if not _factory_builtin(type_name) and spec.kind is not NodeKind.SUBTREE:
                # a project's kind (Nav2's PipelineSequence): declared in the document's models
                # with its ports, as every node BehaviorTree.CPP's factory does not hold
                seen = ports_seen.setdefault(type_name, dict.fromkeys(spec.ports))
                for key in attrs:
                    seen.setdefault(key, None)
                implied.setdefault(type_name, spec.kind)
            return BTNode(type_name, spec.kind, name, attrs, location=where)
        seen = ports_seen.setdefault(type_name, {})
        for key in attrs:
            seen.setdefault(key, None)
        model = self.declared.get(type_name) or self.external.get(type_name)
        kind: NodeKind
        if model is not None and model.kind is not NodeKind.SUBTREE:
            kind = model.kind
        elif explicit is not None:
            kind = explicit
        else:
            kind = (
                NodeKind.ACTION
                if n_children == 0
                else NodeKind.DECORATOR
                if n_children == 1
                else NodeKind.CONTROL
            )
            return BTNode(type_name, kind, name, attrs, kind_declared=False, location=where)
        implied.setdefault(type_name, kind)
        return BTNode(type_name, kind, name, attrs, location=where)


def _subtree_refs(root: etree._Element) -> list[tuple[str, etree._Element]]:
    """``(tree ID, element)`` of every SubTree reference inside the file's ``<BehaviorTree>`` s
    (not the ``<SubTree>`` declarations of a ``<TreeNodesModel>``); lxml iterates, no
    recursion."""
    refs = []
    for tree in _elements(root):
        if tree.tag != "BehaviorTree":
            continue
        for element in tree.iter():
            if isinstance(element.tag, str) and canonical_type(element.tag) == "SubTree":
                tree_id = element.get("ID")
                if tree_id:
                    refs.append((tree_id, element))
    return refs


def _elements(element: etree._Element) -> list[etree._Element]:
    return [c for c in element if isinstance(c.tag, str)]


def _read_models(element: etree._Element, source: str) -> list[NodeModel]:
    models = []
    for entry in _elements(element):
        where = SourceLocation(source, entry.sourceline)
        kind = EXPLICIT_TAGS.get(str(entry.tag))
        if kind is None:
            raise InputError(
                f"unknown <TreeNodesModel> entry <{str(entry.tag)}> (expected Action, "
                "Condition, Control, Decorator or SubTree)",
                location=where,
                element=str(entry.tag),
            )
        attrs = dict(entry.attrib)
        type_id = attrs.pop("ID", None)
        if not type_id:
            raise InputError(
                f"<{str(entry.tag)}> in <TreeNodesModel> without ID",
                location=where,
                element=str(entry.tag),
            )
        ports: list[PortModel] = []
        extra: list[str] = []
        for child in _elements(entry):
            direction = PORT_TAGS.get(str(child.tag))
            if child.tag == "description" and (child.text or "").strip() == ASSUMED_DESCRIPTION:
                attrs[ASSUMED_MARK] = "true"
                continue
            if direction is None:
                extra.append(etree.tostring(child, encoding="unicode", with_tail=False))
                continue
            port_name = child.get("name")
            if not port_name:
                raise InputError(
                    f"<{str(child.tag)}> without name",
                    element=str(child.tag),
                    location=SourceLocation(source, child.sourceline),
                )
            text = (child.text or "").strip() or child.get("description")
            ports.append(
                PortModel(port_name, direction, child.get("default"), text, child.get("type"))
            )
        if extra:
            attrs[EXTRA_XML_KEY] = "".join(extra)
        type_name = type_id if kind is NodeKind.SUBTREE else canonical_type(type_id)
        models.append(NodeModel(type_name, kind, ports, attrs))
    return models


def read_btcpp(text: str, ctx: ReadContext) -> BTDocument:
    """Read a BehaviorTree.CPP v3/v4 file (and the files it includes) into one document."""
    loader = _Loader(ctx)
    loader.load_external_models()
    path = ctx.path.resolve() if ctx.path is not None else None
    if path is not None:
        loader.loaded.add(path)
    loader.load(text, ctx.path, (path,) if path is not None else ())
    loader.resolve_subtrees()
    given_nodes = [str(n) for n in _as_list(ctx.options.get("nodes"))]
    found = None
    if not ctx.options.get("no_profiles"):
        found = _find_profiles(loader, ctx, given_nodes)
    doc = loader.document()
    loader.prune_extra_trees(doc)
    # --nodes / --abstract (fsmbt.model.nodes.library): project kinds, aliases, abstractions
    # the user's own libraries last: a later file's entry for a type wins (model/nodes/library.py)
    nodes = (found.profiles + found.libraries if found is not None else []) + given_nodes
    library = build_library(nodes, ctx.options.get("abstract"))

    def warn(message: str, location: SourceLocation | None) -> None:
        ctx.warnings.append(f"{location}: {message}" if location is not None else message)

    apply_library(doc, library, warn)
    _declare_library_kinds(doc)
    ticks_otherwise = btcpp_v3_ticks.granularity(doc)[0] if doc.format_version == "3" else []
    if ticks_otherwise:  # where 3.8 ticks otherwise than the v4 rule fsmbt reads: one line
        tree_id, node, why = ticks_otherwise[0]
        more = len(ticks_otherwise) - 1
        ctx.warnings.append(
            f"{btcpp_v3_ticks.where(tree_id, node)}: {why}; fsmbt reads this v3 file with v4's "
            "rule (docs/semantics.md section 1)" + (f" ({more} more such node(s))" if more else "")
        )
    if found is not None:
        abstractions: dict[str, list[str]] = {}
        for _tree, node in doc.nodes():
            spec = node_semantics(node.semantics) if node.semantics else None
            if spec is None or spec.abstraction is None:
                continue
            origin = library.sources.get(node.type) or spec.requires or ""
            names = abstractions.setdefault(origin, [])
            if node.type not in names:
                names.append(node.type)
        ctx.warnings.extend(btcpp_profiles.notes(found, abstractions, ctx.display_name))
    return doc


def _declare_library_kinds(doc: BTDocument) -> None:
    """Kinds a node library declared (``kind: action``, an alias's target kind) join the
    document's models with the ports the nodes use, as the writer declares them: a written
    file read again is the same document (docs/formats/btcpp.md)."""
    added: set[str] = set()
    for _tree, node in doc.nodes():
        if (
            not node.kind_declared
            or node.kind is NodeKind.SUBTREE
            or _factory_builtin(node.type)
            or (node.type in doc.node_models and node.type not in added)
        ):
            continue
        if node.type not in doc.node_models:
            doc.node_models[node.type] = NodeModel(node.type, node.kind, [])
            added.add(node.type)
        entry = doc.node_models[node.type]
        known = {p.name for p in entry.ports}
        entry.ports.extend(PortModel(k) for k in node.attrs if k not in known)


def _as_list(value: object) -> list[object]:
    if value is None:
        return []
    if isinstance(value, (str, Path)):
        return [part.strip() for part in str(value).split(",") if part.strip()]
    return list(value)  # type: ignore[call-overload]


def _find_profiles(
    loader: _Loader, ctx: ReadContext, given_nodes: list[str]
) -> btcpp_profiles.Found:
    """Profiles and node models found by themselves (``fsmbt.formats.btcpp.profiles``); the
    found declarations join the external models after the user's ``--node-models``."""
    declared: set[str] = set()
    for f in loader.files:
        for child in _elements(f.root):
            if child.tag == "TreeNodesModel":
                declared |= {m.type for m in _read_models(child, f.path)}
    found = btcpp_profiles.discover(
        ctx.path,
        [(f.path, f.root) for f in loader.files],
        declared,
        given_nodes,
        set(loader.external),
    )
    ctx.warnings.extend(found.warnings)
    for type_name, (model, _source) in found.models.items():
        loader.external.setdefault(type_name, model)
    return found


# -- writing -------------------------------------------------------------------------------------
def write_btcpp(model: Model) -> str:
    """Write a BehaviorTree.CPP v4 file: compact style, main tree named, custom types declared."""
    return serialize(*document_root(model))


def serialize(root: etree._Element, depth: int) -> str:
    """The text of a written ``<root>``: indented unless a tree is deeper than
    ``PRETTY_MAX_DEPTH``; ends with a newline."""
    text = etree.tostring(root, encoding="unicode", pretty_print=depth <= PRETTY_MAX_DEPTH)
    return text if text.endswith("\n") else text + "\n"


def document_root(model: Model) -> tuple[etree._Element, int]:
    """The v4 ``<root>`` element of a document and the depth of its deepest tree (the
    ``btcpp3`` writer edits this element into v3; ``fsmbt.formats.btcpp.v3_write``)."""
    if not isinstance(model, BTDocument):
        raise InputError("BehaviorTree.CPP XML holds a behavior tree, not a state machine")
    doc = model
    root = etree.Element("root")
    root.set("BTCPP_format", "4")
    if doc.trees:
        root.set("main_tree_to_execute", doc.main.id)
    for key, value in doc.attrs.items():
        root.set(key, value)
    depth = 0
    for tree in doc.trees.values():
        element = etree.SubElement(root, "BehaviorTree", ID=tree.id)
        for key, value in tree.attrs.items():
            element.set(key, value)
        if tree.root is not None:
            depth = max(depth, _write_nodes(element, tree.root))
    _write_models(root, doc)
    return root, depth


def _write_nodes(parent: etree._Element, top: BTNode) -> int:
    """Append ``top``'s subtree under ``parent`` (explicit stack); returns the depth."""
    deepest = 0
    stack: list[tuple[BTNode, etree._Element, int]] = [(top, parent, 1)]
    while stack:
        node, into, depth = stack.pop()
        deepest = max(deepest, depth)
        element = _node_element(into, node)
        stack.extend((child, element, depth + 1) for child in reversed(node.children))
    return deepest


def _node_element(parent: etree._Element, node: BTNode) -> etree._Element:
    if node.kind is NodeKind.SUBTREE:
        element = etree.SubElement(parent, "SubTree")
    elif _XML_NAME.match(node.type) and node.type not in EXPLICIT_TAGS:
        element = etree.SubElement(parent, node.type)
    else:  # not a valid tag name: Groot's explicit style says the same thing
        element = etree.SubElement(parent, node.kind.value, ID=node.type)
    if node.name is not None:
        element.set("name", node.name)
    for key, value in node.attrs.items():
        element.set(key, value)
    return element


def _write_models(root: etree._Element, doc: BTDocument) -> None:
    """``<TreeNodesModel>``: the document's declarations, then every other custom type used."""
    models: dict[str, NodeModel] = dict(doc.node_models)
    assumed: dict[str, NodeModel] = {}
    added: set[str] = set()
    for _tree, node in doc.nodes():
        if _factory_builtin(node.type) or node.kind is NodeKind.SUBTREE:
            continue
        if node.type in doc.node_models or (node.kind_declared and node.type in assumed):
            continue
        target = models if node.kind_declared else assumed
        if node.type not in target:
            spec = builtin_spec(node.type)
            ports = [PortModel(p) for p in spec.ports] if spec is not None else []
            target[node.type] = NodeModel(node.type, node.kind, ports)
            added.add(node.type)
        elif node.type not in added:
            continue
        entry = target[node.type]
        known = {p.name for p in entry.ports}
        entry.ports.extend(PortModel(k) for k in node.attrs if k not in known)
    if not models and not assumed:
        return
    container = etree.SubElement(root, "TreeNodesModel")
    for model in models.values():
        _model_element(container, model)
    for model in assumed.values():
        if model.type not in models:
            etree.SubElement(
                _model_element(container, model), "description"
            ).text = ASSUMED_DESCRIPTION


#: Registered BehaviorTree.CPP kinds a 4.8.2 ``BehaviorTreeFactory`` does not hold: v3's
#: blackboard checks (removed in v4) and ManualSelector (registered only with ncurses).
_NOT_IN_FACTORY = frozenset(
    {"BlackboardCheckDouble", "BlackboardCheckInt", "BlackboardCheckString", "ManualSelector"}
)


def _factory_builtin(type_name: str) -> bool:
    """A node BehaviorTree.CPP 4.8.2's factory knows without a declaration; every other node
    (a project's ``PipelineSequence``, a user's leaf) is declared in ``<TreeNodesModel>`` with
    its ports, so BehaviorTree.CPP's XSD and Groot2 know it (docs/formats/btcpp.md)."""
    spec = builtin_spec(type_name)
    return (
        spec is not None and spec.library == "BehaviorTree.CPP" and spec.name not in _NOT_IN_FACTORY
    )


def _model_element(parent: etree._Element, model: NodeModel) -> etree._Element:
    element = etree.SubElement(parent, model.kind.value, ID=model.type)
    for key, value in model.attrs.items():
        if key != EXTRA_XML_KEY:
            element.set(key, value)
    for port in model.ports:
        port_element = etree.SubElement(
            element, PORT_ELEMENT.get(port.direction, "input_port"), name=port.name
        )
        if port.type is not None:
            port_element.set("type", port.type)
        if port.default is not None:
            port_element.set("default", port.default)
        if port.description is not None:
            port_element.text = port.description
    extra = model.attrs.get(EXTRA_XML_KEY)
    if extra:
        for child in parse_xml(f"<x>{extra}</x>", "<node model metadata>"):
            element.append(child)
    return element


def _sniff(text: str) -> bool:
    return root_tag(text) == "root"


register(
    Format(
        "btcpp",
        (".xml",),
        frozenset({"bt"}),
        "BehaviorTree.CPP XML (read v3/v4, write v4; Groot2 compatible)",
        read_btcpp,
        write_btcpp,
        _sniff,
        priority=30,
    )
)
