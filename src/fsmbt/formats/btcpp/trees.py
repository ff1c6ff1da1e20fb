"""Where the trees a BehaviorTree.CPP file's SubTrees name come from, when not from the file.

BehaviorTree.CPP resolves a ``<SubTree ID="X">`` against every tree registered in the factory:
the file's own trees, its ``<include>`` files, and any other file the program registered with
``registerBehaviorTreeFromFile`` (BT.CPP tutorial 7; MoveIt Pro registers its whole objectives
folder). fsmbt has no program, so the reader finds those files itself (docs/formats/btcpp.md,
"Trees in other files"):

1. the reader option ``trees`` (CLI ``--trees PATH``, repeatable): files, or folders whose
   ``.xml`` files are all candidates, like ``registerBehaviorTreeFromFile``. A tree ID defined by
   two of them is refused, naming both. An unreadable file named there is an error.
2. without ``trees``: the other ``.xml`` files of the *referencing* file's own folder (never a
   subfolder, never outside it; symlinks must stay inside). A file there that cannot be read
   (too big, not XML, not a ``<root>``) is skipped and named if the ID is then found nowhere; an
   ID defined by two files is refused naming both; a use is reported as a warning naming the
   file.

Every file opened obeys the limits of any input (``max_input_bytes`` each, and the hostile-XML
rules of ``fsmbt.formats.xml_safe``) plus ``max_tree_files``: at most that many ``.xml`` files per
folder or ``trees`` option are opened. Cost: each candidate file is read and parsed once per read
(O(total bytes)); the index is a dict from tree ID to files.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from fsmbt import limits
from fsmbt.formats.registry import decode
from fsmbt.formats.xml_safe import parse_xml
from fsmbt.model.errors import InputError, SourceLocation
from fsmbt.model.files import note_read, read_bounded, read_located

#: The option a caller names extra tree files with (``--trees``).
TREES_OPTION = "trees"
#: The CLI spelling, for messages.
TREES_FLAG = "--trees"


@dataclass
class TreeIndex:
    """The tree IDs defined by a set of candidate files.

    Attributes:
        defined: tree ID -> the files (resolved paths) whose ``<BehaviorTree>`` has that ID.
        skipped: files that could not be read, each as ``"name (why)"``.
        files: every candidate file opened, in order.
    """

    defined: dict[str, list[Path]] = field(default_factory=dict)
    skipped: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)

    def add(self, path: Path, ids: Iterable[str]) -> None:
        self.files.append(path)
        for tree_id in ids:
            found = self.defined.setdefault(tree_id, [])
            if path not in found:
                found.append(path)


def tree_ids(root: etree._Element) -> list[str]:
    """The IDs of the ``<BehaviorTree>`` elements under a ``<root>`` (an unnamed single tree is
    ``MainTree``, as the reader names it)."""
    trees = [c for c in root if isinstance(c.tag, str) and c.tag == "BehaviorTree"]
    ids = [t.get("ID") or "" for t in trees]
    if len(ids) == 1 and not ids[0]:
        return ["MainTree"]
    return [i for i in ids if i]


def read_root(path: Path, what: str | None = None) -> etree._Element:
    """A BehaviorTree.CPP file's ``<root>``, read under every input limit.

    Args:
        path: the file.
        what: what the file is to the user (``--trees file``): the file system's refusal is
            then the ``InputError`` "cannot read WHAT: REASON"; ``None``: it is the ``OSError``.

    Raises:
        InputError: unreadable, too big, not XML, or its root is not ``<root>`` (located).
        OSError: the file system refused to open it (``what`` is ``None``).
    """
    data = read_bounded(path) if what is None else read_located(path, what)
    root = parse_xml(decode(data, str(path)), str(path))
    if root.tag != "root":
        raise InputError(
            f"not a BehaviorTree.CPP file: root element is <{str(root.tag)}>, expected <root>",
            location=SourceLocation(str(path), root.sourceline),
        )
    return root


def _xml_files(folder: Path, what: str) -> list[Path]:
    """The regular ``.xml`` files directly in ``folder`` (sorted), resolved, inside it.

    Raises:
        InputError: more than ``max_tree_files`` of them.
    """
    cap = limits.current().max_tree_files
    top = folder.resolve()
    note_read(folder)  # a file added to the folder later may define a tree that is missing now
    found: list[Path] = []
    for entry in sorted(folder.iterdir()):
        if entry.suffix.lower() != ".xml":
            continue
        resolved = entry.resolve()
        if not resolved.is_relative_to(top) or not resolved.is_file():
            continue  # a symlink out of the folder, a FIFO, a device, a folder named x.xml
        found.append(resolved)
        if len(found) > cap:
            raise InputError(
                limits.exceeded(f"{what} with more than {cap} .xml files", "max_tree_files", cap),
                location=SourceLocation(str(folder)),
            )
    return found


def option_paths(option: object, name: str = TREES_OPTION) -> list[Path]:
    """A reader option that names files (``trees``, ``node_models``) as paths: a path, or a
    list of paths.

    Raises:
        InputError: the option is neither (the message names the option ``name``).
    """
    if isinstance(option, (str, Path)):
        return [Path(option)]
    if isinstance(option, Iterable):
        return [Path(str(item)) for item in option]
    raise InputError(f"the {name} option must be a path or a list of paths")


def index_option(option: object) -> TreeIndex:
    """Index the files and folders the caller named with ``trees``.

    Raises:
        InputError: a named path is missing or unreadable, a named file is not a
            BehaviorTree.CPP file, or the files exceed ``max_tree_files``.
    """
    index = TreeIndex()
    cap = limits.current().max_tree_files
    for given in option_paths(option):
        if given.is_dir():
            paths = _xml_files(given, f"the {TREES_FLAG} folder {given}")
        elif given.exists():
            paths = [given.resolve()]
        else:
            note_read(given)
            raise InputError(
                f"{TREES_FLAG}: no such file or folder", location=SourceLocation(str(given))
            )
        for path in paths:
            if path in index.files:
                continue
            if len(index.files) >= cap:
                raise InputError(
                    limits.exceeded(
                        f"the {TREES_FLAG} files (more than {cap})", "max_tree_files", cap
                    ),
                    location=SourceLocation(str(given)),
                )
            index.add(path, tree_ids(read_root(path, f"{TREES_FLAG} file")))
    return index


def index_folder(folder: Path) -> TreeIndex:
    """Index the ``.xml`` files of one folder; unreadable ones are recorded in ``skipped``.

    Raises:
        InputError: the folder holds more than ``max_tree_files`` ``.xml`` files.
    """
    index = TreeIndex()
    try:
        paths = _xml_files(folder, f"the folder {folder}")
    except OSError as exc:
        index.skipped.append(f"{folder} ({exc.strerror})")
        return index
    for path in paths:
        try:
            root = read_root(path)
        except InputError as exc:
            index.skipped.append(f"{path.name} ({str(exc).split(': ', 1)[-1]})")
            continue
        except OSError as exc:
            index.skipped.append(f"{path.name} ({exc.strerror})")
            continue
        index.add(path, tree_ids(root))
    return index
