"""FlexBE behaviours as people wrote them: how many of a folder of real behaviour files read and
convert (FSM -> BT, rules engine, verified equivalent by the native checker), and what blocks
the others (issue 26 item 2; docs/corpus.md, "FlexBE behaviours from public robot projects").

The folder holds snapshots of public robot projects' FlexBE behaviour packages (checked out
with ``git --git-dir=SNAPSHOT archive HEAD | tar -x -C FOLDER/<name>``); they are test input
only and are never copied into this repository. A behaviour is a ``*.py`` file that imports
``flexbe_core`` and defines a class deriving from ``Behavior``; each is read with no option,
as a new user runs ``fsmbt convert FILE`` (format detected, embedded behaviours looked up in
the file's own package). Nothing in them is imported or executed.

    .venv/bin/python benchmarks/flexbe_sample.py FOLDER [--budget SECONDS] [--list]

Prints one line per project (behaviours, read, converted), the overall rate, and the remaining
first causes grouped by message (file names and quoted names folded so that one cause is one
line). ``--list`` also prints each failing file with its message. A file still running after
``--budget`` CPU seconds (default 60) counts as "over the budget".
"""

from __future__ import annotations

import argparse
import re
import signal
import sys
from collections import Counter
from pathlib import Path

from fsmbt import api
from fsmbt.model.errors import FsmbtError

_BEHAVIOUR_CLASS = re.compile(r"^\s*class\s+\w+\s*\(\s*(\w+\.)*Behavior\s*\)", re.M)
_QUOTED = re.compile(r"'[^']*'")
_PATHISH = re.compile(r"(/[^\s:]+)+")
_LINE = re.compile(r"line \d+|:\d+(:\d+)?")


class _OverBudget(Exception):
    pass


def behaviour_files(folder: Path) -> list[Path]:
    """Every behaviour file under ``folder`` (imports flexbe_core, defines a Behavior)."""
    out = []
    for path in sorted(folder.rglob("*.py")):
        try:
            head = path.read_text(encoding="utf-8", errors="replace")
        except OSError:
            continue
        if "flexbe_core" in head and _BEHAVIOUR_CLASS.search(head):
            out.append(path)
    return out


def cause(message: str) -> str:
    """The message with names, paths and line numbers folded (one cause, one line)."""
    folded = _PATHISH.sub("<path>", message)
    folded = _QUOTED.sub("'…'", folded)
    folded = _LINE.sub("", folded)
    return folded[:140]


def run(path: Path, budget: int) -> tuple[bool, bool, str, list[str]]:
    """(read, converted and verified, message, the reader's warnings) for one behaviour."""

    def over(_signum: int, _frame: object) -> None:
        raise _OverBudget

    read = False
    warnings: list[str] = []
    previous = signal.signal(signal.SIGPROF, over)
    signal.setitimer(signal.ITIMER_PROF, budget)
    try:
        loaded = api.load(path)
        read = True
        warnings = loaded.warnings
        outcome = api.convert_loaded(loaded)
        signal.setitimer(signal.ITIMER_PROF, 0)
        if outcome.report is not None and not outcome.report.equivalent:
            return read, False, "not equivalent", warnings
        return read, True, "", warnings
    except _OverBudget:
        return read, False, f"over the {budget} s CPU budget", warnings
    except FsmbtError as exc:
        signal.setitimer(signal.ITIMER_PROF, 0)
        return read, False, str(exc), warnings
    except RecursionError:
        signal.setitimer(signal.ITIMER_PROF, 0)
        return read, False, "internal error: RecursionError", warnings
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, previous)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--budget", type=int, default=60)
    parser.add_argument("--list", action="store_true")
    args = parser.parse_args(argv)
    projects = sorted(p for p in args.folder.iterdir() if p.is_dir())
    if not projects:
        print(f"no project folders under {args.folder}", file=sys.stderr)
        return 2
    causes: Counter[str] = Counter()
    failures: list[tuple[Path, str]] = []
    total = read_total = ok_total = 0
    print(
        "| project | behaviours | read | read and convert (verified) | read as Python 2 | "
        "with an embedded behaviour not found (opaque state) |"
    )
    print("|---|---|---|---|---|---|")
    py2_total = opaque_total = 0
    for project in projects:
        files = behaviour_files(project)
        read_count = ok_count = py2_count = opaque_count = 0
        for path in files:
            read, ok, message, warnings = run(path, args.budget)
            read_count += read
            ok_count += ok
            py2_count += any("read as Python 2" in w for w in warnings)
            opaque_count += any("read as one opaque state" in w for w in warnings)
            if not ok:
                causes[cause(message)] += 1
                failures.append((path.relative_to(args.folder), message))
        total += len(files)
        read_total += read_count
        ok_total += ok_count
        py2_total += py2_count
        opaque_total += opaque_count
        print(
            f"| {project.name} | {len(files)} | {read_count} | {ok_count} | {py2_count} | "
            f"{opaque_count} |"
        )

    def rate(n: int) -> str:
        return f"{n}/{total} ({100 * n / total:.1f} %)" if total else "0/0"

    print(
        f"| **all** | {total} | {rate(read_total)} | **{rate(ok_total)}** | {py2_total} | "
        f"{opaque_total} |"
    )
    print()
    print("Remaining causes:")
    print()
    if not causes:
        print("- none")
    for text, count in causes.most_common():
        print(f"- {count} × {text}")
    if args.list:
        print()
        for path, message in failures:
            print(f"{path}: {message}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
