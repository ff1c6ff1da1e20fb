"""Coverage-guided fuzzing of every fsmbt reader with atheris (libFuzzer).

Usage (from the repository root)::

    PYTHONPATH=src python fuzz/fuzz_readers.py --iterations 100000 --reader all --seed 1 \
        --timeout-per-input 2

The rule every reader must keep: whatever bytes it is given, reading them (``decode`` then the
format's reader, as ``fsmbt.api.load`` does) ends in one of three ways only - a model,
an ``InputError`` or an ``UnsupportedError`` (``fsmbt.model.errors``) whose message is one line
and names the input (a location). Anything else is a *finding*:

- ``crash``: any other exception (``KeyError``, ``RecursionError``, ``MemoryError`` ...), or an
  ``InputError`` whose message spans several lines or carries no location;
- ``timeout``: one input took longer than ``--timeout-per-input`` seconds of CPU (a soft
  ``SIGPROF`` alarm raises inside the reader) or longer than ``--hard-timeout`` seconds of wall
  time (libFuzzer's own alarm kills the worker; this catches loops inside C code);
- ``memory``: the worker's address space is capped with ``resource.setrlimit(RLIMIT_AS)`` at
  ``--memory-mb``; an allocation past it raises ``MemoryError`` in Python (reported as
  ``memory``) or kills the worker (libFuzzer's ``-rss_limit_mb`` reports it as ``oom``).

Each finding's input is saved once per distinct cause (exception type and the innermost fsmbt
frame) as ``tests/fuzz/regressions/<reader>/<kind>-<sha1>.input`` with a ``.cause`` file holding
the one-line cause; ``tests/fuzz/test_fuzz_regressions.py`` replays every saved input.

The readers come from the format registry (every format with a reader is one entry), so a reader
added to ``fsmbt.formats`` is fuzzed without a change here. Seeds: the examples, the external
corpus (``$FSMBT_CORPUS``, default ``/work/shared/corpus``, read at run time and never copied into
the repository), and every example and generated model written in the reader's own format.

atheris runs the target in-process, so each batch of at most ``--batch`` iterations of one reader
runs in a subprocess of its own (memory cap, alarms, a crash of the worker costs one batch); the
parent adds the batches up and prints one table: reader, iterations, crashes, timeouts, memory,
and coverage as libFuzzer reports it for the instrumented fsmbt bytecode (``cov``: edges,
``ft``: features, at the end of the reader's last batch; the working corpus persists in
``--work-dir`` between batches and runs, so the figures grow with the total budget).

Costs: the parent is cheap; a worker runs one reader at a time on one core.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from dataclasses import asdict, dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_REGRESSIONS = ROOT / "tests" / "fuzz" / "regressions"
DEFAULT_WORK_DIR = ROOT / ".cache" / "fuzz"
EXAMPLES = ROOT / "examples"
#: The fake file every input is read as: an empty folder, so an ``<include>`` finds nothing.
FAKE_DIR_NAME = "fuzz-input-dir"
COV_LINE = re.compile(r"cov: (\d+) ft: (\d+)")


# ------------------------------------------------------------------------------------------------
# the parent: build seeds, run batches, add them up, print the table


@dataclass
class ReaderResult:
    """What the batches of one reader added up to."""

    reader: str
    iterations: int = 0
    crashes: int = 0
    timeouts: int = 0
    memory: int = 0
    cov: int = 0
    ft: int = 0
    seeds: int = 0
    seconds: float = 0.0
    findings: list[str] = field(default_factory=list)  # saved input files (new or known)


def import_plugins(modules: list[str]) -> None:
    """Import modules that register further formats (``--import``; e.g. a test's planted
    reader); they become readers like any other."""
    import importlib

    for name in modules:
        importlib.import_module(name)


def reader_names() -> list[str]:
    """Every format of the registry that can read: one entry each."""
    from fsmbt.formats import formats

    return [f.name for f in formats() if f.read is not None]


def corpus_dir() -> Path | None:
    """The external corpus, if present (it is read, never copied)."""
    path = Path(os.environ.get("FSMBT_CORPUS", "/work/shared/corpus"))
    return path if path.is_dir() else None


def build_seeds(reader: str, out: Path, *, max_seed_bytes: int) -> int:
    """Write the seed inputs of ``reader`` into ``out``; returns how many.

    Seeds: example and corpus files the reader claims (extension or content sniffing), and
    example, corpus and generated models written by the reader's own writer, when it has one.
    """
    from fsmbt import api
    from fsmbt.formats import detect_format, dumps, get_format
    from fsmbt.formats.registry import decode
    from fsmbt.generate import random_bt, random_fsm
    from fsmbt.model.errors import InputError

    fmt = get_format(reader)
    out.mkdir(parents=True, exist_ok=True)
    files = sorted(p for p in EXAMPLES.iterdir() if p.is_file())
    corpus = corpus_dir()
    if corpus is not None:
        files += sorted(p for p in corpus.rglob("*") if p.is_file() and p.suffix != ".md")
    seeds: dict[str, bytes] = {}
    models = []
    for path in files:
        data = path.read_bytes()
        if len(data) > max_seed_bytes:
            continue
        try:
            text = decode(data, str(path))
        except InputError:
            continue
        claims = any(str(path).lower().endswith(ext) for ext in fmt.extensions)
        try:
            claims = claims or detect_format(text, None).name == reader
        except InputError:
            pass
        if claims:
            seeds[hashlib.sha1(data).hexdigest()] = data
        try:
            models.append(api.load(path).model)
        except InputError:
            pass
    for seed in range(12):
        models.append(random_fsm(seed=seed, max_states=8))
        models.append(random_bt(seed=seed, max_nodes=20))
    if fmt.write is not None:
        for model in models:
            try:
                data = dumps(model, reader).encode("utf-8")
            except InputError:
                continue  # the format cannot hold this model
            if len(data) <= max_seed_bytes:
                seeds[hashlib.sha1(data).hexdigest()] = data
    for digest, data in seeds.items():
        (out / digest).write_bytes(data)
    return len(seeds)


_DICT_TOKEN = re.compile(
    rb"</?[A-Za-z_][\w:.-]*|[A-Za-z_][\w:.-]*=\"?|[A-Za-z_]\w{2,}"
    rb"|[-=<>|*\[\]{}():;,#]{1,4}"
)


def build_dictionary(seeds: Path, out: Path, *, max_tokens: int = 500) -> Path:
    """A libFuzzer dictionary of the seeds' most frequent tokens (tags, attribute names,
    keywords, arrows), so mutations insert whole words of the format instead of stray bytes."""
    counts: dict[bytes, int] = {}
    for path in seeds.iterdir():
        for token in _DICT_TOKEN.findall(path.read_bytes()):
            if len(token) <= 40:
                counts[token] = counts.get(token, 0) + 1
    best = sorted(counts, key=lambda t: (-counts[t], t))[:max_tokens]
    lines = [
        '"'
        + "".join(chr(b) if 32 <= b < 127 and b not in (34, 92) else f"\\x{b:02x}" for b in token)
        + '"'
        for token in best
    ]
    out.write_text("\n".join(lines) + "\n", encoding="ascii")
    return out


def run_reader(reader: str, args: argparse.Namespace) -> ReaderResult:
    """All batches of one reader, each in a fresh worker subprocess."""
    result = ReaderResult(reader)
    work = Path(args.work_dir) / reader
    corpus = work / "corpus"
    seeds = work / "seeds"
    artifacts = work / "artifacts"
    for folder in (corpus, artifacts):
        folder.mkdir(parents=True, exist_ok=True)
    if seeds.exists():
        shutil.rmtree(seeds)
    result.seeds = build_seeds(reader, seeds, max_seed_bytes=args.max_len)
    dictionary = build_dictionary(seeds, work / "tokens.dict")
    started = time.monotonic()
    batch_index = 0
    stalled = 0
    while result.iterations < args.iterations:
        runs = min(args.batch, args.iterations - result.iterations)
        status_file = work / "status.json"
        status_file.unlink(missing_ok=True)
        for stale in artifacts.iterdir():
            stale.unlink()
        command = [
            sys.executable,
            str(Path(__file__).resolve()),
            "--worker",
            "--reader",
            reader,
            "--iterations",
            str(runs),
            "--seed",
            str(args.seed * 1000 + batch_index),
            "--timeout-per-input",
            str(args.timeout_per_input),
            "--hard-timeout",
            str(args.hard_timeout),
            "--memory-mb",
            str(args.memory_mb),
            "--max-len",
            str(args.max_len),
            "--regressions",
            str(args.regressions),
            "--status",
            str(status_file),
            "--artifacts",
            str(artifacts),
            "--dict",
            str(dictionary),
            *(["--value-profile"] if args.value_profile else []),
            *[f"--import={name}" for name in args.imports],
            str(corpus),
            str(seeds),
        ]
        env = dict(
            os.environ, PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")
        )
        proc = subprocess.run(
            command,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            errors="replace",
        )
        status = _read_status(status_file)
        done = int(status.get("iterations", 0))
        result.crashes += int(status.get("crashes", 0))
        result.timeouts += int(status.get("timeouts", 0))
        result.memory += int(status.get("memory", 0))
        result.findings += [str(p) for p in status.get("saved", [])]
        covs = COV_LINE.findall(proc.stdout)
        if covs:
            result.cov, result.ft = (int(x) for x in covs[-1])
        if proc.returncode != 0:
            # the worker died: libFuzzer's hard alarm, its RSS limit, or a crash in C code
            done += 1  # the input that killed it
            kind = _save_artifacts(reader, artifacts, Path(args.regressions), proc.stdout, result)
            if args.verbose:
                print(proc.stdout[-3000:], file=sys.stderr)
            print(
                f"  {reader}: worker exited {proc.returncode} ({kind}) after {done} inputs",
                file=sys.stderr,
            )
        result.iterations += done
        stalled = stalled + 1 if done <= 1 else 0
        if stalled >= 3:
            print(
                f"  {reader}: three batches in a row died at once; giving up on it", file=sys.stderr
            )
            break
        batch_index += 1
        print(
            f"  {reader}: {result.iterations}/{args.iterations} inputs, "
            f"{result.crashes} crash(es), {result.timeouts} timeout(s), "
            f"{result.memory} memory; cov {result.cov} ft {result.ft}",
            file=sys.stderr,
        )
    result.seconds = time.monotonic() - started
    return result


def _read_status(path: Path) -> dict[str, object]:
    try:
        return dict(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError):
        return {}


def _save_artifacts(
    reader: str, artifacts: Path, regressions: Path, output: str, result: ReaderResult
) -> str:
    """Keep the input libFuzzer wrote when it killed the worker; count it by its kind."""
    kind = "crash"
    for artifact in sorted(artifacts.iterdir()):
        prefix = artifact.name.split("-", 1)[0]
        kind = {"timeout": "timeout", "oom": "memory"}.get(prefix, "crash")
        data = artifact.read_bytes()
        cause = {
            "timeout": "hard timeout (libFuzzer alarm): the reader did not return",
            "memory": "out of memory (libFuzzer RSS limit)",
        }.get(kind, "worker crashed")
        tail = [line for line in output.splitlines() if line.strip()][-3:]
        saved = save_finding(regressions / reader, kind, data, f"{cause}; {' | '.join(tail)}")
        result.findings.append(str(saved))
    if kind == "timeout":
        result.timeouts += 1
    elif kind == "memory":
        result.memory += 1
    else:
        result.crashes += 1
    return kind


def save_finding(folder: Path, kind: str, data: bytes, cause: str) -> Path:
    """Save one finding's input (named by content) and its one-line cause; returns the path."""
    folder.mkdir(parents=True, exist_ok=True)
    digest = hashlib.sha1(data).hexdigest()[:16]
    path = folder / f"{kind}-{digest}.input"
    if not path.exists():
        path.write_bytes(data)
        path.with_suffix(".cause").write_text(
            " ".join(cause.split())[:500] + "\n", encoding="utf-8"
        )
    return path


def print_table(results: list[ReaderResult]) -> str:
    """The figures, as a Markdown table (also what docs/security.md quotes)."""
    rows = [
        "| reader | iterations | crashes | timeouts | memory | cov (edges) | ft (features) "
        "| seeds | seconds |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        rows.append(
            f"| {r.reader} | {r.iterations} | {r.crashes} | {r.timeouts} | {r.memory} "
            f"| {r.cov} | {r.ft} | {r.seeds} | {r.seconds:.0f} |"
        )
    total = sum(r.iterations for r in results)
    rows.append(
        f"| **total** | {total} | {sum(r.crashes for r in results)} "
        f"| {sum(r.timeouts for r in results)} | {sum(r.memory for r in results)} "
        "| | | | "
        f"{sum(r.seconds for r in results):.0f} |"
    )
    table = "\n".join(rows)
    print(table)
    print(
        "coverage: libFuzzer's cov (edges) and ft (features) over the atheris-instrumented "
        "fsmbt bytecode, at the end of each reader's last batch"
    )
    return table


def parent_main(args: argparse.Namespace) -> int:
    import_plugins(args.imports)
    names = reader_names()
    chosen = names if args.reader == "all" else [args.reader]
    for name in chosen:
        if name not in names:
            print(f"unknown reader '{name}' (readers: {', '.join(names)})", file=sys.stderr)
            return 2
    results = [run_reader(name, args) for name in chosen]
    print_table(results)
    if args.json:
        Path(args.json).write_text(
            json.dumps([asdict(r) for r in results], indent=2), encoding="utf-8"
        )
    found = sum(r.crashes + r.timeouts + r.memory for r in results)
    return 1 if found else 0


# ------------------------------------------------------------------------------------------------
# the worker: one reader, one libFuzzer run, in-process


class InputTimeout(BaseException):
    """Raised by the soft alarm inside a reader (a BaseException: ``except Exception`` in a
    reader must not swallow it)."""


def _on_alarm(signum: int, frame: object) -> None:
    raise InputTimeout()


def innermost_fsmbt_frame(exc: BaseException) -> str:
    """``module.py:line`` of the deepest traceback frame inside fsmbt (the cause's place)."""
    place = "?"
    for frame in traceback.extract_tb(exc.__traceback__):
        if "/fsmbt/" in frame.filename.replace(os.sep, "/"):
            place = f"{Path(frame.filename).name}:{frame.lineno}"
    return place


def check_input(reader: str, data: bytes, path: Path) -> tuple[str, str] | None:
    """Read ``data`` as ``reader``; ``None`` if the outcome is allowed, else (kind, cause).

    Shared by the fuzz worker and the regression tests, so both apply the same rule.
    """
    from fsmbt.formats.registry import decode, loads
    from fsmbt.model.bt import BTDocument
    from fsmbt.model.errors import InputError
    from fsmbt.model.fsm import FSM

    try:
        model = loads(decode(data, str(path)), reader, path=path)
    except InputError as exc:
        message = str(exc)
        if "\n" in message.strip() or "\r" in message.strip():
            return "crash", f"multi-line error message: {message[:200]!r}"
        if exc.location is None or not exc.location.file:
            return "crash", f"error without a location: {message[:200]!r}"
        if not exc.message.strip():
            return "crash", f"error without a cause: {message[:200]!r}"
        return None
    except RecursionError as exc:
        return "crash", f"RecursionError at {innermost_fsmbt_frame(exc)}"
    except MemoryError as exc:
        return "memory", f"MemoryError at {innermost_fsmbt_frame(exc)}"
    except Exception as exc:  # noqa: BLE001 - every other exception is the finding
        return "crash", (f"{type(exc).__name__} at {innermost_fsmbt_frame(exc)}: {str(exc)[:200]}")
    if not isinstance(model, (FSM, BTDocument)):
        return "crash", f"reader returned {type(model).__name__}, not a model"
    return None


def worker_main(args: argparse.Namespace) -> int:
    import atheris

    cap = args.memory_mb * 1024 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
    sys.setrecursionlimit(10_000)  # what a user's interpreter may have; readers must not recurse

    with atheris.instrument_imports(include=["fsmbt"]):
        from fsmbt.formats import registry

        registry.formats()  # imports (and so instruments) every format module
        import_plugins(args.imports)
        import fsmbt.model.bt  # noqa: F401
        import fsmbt.model.fsm  # noqa: F401

    fake_dir = Path(tempfile.mkdtemp(prefix="fsmbt-fuzz-"))
    extension = registry.get_format(args.reader).extensions[0]
    fake_path = fake_dir / f"input{extension}"
    regressions = Path(args.regressions) / args.reader
    status_path = Path(args.status)
    counts = {"iterations": 0, "crashes": 0, "timeouts": 0, "memory": 0}
    saved: list[str] = []
    causes_seen: set[str] = set()
    signal.signal(signal.SIGPROF, _on_alarm)

    def write_status() -> None:
        tmp = status_path.with_suffix(".tmp")
        tmp.write_text(json.dumps({**counts, "saved": saved}), encoding="utf-8")
        tmp.replace(status_path)

    def one_input(data: bytes) -> None:
        counts["iterations"] += 1
        signal.setitimer(signal.ITIMER_PROF, args.timeout_per_input)
        try:
            outcome = check_input(args.reader, data, fake_path)
        except InputTimeout:
            outcome = ("timeout", f"no answer within {args.timeout_per_input} s of CPU")
        finally:
            signal.setitimer(signal.ITIMER_PROF, 0)
        if outcome is not None:
            kind, cause = outcome
            counts[{"crash": "crashes", "timeout": "timeouts", "memory": "memory"}[kind]] += 1
            key = f"{kind}:{cause.split(':', 2)[:2]}"
            if key not in causes_seen and len(causes_seen) < 50:
                causes_seen.add(key)
                saved.append(str(save_finding(regressions, kind, data, cause)))
                print(f"FINDING {args.reader} {kind}: {cause}", file=sys.stderr)
        if counts["iterations"] % 500 == 0 or counts["iterations"] >= args.iterations:
            write_status()

    write_status()
    atheris.Setup(
        [
            sys.argv[0],
            f"-runs={args.iterations}",
            f"-seed={args.seed}",
            f"-timeout={args.hard_timeout}",
            f"-rss_limit_mb={args.memory_mb}",
            f"-max_len={args.max_len}",
            f"-artifact_prefix={args.artifacts}/",
            "-print_final_stats=1",
            *([f"-dict={args.dict}"] if args.dict else []),
            *(["-use_value_profile=1"] if args.value_profile else []),
            *args.dirs,
        ],
        one_input,
    )
    atheris.Fuzz()
    return 0


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--iterations", type=int, default=10_000, help="inputs per reader")
    parser.add_argument("--reader", default="all", help="a format name, or 'all'")
    parser.add_argument(
        "--seed", type=int, default=1, help="libFuzzer seed (batches derive theirs from it)"
    )
    parser.add_argument(
        "--timeout-per-input",
        type=float,
        default=2.0,
        help="CPU seconds one input may take (soft alarm)",
    )
    parser.add_argument(
        "--hard-timeout",
        type=int,
        default=20,
        help="wall seconds before libFuzzer kills the worker",
    )
    parser.add_argument("--memory-mb", type=int, default=2048, help="address-space cap")
    parser.add_argument("--max-len", type=int, default=16384, help="largest input in bytes")
    parser.add_argument("--batch", type=int, default=50_000, help="inputs per worker")
    parser.add_argument(
        "--work-dir",
        default=str(DEFAULT_WORK_DIR),
        help="working corpus and seeds (kept between runs)",
    )
    parser.add_argument(
        "--regressions", default=str(DEFAULT_REGRESSIONS), help="where finding inputs are saved"
    )
    parser.add_argument("--json", help="also write the figures to this JSON file")
    parser.add_argument(
        "--value-profile",
        action="store_true",
        help="libFuzzer -use_value_profile=1 (guides mutations by comparison "
        "operands; slower, finds magic values)",
    )
    parser.add_argument(
        "--import",
        dest="imports",
        action="append",
        default=[],
        metavar="MODULE",
        help="import a module that registers more formats",
    )
    parser.add_argument("--verbose", action="store_true")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--status", help=argparse.SUPPRESS)
    parser.add_argument("--artifacts", help=argparse.SUPPRESS)
    parser.add_argument("--dict", help=argparse.SUPPRESS)
    parser.add_argument("dirs", nargs="*", help=argparse.SUPPRESS)
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    return worker_main(args) if args.worker else parent_main(args)


if __name__ == "__main__":
    sys.exit(main())
