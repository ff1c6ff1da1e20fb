"""The trace of fsmbt's Python runtime on py_trees: JSON lines (docs/conform.md, 'The py_trees
trace'), and its writer.

Format, one JSON object per line, UTF-8:

- line 1, the header: ``{"fsmbt_trace": 1, "engine": "py_trees", "start_us": INT,
  "nodes": [{"uid": INT, "name": STR, "type": STR, "path": STR, "leaf": BOOL}, ...]}`` — every
  node of the tree that ran, ``path`` the child-index path from the main root through expanded
  SubTrees (``""`` for the root, which comes first);
- every further line, one status transition: ``{"t": INT, "uid": INT, "status": STR}`` — ``t``
  microseconds since ``start_us``, ``status`` one of ``IDLE``, ``RUNNING``, ``SUCCESS``,
  ``FAILURE`` (py_trees' ``INVALID`` is written ``IDLE``). A leaf has one line per tick, even
  when its status does not change (a RUNNING action ticked again); an inner node one line per
  change, written after the tick's leaves; the root's SUCCESS or FAILURE every tick it ends so.

The same information as a ``.btlog``, so the replay reads both the same way. Refused with the
line named (exit 2): not JSON, a missing or foreign header, an unknown status or UID.
``TraceWriter`` writes it; ``TracedPyTreesRunner`` runs a tree on py_trees (fsmbt's py_trees
runner, ``fsmbt.semantics.engines.pytrees_engine``) and writes its trace. Costs: O(lines).
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import IO, Any

from fsmbt.conform.log import STATUS_NAMES, LoggedNode, RecordedLog
from fsmbt.model.errors import InputError, SourceLocation
from fsmbt.model.files import read_located
from fsmbt.model.nodes import SUBTREE_TYPE

VERSION = 1
_BY_NAME = {name: value for value, name in STATUS_NAMES.items()}


def _bad(path: str, line: int, message: str) -> InputError:
    return InputError(message, location=SourceLocation(path, line))


def read_trace(path: str | Path) -> RecordedLog:
    """Read a py_trees trace (see the module docstring).

    Raises:
        InputError: the file is not such a trace (the line is named).
    """
    name = str(path)
    data = read_located(Path(path), "the trace")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise _bad(name, 1, "not a fsmbt trace: the file is not UTF-8 text") from None
    lines = text.splitlines()
    header = _json(name, 1, lines[0] if lines else "")
    if not isinstance(header, dict) or header.get("fsmbt_trace") != VERSION:
        raise _bad(
            name,
            1,
            f'not a fsmbt trace: the first line is not a header with "fsmbt_trace": {VERSION}',
        )
    nodes: dict[int, LoggedNode] = {}
    for entry in header.get("nodes", []):
        try:
            node = LoggedNode(
                int(entry["uid"]),
                str(entry["name"]),
                str(entry["type"]),
                str(entry["path"]),
                bool(entry["leaf"]),
            )
        except (KeyError, TypeError, ValueError):
            raise _bad(name, 1, "a header node lacks uid, name, type, path or leaf") from None
        nodes[node.uid] = node
    roots = [n.uid for n in nodes.values() if n.path == ""]
    if not roots:
        raise _bad(name, 1, 'the header has no root node (path "")')
    log = RecordedLog(name, "trace", nodes, roots[0], int(header.get("start_us", 0)))
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        event = _json(name, number, line)
        try:
            t, uid, status = int(event["t"]), int(event["uid"]), _BY_NAME[event["status"]]
        except (KeyError, TypeError, ValueError):
            raise _bad(
                name,
                number,
                f"a transition needs t (int), uid (int) and status ({', '.join(_BY_NAME)})",
            ) from None
        if uid not in nodes:
            raise _bad(
                name,
                number,
                f"node UID {uid} is not in the trace's header (a trace of "
                "another tree, or a corrupt file)",
            )
        log.times.append(t)
        log.uids.append(uid)
        log.statuses.append(status)
    return log


def _json(name: str, number: int, line: str) -> Any:
    try:
        return json.loads(line)
    except json.JSONDecodeError as exc:
        raise _bad(name, number, f"not JSON ({exc.msg} at column {exc.colno})") from None


class TraceWriter:
    """Writes a trace: the header once, then ``transition(uid, status)`` per change."""

    def __init__(self, stream: IO[str], nodes: list[LoggedNode], engine: str = "py_trees") -> None:
        self.stream = stream
        self.start = time.time_ns() // 1000
        self.last: dict[int, int] = {}
        header = {
            "fsmbt_trace": VERSION,
            "engine": engine,
            "start_us": self.start,
            "nodes": [
                {"uid": n.uid, "name": n.label, "type": n.type, "path": n.path, "leaf": n.leaf}
                for n in nodes
            ],
        }
        stream.write(json.dumps(header) + "\n")

    def transition(self, uid: int, status: int, *, tick: bool = False) -> None:
        """Record that node ``uid`` now has ``status``: nothing when it already had it (as
        BehaviorTree.CPP's loggers), unless ``tick`` (a leaf's tick, always written)."""
        if self.last.get(uid, 0) == status and not tick:
            return
        self.last[uid] = status
        t = time.time_ns() // 1000 - self.start
        self.stream.write(json.dumps({"t": t, "uid": uid, "status": STATUS_NAMES[status]}) + "\n")


def write_lines(path: Path, nodes: list[LoggedNode], events: list[tuple[int, int, int]]) -> None:
    """Write a whole trace at once (``events``: ``(t, uid, status)``); for tests and the
    benchmark."""
    with path.open("w", encoding="utf-8") as stream:
        writer = TraceWriter(stream, nodes)
        for t, uid, status in events:
            stream.write(json.dumps({"t": t, "uid": uid, "status": STATUS_NAMES[status]}) + "\n")
        del writer


class TracedPyTreesRunner:
    """A tree run on py_trees (``PyTreesRunner``: every leaf asks ``env(node, path)``) whose
    every tick is written to a trace: each leaf's tick as it returns, then every other node's
    status change."""

    def __init__(self, doc: Any, env: Any, stream: IO[str]) -> None:
        from fsmbt.semantics.bt_interpreter import CompiledTree
        from fsmbt.semantics.engines.pytrees_engine import PyTreesRunner

        compiled = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        nodes = [
            LoggedNode(n.id, n.label, n.type, n.path, not n.children and n.type != SUBTREE_TYPE)
            for n in compiled.nodes
        ]
        self.writer = TraceWriter(stream, nodes)

        def traced(node: Any, path: str) -> str:
            outcome = str(env(node, path))
            uid = by_path[path]
            self.writer.transition(uid, _BY_NAME[outcome.upper()], tick=True)
            return outcome

        by_path = {n.path: n.id for n in compiled.nodes}
        self.runner = PyTreesRunner(compiled, traced)

    def tick_once(self) -> str:
        """One tick; returns the root's status name."""
        record = self.runner.tick_once()
        for behaviour in self.runner.root.iterate():
            name = behaviour.name
            if not (name.startswith("n") and name[1:].isdigit()):
                continue
            uid = int(name[1:])
            status = _PY_TREES.get(behaviour.status.name, 0)
            if behaviour.children or uid == 0 or status == 0:
                # the root's result is written every tick (a tick's end), the rest on change
                self.writer.transition(uid, status, tick=uid == 0 and status in (2, 3))
        return record.result


_PY_TREES = {"INVALID": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3}
