"""BehaviorTree.CPP's ``FileLogger2`` log (``.btlog``), read exactly as 4.8.2 writes it
(src/loggers/bt_file_logger_v2.cpp; docs/conform.md, 'The .btlog format'):

=========  ==========================================================================
bytes      content
=========  ==========================================================================
18         ``BTCPP4-FileLogger2``
1          protocol, ``1``
4          N, the XML's length (int32, little-endian: ``flatbuffers::WriteScalar``)
N          the tree as ``WriteTreeToXML(tree, add_metadata=true, builtin_models=true)``:
           every node has ``_uid``; each SubTree instance is its own ``<BehaviorTree>``
           whose ``_fullpath`` the ``<SubTree>`` element names
8          the first time stamp, microseconds since the epoch (int64 LE)
9 each     a transition: 6 bytes microseconds since the first time stamp, 2 bytes node
           UID, 1 byte the new ``NodeStatus`` (0 IDLE, 1 RUNNING, 2 SUCCESS, 3 FAILURE,
           4 SKIPPED), all little-endian (``memcpy`` of the fields on x86/ARM)
=========  ==========================================================================

Refused, each with one located line (exit 2): another magic or protocol, an XML length past
the file's end, XML that does not parse or holds no tree, a record cut short (the byte offset
is named), a status outside 0..4, a transition of a UID the embedded tree does not have, a time
stamp earlier than the one before (records are written in the order they happen: 4.8.2's
``FileLogger2::flush()``, which writes the file from the caller's thread while the writer
thread writes it too, can duplicate a block of records - do not call it while ticking).
Costs: O(file size); the transitions are decoded with ``memoryview`` slices into three flat
lists (no object per record).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fsmbt.conform.log import LoggedNode, RecordedLog
from fsmbt.formats.xml_safe import local_name, parse_xml
from fsmbt.model.errors import InputError, SourceLocation
from fsmbt.model.files import read_located
from fsmbt.model.nodes import SUBTREE_TYPE

MAGIC = b"BTCPP4-FileLogger2"
PROTOCOL = 1
RECORD = 9


def _bad(path: str, message: str) -> InputError:
    return InputError(message, location=SourceLocation(path))


def read_btlog(path: str | Path) -> RecordedLog:
    """Read a ``.btlog`` file (see the module docstring).

    Raises:
        InputError: the file is not a FileLogger2 log, is truncated, or is inconsistent.
    """
    name = str(path)
    data = read_located(Path(path), "the log")
    head = len(MAGIC)
    if data[:head] != MAGIC:
        raise _bad(
            name,
            "not a BehaviorTree.CPP FileLogger2 log (.btlog): the file does not "
            "start with 'BTCPP4-FileLogger2'",
        )
    if len(data) < head + 5:
        raise _bad(name, "truncated .btlog: the header ends before the tree's length")
    if data[head] != PROTOCOL:
        raise _bad(name, f"unsupported .btlog protocol {data[head]} (this reader knows {PROTOCOL})")
    size = int.from_bytes(data[head + 1 : head + 5], "little", signed=True)
    xml_start = head + 5
    xml_end = xml_start + size
    if size <= 0 or xml_end + 8 > len(data):
        raise _bad(
            name,
            f"truncated .btlog: the embedded tree ({size} bytes) runs past the end "
            f"of the file ({len(data)} bytes)",
        )
    try:
        xml = bytes(data[xml_start:xml_end]).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise _bad(
            name, f"the embedded tree is not UTF-8 text (byte {xml_start + exc.start})"
        ) from None
    nodes, root = embedded_nodes(xml, name)
    start = int.from_bytes(data[xml_end : xml_end + 8], "little", signed=True)
    body = memoryview(data)[xml_end + 8 :]
    whole = len(body) - len(body) % RECORD
    if whole != len(body):
        raise _bad(
            name,
            f"truncated .btlog: {len(body) % RECORD} stray byte(s) after the last "
            f"whole transition (offset {xml_end + 8 + whole})",
        )
    log = RecordedLog(name, "btlog", nodes, root, start)
    times, uids, statuses = log.times, log.uids, log.statuses
    previous = 0
    for offset in range(0, whole, RECORD):
        record = body[offset : offset + RECORD]
        status = record[8]
        uid = record[6] | (record[7] << 8)
        if status > 4:
            raise _bad(
                name,
                f"transition at byte {xml_end + 8 + offset}: status {status} is not "
                "a BehaviorTree.CPP NodeStatus (0..4)",
            )
        if uid not in nodes:
            raise _bad(
                name,
                f"transition at byte {xml_end + 8 + offset}: node UID {uid} is not in "
                "the tree the log embeds (a log of another tree, or a corrupt file)",
            )
        stamp = int.from_bytes(record[:6], "little")
        if stamp < previous:
            raise _bad(
                name,
                f"transition #{offset // RECORD + 1} (byte {xml_end + 8 + offset}): "
                "its time stamp is earlier than the one before (a corrupt log; "
                "BehaviorTree.CPP 4.8.2's FileLogger2::flush() called while the tree runs "
                "can duplicate records)",
            )
        previous = stamp
        times.append(stamp)
        uids.append(uid)
        statuses.append(status)
    return log


def _subtree(by_fullpath: dict[str, Any], fullpath: str, uid: int) -> Any:
    """The ``<BehaviorTree>`` a ``<SubTree _fullpath=...>`` instantiates. 4.8.2 names a SubTree
    with a ``name`` its instance ``NAME::UID`` while the tree it expands is ``NAME``
    (``_fullpath="Operating::5"`` expands ``_fullpath="Operating"``): the exact path, else the
    path without its ``::UID``."""
    found = by_fullpath.get(fullpath)
    suffix = f"::{uid}"
    if found is None and fullpath.endswith(suffix):
        found = by_fullpath.get(fullpath[: -len(suffix)])
    return found


def embedded_nodes(xml: str, name: str) -> tuple[dict[int, LoggedNode], int]:
    """The nodes of the tree a BehaviorTree.CPP log embeds, by ``_uid``, with their
    interpreter paths, and the root's uid (explicit stack).

    Raises:
        InputError: XML that does not parse, no tree, or a node without ``_uid``.
    """
    root_el = parse_xml(xml, name)
    trees = [el for el in root_el if isinstance(el.tag, str) and local_name(el) == "BehaviorTree"]
    if not trees:
        raise _bad(name, "the embedded XML holds no <BehaviorTree>")
    by_fullpath = {el.get("_fullpath", ""): el for el in trees}
    main = by_fullpath.get("", trees[0])
    nodes: dict[int, LoggedNode] = {}
    tops = [child for child in main if isinstance(child.tag, str)]
    if not tops:
        raise _bad(name, "the embedded main tree is empty")
    stack = [(tops[0], "")]
    root_uid = -1
    while stack:
        el, path = stack.pop()
        tag = local_name(el)
        uid_text = el.get("_uid")
        if uid_text is None or not uid_text.isdigit():
            raise _bad(name, f"embedded node <{tag}> has no _uid (not a FileLogger2 tree)")
        uid = int(uid_text)
        if root_uid < 0:
            root_uid = uid
        children = [child for child in el if isinstance(child.tag, str)]
        sub = _subtree(by_fullpath, el.get("_fullpath", "\0"), uid) if tag == SUBTREE_TYPE else None
        if sub is not None:
            children = [child for child in sub if isinstance(child.tag, str)][:1]
        is_leaf = not children and tag != SUBTREE_TYPE
        nodes[uid] = LoggedNode(uid, el.get("name") or tag, tag, path, is_leaf)
        for index in range(len(children) - 1, -1, -1):
            stack.append((children[index], f"{path}/{index}" if path else str(index)))
    return nodes, root_uid
