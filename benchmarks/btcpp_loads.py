"""Does BehaviorTree.CPP 4.8.2 itself load a tree file? (behaviortreepy, the real engine)

Used by ``corpus_coverage.py`` to count the corpus files the real engine refuses, so coverage
can also be given over the files BehaviorTree.CPP accepts. The question asked is "is the file
well-formed for BehaviorTree.CPP", not "are its custom nodes built": every node type the engine
does not know ("Node not recognized: X") is registered as a dummy of its *declared* kind - a
``<TreeNodesModel>`` entry (the file's, any file of its source folder, the ``--node-models``
files), the explicit Groot tag, fsmbt's node registry (v3 names, Nav2 / MoveIt Pro kinds), else
the element's shape (no child: action, one: decorator, more: control) - and the load is retried.
A dummy declares the ports the file uses: the dummy's attributes are dropped from the copy the
engine reads (behaviortreepy registers port-less simple nodes). behaviortreepy cannot register a
control node, so a dummy control is loaded as a ``Sequence`` (the same loader rule: one or more
children). Everything else - child counts of built-ins and dummies, ports of built-ins, SubTree
IDs, ``main_tree_to_execute``, the trees the SubTrees name - is the engine's own check.

The files are copied (rewritten) into a temporary mirror of the source folder, so
``<include path>`` resolves as BehaviorTree.CPP resolves it; the trees fsmbt takes from other
files (``--trees`` / the folder lookup, ``BTDocument.includes``) are registered as
``registerBehaviorTreeFromText`` would, then ``createTree(main tree)`` is called.

Cost: one parse and write of the source folder per retry; a retry per unknown node type.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from lxml import etree

from fsmbt import api
from fsmbt.model.nodes import canonical_type, node_semantics

try:  # the engine; without it the classification is skipped (the caller says so)
    import behaviortreepy as btpy
except ImportError:  # pragma: no cover - behaviortreepy is a pinned dependency
    btpy = None

EXPLICIT = ("Action", "Condition", "Control", "Decorator")
_UNKNOWN = re.compile(r"(?:Node not recognized|Unknown node type): (.+?)\s*$")
_XML_NAME = re.compile(r"^[A-Za-z_][\w.-]*$")
_PARSER = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)


def available() -> bool:
    """Whether behaviortreepy (BehaviorTree.CPP 4.8.2) can be imported."""
    return btpy is not None


def _declared_kinds(roots: list[etree._Element], model_files: list[Path]) -> dict[str, str]:
    kinds: dict[str, str] = {}
    for extra in model_files:
        roots = [*roots, etree.parse(str(extra), _PARSER).getroot()]
    for root in roots:
        for models in root.iter("TreeNodesModel"):
            for entry in models:
                if isinstance(entry.tag, str) and entry.tag in EXPLICIT and entry.get("ID"):
                    kinds.setdefault(entry.get("ID", ""), entry.tag)
    return kinds


def _kind_of(name: str, element: etree._Element | None, declared: dict[str, str]) -> str:
    if name in declared:
        return declared[name]
    if element is not None and element.tag in EXPLICIT:
        return str(element.tag)
    spec = node_semantics(canonical_type(name))
    if spec is not None:
        return spec.kind.value
    children = len([c for c in element if isinstance(c.tag, str)]) if element is not None else 0
    return "Action" if children == 0 else "Decorator" if children == 1 else "Control"


def _type_of(element: etree._Element) -> str:
    return element.get("ID", "") if element.tag in EXPLICIT else str(element.tag)


def _rewrite(root: etree._Element, dummies: dict[str, str]) -> None:
    """Explicit Groot tags in compact style (the same tree for the loader, but 4.8.2's
    ReactiveSequence check looks a child up by its tag and misses ``Action``); the dummies'
    attributes (their ports) dropped; a dummy control written as a Sequence."""
    for tree in root.iter("BehaviorTree"):
        for element in tree.iter():
            if not isinstance(element.tag, str):
                continue
            if element.tag in EXPLICIT and _XML_NAME.match(element.get("ID", "")):
                element.tag = element.attrib.pop("ID")
            name = _type_of(element)
            if name not in dummies:
                continue
            keep = {k: v for k, v in element.attrib.items() if k == "name"}
            if element.tag in EXPLICIT:  # an ID that is no valid tag: stays explicit
                keep["ID"] = "Sequence" if dummies[name] == "Control" else name
            elif dummies[name] == "Control":
                element.tag = "Sequence"
            element.attrib.clear()
            element.attrib.update(keep)


def _first_use(roots: list[etree._Element], name: str) -> etree._Element | None:
    for root in roots:
        for tree in root.iter("BehaviorTree"):
            for element in tree.iter():
                if isinstance(element.tag, str) and _type_of(element) == name:
                    return element
    return None


def _include_closure(path: Path, parsed: dict[Path, etree._ElementTree]) -> set[Path]:
    """The files ``path`` includes, transitively (BehaviorTree.CPP loads them itself)."""
    found: set[Path] = {path.resolve()}
    stack = [path]
    by_path = {p.resolve(): t for p, t in parsed.items()}
    while stack:
        current = stack.pop()
        tree = by_path.get(current.resolve())
        if tree is None:
            continue
        for include in tree.getroot().iter("include"):
            target = (current.parent / include.get("path", "")).resolve()
            if target not in found:
                found.add(target)
                stack.append(target)
    return found


@contextmanager
def _quiet_stdout() -> Iterator[None]:
    """BehaviorTree.CPP prints its loader warnings with std::cout: keep them off our tables."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def _never_ticked(*_args: object) -> object:
    raise AssertionError("a dummy node is never ticked: the tree is only loaded")


def refusal(path: Path, source_root: Path, options: dict[str, object]) -> str | None:
    """BehaviorTree.CPP 4.8.2's error when it refuses to load ``path``, else ``None``.

    Args:
        path: the tree file.
        source_root: the folder mirrored (the corpus source folder holding ``path``).
        options: the fsmbt reader options of the setting (``node_models`` decides kinds;
            ``trees``/``include_root`` decide which other files fsmbt takes).

    Returns:
        The engine's message (first line), or ``None`` when ``createTree`` succeeds.
    """
    assert btpy is not None
    # resolved, so included files (resolved by fsmbt) compare with it: ``a/../b`` is ``b``
    path, source_root = path.resolve(), source_root.resolve()
    parsed: dict[Path, etree._ElementTree] = {}
    for p in sorted(source_root.rglob("*.xml")):
        try:
            parsed[p] = etree.parse(str(p), _PARSER)
        except (etree.XMLSyntaxError, OSError):
            if p == path:
                raise
            continue  # a malformed neighbour: BT.CPP would not open it either
    roots = [t.getroot() for t in parsed.values()]
    raw_models = options.get("node_models") or []
    model_files = [Path(str(m)) for m in raw_models] if isinstance(raw_models, list) else []
    declared = _declared_kinds(roots, model_files)
    main_tree = None
    extra: list[Path] = []
    try:
        doc = api.load(path, options=options).model
        main_tree = getattr(doc, "main_tree", None) or next(iter(getattr(doc, "trees", {})), None)
        extra = [Path(p).resolve() for p in getattr(doc, "includes", [])]
    except Exception:  # noqa: BLE001 - fsmbt refusing is not BT.CPP refusing: ask the engine
        pass
    main_root = parsed[path].getroot()
    tree_ids = {t.get("ID") for r in roots for t in r.iter("BehaviorTree") if t.get("ID")}
    included = _include_closure(path, parsed)
    extra = [p for p in extra if p not in included]
    if main_tree is None:
        main_tree = main_root.get("main_tree_to_execute")
        if main_tree is None:
            ids = [t.get("ID") or "MainTree" for t in main_root.iter("BehaviorTree")]
            main_tree = ids[0] if ids else "MainTree"
    dummies: dict[str, str] = {}
    with tempfile.TemporaryDirectory(prefix="fsmbt-btcpp-load-") as tmp:
        mirror = Path(tmp)
        cwd = os.getcwd()
        try:
            for _attempt in range(500):
                for p, tree in parsed.items():
                    copy = etree.fromstring(etree.tostring(tree.getroot()), _PARSER)
                    _rewrite(copy, dummies)
                    target = mirror / p.relative_to(source_root)
                    target.parent.mkdir(parents=True, exist_ok=True)
                    # no XML declaration: the engine's line numbers stay the file's
                    target.write_text(etree.tostring(copy, encoding="unicode"), encoding="utf-8")
                main_copy = mirror / path.relative_to(source_root)
                os.chdir(main_copy.parent)  # the factory's parser resolves includes from here
                factory = btpy.BehaviorTreeFactory()
                for name, kind in dummies.items():
                    if kind == "Action":
                        factory.register_simple_action(name, _never_ticked)
                    elif kind == "Condition":
                        factory.register_simple_condition(name, _never_ticked)
                    elif kind == "Decorator":
                        factory.register_simple_decorator(name, _never_ticked)
                try:
                    with _quiet_stdout():
                        factory.register_behavior_tree_from_text(
                            main_copy.read_text(encoding="utf-8")
                        )
                        for other in extra:
                            if other.is_relative_to(source_root) and other != path.resolve():
                                copy_path = mirror / other.relative_to(source_root)
                                factory.register_behavior_tree_from_text(
                                    copy_path.read_text(encoding="utf-8")
                                )
                        factory.create_tree(main_tree)
                    return None
                except Exception as exc:  # noqa: BLE001 - the engine's refusal is the answer
                    message = str(exc).strip().splitlines()[0] if str(exc).strip() else repr(exc)
                    unknown = _UNKNOWN.search(message)
                    name = unknown.group(1) if unknown is not None else ""
                    if name in tree_ids:  # a dummy would clash with the tree's ID
                        return message + " (a tree's ID used as a node tag: v4 needs <SubTree>)"
                    if not name or name in dummies or name in EXPLICIT:
                        controls = sorted(n for n, k in dummies.items() if k == "Control")
                        if controls and "'Sequence'" in message:
                            message += f" (dummy controls are loaded as Sequence: {controls})"
                        return message
                    dummies[name] = _kind_of(name, _first_use(roots, name), declared)
            return "too many unknown node types"
        finally:
            os.chdir(cwd)
