"""Reading the files a model is made of: bounded, and recorded for whoever needs to know.

A model is often more than the file the user names: BehaviorTree.CPP ``<include>`` files and
SubTree definitions (``--trees``, ``--node-models``), SCXML XIncludes and ``<invoke src>``
machines, FlexBE behaviours embedded by class, ``--nodes`` library files. Every one of them is
opened here, so two rules hold for all of them in one place:

- **Bounded** (docs/security.md, "Limits"): a regular file only (a FIFO or ``/dev/zero`` could
  block or never end), at most ``limits.max_input_bytes``, checked before and while reading
  (the file may grow after ``stat``). Past the bound: an ``InputError`` naming the file.
- **Recorded**: inside ``recording_reads()`` every path asked for - read or not (a missing
  file is a dependency too: creating it changes the result), and every folder a reader scans
  for files (``note_read``) - is noted, resolved, in the order of first request. The batch
  runner keeps them with each row and re-runs a row when one of them changed (docs/batch.md,
  "Resume").

It lives at the bottom of the layers because ``model/nodes`` (node library files) reads files
as well as ``formats/``. Costs: one ``stat`` and one read per file; recording is a set look-up
and a list append.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

from fsmbt import limits
from fsmbt.model.errors import InputError, SourceLocation

#: The paths of the innermost ``recording_reads`` block, and the same as a set (each once).
_RECORDING: ContextVar[tuple[list[Path], set[Path]] | None] = ContextVar(
    "fsmbt_reads", default=None
)


@contextmanager
def recording_reads() -> Iterator[list[Path]]:
    """Record every file requested through ``read_bounded`` inside the block.

    Yields:
        The list the paths are appended to (resolved, each once, in order of first request);
        complete when the block ends. Blocks nest: an inner block records for itself only.
    """
    paths: list[Path] = []
    token = _RECORDING.set((paths, set()))
    try:
        yield paths
    finally:
        _RECORDING.reset(token)


def note_read(path: Path) -> None:
    """Record ``path`` as asked for (inside ``recording_reads``; else nothing): a file a reader
    is about to check and read, or a folder whose listing it scans for files."""
    recording = _RECORDING.get()
    if recording is None:
        return
    paths, seen = recording
    try:
        resolved = path.resolve()
    except (OSError, RuntimeError):  # a symlink loop: keep the name as given
        resolved = path.absolute()
    if resolved not in seen:
        seen.add(resolved)
        paths.append(resolved)


def read_located(
    path: Path,
    what: str = "",
    *,
    location: SourceLocation | None = None,
    element: str | None = None,
) -> bytes:
    """``read_bounded``, where the file system's refusal (an ``OSError``) is the located
    ``InputError`` "cannot read WHAT: REASON" - at ``location`` (the reference to the file,
    e.g. an ``<include>``), else at the file itself.

    Raises:
        InputError: as ``read_bounded``, or the file cannot be opened or read.
    """
    try:
        return read_bounded(path)
    except OSError as exc:
        raise InputError(
            f"cannot read {what}: {exc.strerror}" if what else f"cannot read: {exc.strerror}",
            location=location or SourceLocation(str(path)),
            element=element,
        ) from None


def read_bounded(path: Path) -> bytes:
    """A regular file's bytes, refused past ``max_input_bytes`` (see the module text).

    Raises:
        InputError: a folder, a FIFO or device, a file over the limit (located).
        OSError: the file cannot be opened or read.
    """
    note_read(path)
    limit = limits.current().max_input_bytes
    location = SourceLocation(str(path))
    size = path.stat().st_size
    if size > limit:
        raise InputError(
            limits.exceeded(f"the file's {size} bytes", "max_input_bytes", limit), location=location
        )
    if path.is_dir():
        raise InputError("is a directory, not a model file", location=location)
    if not path.is_file():  # a FIFO or a device (/dev/zero) could block or never end
        raise InputError("is not a regular file", location=location)
    with path.open("rb") as stream:
        data = stream.read(limit + 1)
    if len(data) > limit:
        raise InputError(
            limits.exceeded(f"the file's {len(data)}+ bytes", "max_input_bytes", limit),
            location=location,
        )
    return data
