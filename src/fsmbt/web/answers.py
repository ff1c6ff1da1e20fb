"""A content-addressed cache of the web API's answers (issue 29, item 1; docs/web.md, 'Cache').

Why: the page sends the same example, option and engine again and again; converting,
verifying and drawing both pictures costs tens to hundreds of milliseconds of a worker, while
the answer depends only on the request. So an answer is kept under the SHA-256 of the call's
name, its parsed body (text, format, engine, style, options: every field the service reads,
canonical JSON with sorted keys) and fsmbt's version, and a repeated request is answered from
the server's memory without a worker.

Rules:

- Only successful answers and refusals of bad input (``("ok", ...)`` and ``("error", ...)``)
  are kept; time limits, busy answers and crashes never are (they depend on the load).
- Memory is bounded by bytes: the size of an entry is the length of its pickled answer;
  least recently used entries leave first (``max_bytes``); an answer larger than a quarter of
  the bound is not kept.
- Optional disk (``directory``, ``fsmbt serve --cache-dir``): entries are also written as
  ``<hash>.json`` files (written to a temporary name, then renamed, so a reader never sees
  half a file) and read back on a memory miss. On disk an answer is *data*, never pickle: JSON
  whose byte strings are ``{"$bytes": base64}`` objects, so whoever can write into that folder
  can at worst make the server answer wrongly, never run code in it. A file that does not
  decode to an answer is ignored (a miss). Disk is not bounded by this class (the operator
  owns the folder).
- In memory (the server's own process, nothing else writes there) entries are pickled, which
  keeps a hit to one ``pickle.loads``.

Costs: one SHA-256 over the body and one pickle of the answer per miss (plus a JSON encoding
with ``directory``); a hit is a dict lookup and one unpickle.
"""

from __future__ import annotations

import base64
import hashlib
import json
import os
import pickle
import tempfile
from collections import OrderedDict
from pathlib import Path
from typing import Any

import fsmbt

#: Default bound of the in-memory cache (bytes of pickled answers).
DEFAULT_CACHE_BYTES = 256 * 1024 * 1024


def request_key(call: str, argument: Any) -> str:
    """The content address of ``call(argument)`` under this fsmbt version."""
    canonical = json.dumps(
        {"call": call, "argument": argument, "version": fsmbt.__version__},
        sort_keys=True,
        default=str,
        separators=(",", ":"),
    )
    return hashlib.sha256(canonical.encode("utf-8", "surrogatepass")).hexdigest()


class AnswerCache:
    """Answers by request hash, LRU by bytes in memory, optionally kept on disk.

    Args:
        max_bytes: the memory bound (0: memory off).
        directory: where entries are also kept on disk (``None``: memory only).
    """

    def __init__(self, max_bytes: int = DEFAULT_CACHE_BYTES, directory: Path | None = None):
        self.max_bytes = max(0, max_bytes)
        self.directory = directory
        self._entries: OrderedDict[str, bytes] = OrderedDict()
        self.bytes = 0
        self.hits = 0
        self.misses = 0
        if directory is not None:
            directory.mkdir(parents=True, exist_ok=True)

    def get(self, key: str) -> tuple[str, Any] | None:
        """The stored answer of ``key`` or ``None``."""
        data = self._entries.get(key)
        if data is not None:
            self._entries.move_to_end(key)
        elif self.directory is not None:
            stored = _read_stored(self.directory / f"{key}.json")
            if stored is not None:
                data = pickle.dumps(stored, protocol=pickle.HIGHEST_PROTOCOL)
                self._remember(key, data)
        if data is None:
            self.misses += 1
            return None
        self.hits += 1
        answer: tuple[str, Any] = pickle.loads(data)
        return answer

    def put(self, key: str, answer: tuple[str, Any]) -> None:
        """Keep ``answer`` (only ``ok`` and ``error`` answers; see the module's rules)."""
        if answer[0] not in ("ok", "error"):
            return
        data = pickle.dumps(answer, protocol=pickle.HIGHEST_PROTOCOL)
        self._remember(key, data)
        if self.directory is not None:
            stored = json.dumps(answer, default=_bytes_as_data, separators=(",", ":"))
            target = self.directory / f"{key}.json"
            handle, temporary = tempfile.mkstemp(dir=self.directory, suffix=".part")
            with os.fdopen(handle, "wb") as out:
                out.write(stored.encode("utf-8"))
            os.replace(temporary, target)

    def _remember(self, key: str, data: bytes) -> None:
        if len(data) * 4 > self.max_bytes:
            return
        previous = self._entries.pop(key, None)
        if previous is not None:
            self.bytes -= len(previous)
        self._entries[key] = data
        self.bytes += len(data)
        while self.bytes > self.max_bytes and self._entries:
            _, dropped = self._entries.popitem(last=False)
            self.bytes -= len(dropped)


def _bytes_as_data(value: object) -> dict[str, str]:
    """``json.dumps``'s hook: bytes become ``{"$bytes": base64}`` (tuples are lists already)."""
    if isinstance(value, bytes):
        return {"$bytes": base64.b64encode(value).decode("ascii")}
    raise TypeError(f"{type(value).__name__} is not kept in the answer cache")


def _data_as_bytes(item: dict[str, Any]) -> Any:
    """``json.loads``'s hook, the inverse of ``_bytes_as_data`` (bad base64: ``ValueError``)."""
    if set(item) == {"$bytes"}:
        return base64.b64decode(item["$bytes"], validate=True)
    return item


def _read_stored(path: Path) -> tuple[str, Any] | None:
    """The answer kept in ``path``, or ``None`` when it is missing or is not one."""
    try:
        value = json.loads(path.read_bytes(), object_hook=_data_as_bytes)
    except (OSError, ValueError, RecursionError):  # missing, unreadable, not JSON, bad base64
        return None
    if not (isinstance(value, list) and len(value) == 2 and value[0] in ("ok", "error")):
        return None
    return value[0], value[1]
