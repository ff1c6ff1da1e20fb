"""What a batch runs: one ``Job`` per input file, and how inputs become jobs.

Rules (docs/batch.md, "Inputs and outputs"):

- An input is a file, a folder (walked with an explicit stack, symbolic links to folders not
  followed, the output folder skipped) or a glob. A file named on the command line is always a
  job (if it is unreadable, its row says so). In a folder, a file is taken when a reader's
  content sniffer claims it, or when its extension belongs to a format, except the prose and
  source extensions (``.md``, ``.txt``, ``.py``), which are taken only when their content is
  claimed (a Python file is a model only when it builds a SMACH/FlexBE state machine; a
  README is not a model).
- Outputs mirror the inputs' layout under ``outdir``, relative to the deepest folder all inputs
  share. The output's extension is the target format's: ``to`` when given, else the default of
  the result's kind (a BT for an FSM, an FSM for a BT), the kind being decided from the format
  the content is sniffed as (a format holding both kinds, JSON or YAML, is asked for the
  ``kind`` field; when that cannot be told the worker's error row will name the input's
  problem anyway). Two inputs that would share an output keep their source extension in the
  output's name (``paper_fsm.json.xml`` and ``paper_fsm.xml.xml``).
- ``Job.key`` is a content hash of the input and a hash of what decides the result (engine,
  verifier, options, output name); it is what the store remembers. The per-model limits
  (``timeout_s``, ``max_states``) are not part of it, so a second run with larger limits
  re-runs exactly the rows that hit the old ones (``fsmbt.batch.driver``); nor are the LLM
  endpoint's address and request timeout (``ENDPOINT_OPTIONS``): the model's name is.

Costs: ``make_jobs`` reads every input once (hashing, at most ``limits.current().max_input_bytes`` + 1 bytes
each) and sniffs its first ``SNIFF_BYTES``; nothing is parsed except the small ``kind`` probe
of JSON/YAML files.
"""

from __future__ import annotations

import glob
import hashlib
import json
import os
import re
import stat
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fsmbt import limits
from fsmbt.api import DEFAULT_BT_FORMAT, DEFAULT_FSM_FORMAT
from fsmbt.formats.registry import Format, formats, get_format
from fsmbt.model.errors import InputError

#: Options that bound the work on one model; not part of a job's key (see the module text).
LIMIT_OPTIONS = ("timeout_s", "max_states")
#: Options that say how to reach an LLM, not which model answers; not part of a job's key.
#: (``llm_model`` is.) The same model at another address, or with another request timeout,
#: resumes the same rows.
ENDPOINT_OPTIONS = ("llm_base_url", "llm_timeout", "llm_log", "llm_api_key")
#: Options never written to the store (secrets).
SECRET_OPTIONS = ("llm_api_key",)
#: Extensions of prose formats: in a folder they are taken only when the content is claimed.
PROSE_EXTENSIONS = (".md", ".markdown", ".txt", ".py")
#: How much of a file the content sniffers see when a folder is walked.
SNIFF_BYTES = 64 * 1024
_KIND_FIELD = re.compile(r"""["']?kind["']?\s*:\s*["']?(fsm|bt)\b""")


@dataclass(frozen=True)
class Job:
    """One input to convert and verify.

    Attributes:
        input: the input file's path.
        output: where the result goes, or ``None`` (converted and verified, not written).
        engine: the conversion engine (``rules``, ``bsd``, ``chds``, ``llm``, ...).
        verify_engine: ``native``, ``nusmv`` or ``both``; ``"none"`` skips verification.
        options: JSON-able options: ``to``, ``source_format``, ``loop``, ``hierarchy``,
            ``style``, ``node_models``, ``keep_not_equivalent``, ``max_states``,
            ``timeout_s``, the LLM settings (``llm_base_url``, ``llm_model``, ...).
        overwrite: an existing output may be replaced (``--force``; not part of the key).
        runtime: run settings that do not change the result (the LLM rate limit and its
            shared state file); not part of the key.
        key: the content hash of the input plus a hash of engine, verifier, options and
            output name; computed when left empty.
    """

    input: str
    output: str | None = None
    engine: str = "rules"
    verify_engine: str = "native"
    options: dict[str, Any] = field(default_factory=dict)
    overwrite: bool = False
    runtime: dict[str, Any] = field(default_factory=dict, compare=False)
    key: str = ""

    def __post_init__(self) -> None:
        if not self.key:
            object.__setattr__(
                self,
                "key",
                job_key(self.input, self.output, self.engine, self.verify_engine, self.options),
            )

    def __hash__(self) -> int:
        return hash(self.key)

    @property
    def limits(self) -> dict[str, Any]:
        """The per-model limits this job runs with (``timeout_s``, ``max_states``)."""
        return {name: self.options[name] for name in LIMIT_OPTIONS if name in self.options}


def public_options(options: dict[str, Any]) -> dict[str, Any]:
    """``options`` without the secrets (what the store may keep)."""
    return {k: v for k, v in options.items() if k not in SECRET_OPTIONS}


def content_hash(path: str | Path) -> str:
    """SHA-256 of a file's first ``max_input_bytes`` + 1 bytes and its size, in hex.

    A folder's hash is of its sorted listing (names only: a reader that scanned it for files
    depends on which files are there; their contents, when read, are dependencies of their
    own). Another path that is not a regular file (missing, a FIFO, a device) is never opened:
    its hash is of its name and what it is, so the worker's row reports the problem.
    """
    digest = hashlib.sha256()
    try:
        info = os.stat(path)
    except OSError as exc:
        digest.update(f"missing:{path}:{exc.errno}".encode())
        return digest.hexdigest()
    if stat.S_ISDIR(info.st_mode):  # a folder a reader scanned: its listing is its content
        try:
            names = sorted(os.listdir(path))
        except OSError as exc:
            names = [f"unlistable:{exc.errno}"]
        digest.update(f"folder:{path}:".encode() + "\0".join(names).encode(errors="replace"))
        return digest.hexdigest()
    if not stat.S_ISREG(info.st_mode):
        digest.update(f"special:{path}:{stat.S_IFMT(info.st_mode)}".encode())
        return digest.hexdigest()
    try:
        with open(path, "rb") as stream:
            remaining = limits.current().max_input_bytes + 1
            while remaining > 0:
                block = stream.read(min(remaining, 1 << 20))
                if not block:
                    break
                digest.update(block)
                remaining -= len(block)
    except OSError as exc:
        digest.update(f"unreadable:{path}:{exc.errno}".encode())
    digest.update(f":size={info.st_size}".encode())
    return digest.hexdigest()


def job_key(
    input_path: str, output: str | None, engine: str, verify_engine: str, options: dict[str, Any]
) -> str:
    """A job's key: ``<content hash>-<settings hash>`` (see the module text).

    Args:
        input_path: the input file.
        output: the output path (only its name counts, so a moved output folder still
            resumes), or ``None``.
        engine, verify_engine, options: as in ``Job``.

    Returns:
        48 hex digits and a dash.
    """
    settings = {
        "engine": engine,
        "verify": verify_engine,
        "options": {
            k: v
            for k, v in sorted(options.items())
            if k not in LIMIT_OPTIONS and k not in ENDPOINT_OPTIONS
        },
        "output": Path(output).name if output is not None else Path(input_path).name,
    }
    encoded = json.dumps(settings, sort_keys=True, default=str).encode()
    return f"{content_hash(input_path)[:32]}-{hashlib.sha256(encoded).hexdigest()[:16]}"


# -- inputs -----------------------------------------------------------------------------------


def _known_extensions() -> tuple[str, ...]:
    return tuple(ext for fmt in formats() if fmt.read is not None for ext in fmt.extensions)


def _sniffed(path: Path) -> Format | None:
    """The format whose content sniffer claims ``path`` (first ``SNIFF_BYTES``), or ``None``."""
    try:
        with path.open("rb") as stream:
            head = stream.read(SNIFF_BYTES)
    except OSError:
        return None
    text = head.decode("utf-8", errors="replace").lstrip("\ufeff")
    for fmt in formats():
        if fmt.read is not None and fmt.sniff is not None:
            try:
                if fmt.sniff(text):
                    return fmt
            except Exception:  # noqa: BLE001 - a sniffer's problem means "not mine"
                continue
    return None


def claimed_by_a_reader(path: Path) -> bool:
    """Whether a folder walk takes ``path`` (see the module text).

    Args:
        path: a regular file met while walking a folder.

    Returns:
        ``True`` when a reader's sniffer claims its content, or its extension is a format's
        and not a prose extension.
    """
    if _sniffed(path) is not None:
        return True
    name = path.name.lower()
    if name.endswith(PROSE_EXTENSIONS):
        return False
    return name.endswith(_known_extensions())


def _walk(folder: Path, skip: Path | None) -> Iterable[Path]:
    """Regular files under ``folder`` (explicit stack, sorted, links to folders not followed)."""
    stack = [folder]
    while stack:
        current = stack.pop()
        try:
            entries = sorted(os.scandir(current), key=lambda e: e.name)
        except OSError:
            continue
        folders: list[Path] = []
        for entry in entries:
            try:
                if entry.is_dir(follow_symlinks=False):
                    child = Path(entry.path)
                    if skip is None or child.resolve() != skip:
                        folders.append(child)
                elif entry.is_file(follow_symlinks=True):
                    yield Path(entry.path)
            except OSError:
                continue
        stack.extend(reversed(folders))


@dataclass
class Expanded:
    """The input files a list of arguments names, and what was left out.

    Attributes:
        files: the input files in order, each once.
        skipped: files met in folders that no reader claims.
        missing: arguments that name nothing (a path or glob that matches no file).
    """

    files: list[Path] = field(default_factory=list)
    skipped: list[Path] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)


def expand_inputs(inputs: Sequence[str | Path], *, skip: Path | None = None) -> Expanded:
    """Files, folders and globs to the list of input files.

    Args:
        inputs: paths of files or folders, or glob patterns (``**`` allowed).
        skip: a folder never walked into (the batch's output folder).

    Returns:
        The ``Expanded`` inputs. A named file that does not exist is kept as a job (its row
        says it is missing) when it is not a glob pattern.
    """
    found = Expanded()
    seen: set[Path] = set()
    skip_resolved = skip.resolve() if skip is not None else None

    def add(path: Path) -> None:
        resolved = path.resolve()
        if resolved not in seen:
            seen.add(resolved)
            found.files.append(path)

    for raw in inputs:
        text = str(raw)
        path = Path(text)
        if path.is_dir():
            for child in _walk(path, skip_resolved):
                if claimed_by_a_reader(child):
                    add(child)
                else:
                    found.skipped.append(child)
        elif glob.has_magic(text):
            matches = sorted(glob.glob(text, recursive=True))
            for match in matches:
                if not Path(match).is_dir():
                    add(Path(match))
            for match in matches:
                if Path(match).is_dir():
                    for child in _walk(Path(match), skip_resolved):
                        if claimed_by_a_reader(child):
                            add(child)
            if not matches:
                found.missing.append(text)
        else:
            add(path)  # a file, or a name whose row will say what is wrong with it
    return found


def _mirror_root(files: Sequence[Path], inputs: Sequence[str | Path]) -> Path:
    """The deepest folder every input lies in (a folder argument counts as itself)."""
    anchors = []
    for raw in inputs:
        path = Path(str(raw))
        if path.is_dir():
            anchors.append(str(path.resolve()))
    anchors.extend(str(f.resolve().parent) for f in files)
    if not anchors:
        return Path.cwd()
    try:
        return Path(os.path.commonpath(anchors))
    except ValueError:  # different drives
        return Path(anchors[0])


def _result_kind(path: Path) -> str | None:
    """The kind of the *result* for ``path`` (``"bt"`` for an FSM input), or ``None``."""
    fmt = _sniffed(path)
    if fmt is None:
        from fsmbt.formats.registry import format_for_path

        fmt = format_for_path(path)
    if fmt is None:
        return None
    kinds = set(fmt.kinds)
    if len(kinds) != 1:
        try:
            with path.open("rb") as stream:
                head = stream.read(SNIFF_BYTES).decode("utf-8", errors="replace")
        except OSError:
            return None
        match = _KIND_FIELD.search(head)
        if match is None:
            return None
        kinds = {match.group(1)}
    return "bt" if kinds == {"fsm"} else "fsm"


def _output_extension(fmt_name: str) -> str:
    return get_format(fmt_name).extensions[0]


def output_for(path: Path, root: Path, outdir: Path, to: str | None) -> Path:
    """Where the result for ``path`` goes (before name clashes are resolved).

    Args:
        path: the input file.
        root: the folder the layout is mirrored relative to.
        outdir: the batch's output folder.
        to: the output format, or ``None`` for the kind's default.

    Returns:
        ``outdir / <path's folder relative to root> / <stem><target extension>``.
    """
    if to is not None:
        extension = _output_extension(to)
    else:
        kind = _result_kind(path)
        default = DEFAULT_FSM_FORMAT if kind == "fsm" else DEFAULT_BT_FORMAT
        extension = _output_extension(default) if kind is not None else ".out"
    try:
        relative = path.resolve().parent.relative_to(root)
    except ValueError:
        relative = Path()
    stem = path.name.split(".")[0] or path.name
    return outdir / relative / f"{stem}{extension}"


def make_jobs(
    inputs: Sequence[str | Path],
    outdir: Path,
    *,
    engine: str = "rules",
    verify_engine: str = "native",
    options: dict[str, Any] | None = None,
    to: str | None = None,
    overwrite: bool = False,
    runtime: dict[str, Any] | None = None,
) -> list[Job]:
    """One ``Job`` per input file, outputs mirrored under ``outdir``.

    Args:
        inputs: files, folders (walked recursively) and glob patterns.
        outdir: the output folder (never walked into, even when it lies inside an input).
        engine: the conversion engine.
        verify_engine: ``native``, ``nusmv``, ``both`` or ``none``.
        options: the jobs' options (see ``Job``); ``to`` is added when given.
        to: the output format (default: the result kind's default).
        overwrite: existing outputs may be replaced.
        runtime: run settings handed to every job (see ``Job.runtime``).

    Returns:
        The jobs, in input order.

    Raises:
        InputError: an unknown output format, or a glob that matches nothing.
    """
    if to is not None:
        get_format(to)  # an unknown name fails here, once, not in every row
    expanded = expand_inputs(inputs, skip=outdir)
    if expanded.missing:
        raise InputError(f"no file matches {', '.join(repr(m) for m in expanded.missing)}")
    job_options = dict(options or {})
    if to is not None:
        job_options["to"] = to
    root = _mirror_root(expanded.files, inputs)
    outputs = [output_for(path, root, outdir, to) for path in expanded.files]
    clashes: dict[Path, int] = {}
    for output in outputs:
        clashes[output] = clashes.get(output, 0) + 1
    jobs = []
    for path, output in zip(expanded.files, outputs):
        if clashes[output] > 1:
            output = output.with_name(f"{path.name}{output.suffix}")
        jobs.append(
            Job(
                str(path),
                str(output),
                engine,
                verify_engine,
                dict(job_options),
                overwrite,
                dict(runtime or {}),
            )
        )
    return jobs
