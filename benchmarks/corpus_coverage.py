"""Corpus coverage: how many real files (written by others) convert and verify (prints tables).

Runs ``fsmbt.api.convert_file`` (rules engine, native checker, nothing written) over every file
of the corpus (``FSMBT_CORPUS``, default ``../shared/corpus``): BehaviorTree.CPP XML under
``bt/``, SCXML, SMACH, FlexBE and YASMIN (``fsm/yasmin/*.xml``) under ``fsm/``. Each file is tried in three settings:

- ``no_profiles``: ``--no-profiles`` only: nothing fsmbt would find by itself is applied
  (the figure before issue 26);
- ``plain``: no options, as a new user types ``fsmbt convert FILE -o OUT`` (the profiles and
  node-model files fsmbt finds by itself are applied: docs/semantics.md §10);
- ``profiles``: ``--nodes nav2,moveit_pro`` (the project node libraries; their gating
  controllers are abstractions, named in the verdict), the node-library files of
  node_libraries/ for the trees of their projects (``options_for``) and, for Nav2
  trees, Nav2's model file as ``--node-models``;
- ``abstract``: ``profiles`` plus ``--abstract time,blackboard``.

For the profiles and abstract settings the BehaviorTree.CPP test files (``bt/btcpp``) are read
with ``include_root`` = their source folder (``--include-root``: BT.CPP's test set includes
``../parent_no_include.xml`` from a subfolder). SubTrees naming trees of other files are found
by the reader's folder lookup (docs/formats/btcpp.md), as for a user.

Every BehaviorTree.CPP file is also loaded by BehaviorTree.CPP 4.8.2 itself (behaviortreepy;
``btcpp_loads.py``: every unknown node registered as a dummy of its declared kind): the files the
real engine refuses to load are counted in their own column and listed with the engine's
message, and the BT figure is printed twice - over all well-formed files, and over the files
BehaviorTree.CPP itself loads.

Files under ``_malformed/`` or ``_legacy_draft/`` are negative inputs: they must be refused
(counted apart). A file "converts" when the result is EQUIVALENT. For the others the first
blocker (the error's message, with node names and locations cut out) is tallied.

A file still running after ``--budget`` seconds of CPU time (default 60; the process's own
CPU time, ``ITIMER_PROF``, so a loaded machine does not move the figures) is counted as "over
the budget": its explored state space is too large for that time (it is reported, not hidden).

Run: PYTHONPATH=src python benchmarks/corpus_coverage.py [--setting plain] [--markdown]
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import sys
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import btcpp_loads  # noqa: E402 - the sibling script, importable when run from anywhere

from fsmbt import api  # noqa: E402
from fsmbt.model.errors import InputError  # noqa: E402

SETTINGS = ("no_profiles", "plain", "profiles", "abstract")
KINDS = ("bt", "scxml", "smach", "flexbe", "yasmin")
NEGATIVE_DIRS = ("_malformed", "_legacy_draft")


@dataclass
class Row:
    path: Path
    source: str  # "bt/nav2", "fsm/scion_tests", ...
    kind: str  # "bt", "scxml", "smach", "flexbe", "yasmin"
    negative: bool
    ok: bool
    reason: str
    seconds: float = 0.0
    btcpp_refusal: str | None = None  # BehaviorTree.CPP 4.8.2's own refusal (bt files)


def corpus_root() -> Path:
    return Path(
        os.environ.get(
            "FSMBT_CORPUS", Path(__file__).resolve().parents[1] / ".." / "shared" / "corpus"
        )
    ).resolve()


def corpus_files(root: Path) -> list[tuple[Path, str, str]]:
    """(path, source folder, kind) for every model file of the corpus, sorted."""
    found: list[tuple[Path, str, str]] = []
    for path in sorted(root.rglob("*")):
        if not path.is_file() or "models" in path.parts or "LICENSES" in path.parts:
            continue
        rel = path.relative_to(root)
        if len(rel.parts) < 3:
            continue
        source = "/".join(rel.parts[:2])
        if path.suffix == ".xml" and rel.parts[0] == "bt":
            found.append((path, source, "bt"))
        elif path.suffix == ".xml" and rel.parts[:2] == ("fsm", "yasmin"):
            found.append((path, source, "yasmin"))
        elif path.suffix == ".scxml":
            found.append((path, source, "scxml"))
        elif path.suffix == ".py" and "flexbe" in rel.parts[1]:
            found.append((path, source, "flexbe"))
        elif path.suffix == ".py" and "smach" in rel.parts[1]:
            found.append((path, source, "smach"))
    return found


#: Project node-library files (node_libraries/, docs/semantics.md "Project nodes"):
#: by corpus source folder, and by the file-name prefix of the project a tree comes from.
NODE_LIBRARIES = Path(__file__).resolve().parents[1] / "node_libraries"
LIBRARIES_BY_SOURCE = {"bt/btcpp_tutorials": ("btcpp_tutorials.yaml",)}
LIBRARIES_BY_PREFIX = {
    "IntelligentRoboticsLabs_robocup2020_": ("robocup2020.yaml",),
    "julienbayle_stardust_": ("stardust.yaml",),
    "kmi-robots_hans-ros-supervisor_": ("hans_ros_supervisor.yaml",),
}


def library_files(source: str, path: Path | None) -> list[str]:
    """The node-library files a user of the file's project would pass with ``--nodes``."""
    names = list(LIBRARIES_BY_SOURCE.get(source, ()))
    if path is not None:
        for prefix, files in LIBRARIES_BY_PREFIX.items():
            if path.name.startswith(prefix):
                names += files
    return [str(NODE_LIBRARIES / name) for name in names]


def options_for(
    setting: str, source: str, root: Path, path: Path | None = None
) -> dict[str, object]:
    if setting == "no_profiles":
        return {"no_profiles": True}
    if setting == "plain":
        return {}
    options: dict[str, object] = {"nodes": ["nav2", "moveit_pro", *library_files(source, path)]}
    if source == "bt/nav2":
        options["node_models"] = [str(root / "bt" / "nav2" / "models" / "nav2_tree_nodes.xml")]
    if source == "bt/btcpp":
        options["include_root"] = str(root / source)
    if setting == "abstract":
        options["abstract"] = ["time", "blackboard"]
    return options


_LOCATION = re.compile(r"^\S+?(:\d+(:\d+)?)?: ")
_QUOTED = re.compile(r"'[^']*'")


def reason_of(exc: Exception) -> str:
    """The error's cause without the file location and quoted names (so causes tally)."""
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    text = _LOCATION.sub("", text)
    text = re.sub(r"<[^>]*> ", "", text)
    text = _QUOTED.sub("'…'", text)
    text = re.sub(r"\(and \d+ more.*", "", text)
    return text.strip()[:110]


class _OverBudget(Exception):
    pass


def _alarm(_signum: int, _frame: object) -> None:
    raise _OverBudget


def run_one(path: Path, source: str, kind: str, setting: str, root: Path, budget: int = 0) -> Row:
    """Convert and verify one file; ``budget`` seconds (0: none) before it counts as "over
    the time budget" (a state space too large to explore in that time)."""
    negative = any(part in NEGATIVE_DIRS for part in path.parts)
    if budget:
        signal.signal(signal.SIGPROF, _alarm)
        signal.setitimer(signal.ITIMER_PROF, budget)
    started = time.perf_counter()
    try:
        try:
            outcome = api.convert_file(path, options=options_for(setting, source, root, path))
        finally:
            # the alarm is off before any handler below runs (a run ending at the budget
            # must not raise _OverBudget from inside a handler)
            if budget:
                signal.setitimer(signal.ITIMER_PROF, 0)
        ok = outcome.equivalent is True
        reason = "" if ok else f"verdict {outcome.verdict}"
    except _OverBudget:
        ok, reason = False, f"over the {budget} s CPU budget (state space too large)"
    except InputError as exc:  # UnsupportedError is an InputError
        ok, reason = False, reason_of(exc)
    except Exception as exc:  # noqa: BLE001 - a crash is a finding: count it, never hide it
        ok, reason = False, f"CRASH {type(exc).__name__}: {reason_of(exc)}"
    row = Row(path, source, kind, negative, ok, reason)
    row.seconds = time.perf_counter() - started
    if kind == "bt" and not negative and btcpp_loads.available():
        row.btcpp_refusal = btcpp_loads.refusal(
            path, root / source, options_for(setting, source, root)
        )
    return row


def table(title: str, header: list[str], rows: list[list[object]], markdown: bool) -> str:
    if markdown:
        lines = [
            f"**{title}**",
            "",
            "| " + " | ".join(header) + " |",
            "|" + "|".join("---" for _ in header) + "|",
        ]
        lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
        return "\n".join(lines) + "\n"
    widths = [max(len(str(x)) for x in [h, *(r[i] for r in rows)]) for i, h in enumerate(header)]
    out = [title, "  ".join(h.ljust(w) for h, w in zip(header, widths))]
    out += ["  ".join(str(c).ljust(w) for c, w in zip(r, widths)) for r in rows]
    return "\n".join(out) + "\n"


def share(ok: int, total: int) -> str:
    return f"{ok}/{total} ({100.0 * ok / total:.1f} %)" if total else "0/0"


def _comment_only(path: Path) -> bool:
    """The file is refused by the strict XML parse and read by the BehaviorTree.CPP reader's
    comment leniency (``xml_safe.parse_xml`` with notes)."""
    from fsmbt.formats.xml_safe import parse_xml

    text = path.read_text(encoding="utf-8", errors="replace")
    try:
        parse_xml(text, str(path))
        return False
    except InputError:
        pass
    notes: list[str] = []
    try:
        parse_xml(text, str(path), notes)
    except InputError:
        return False
    return bool(notes)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--setting", choices=SETTINGS, action="append")
    parser.add_argument("--markdown", action="store_true")
    parser.add_argument("--kind", choices=KINDS, action="append")
    parser.add_argument(
        "--budget",
        type=int,
        default=60,
        help="CPU seconds per file before it counts as over budget (0: none)",
    )
    args = parser.parse_args()
    root = corpus_root()
    if not root.is_dir():
        print(f"corpus not found: {root} (set FSMBT_CORPUS)", file=sys.stderr)
        return 2
    files = [f for f in corpus_files(root) if not args.kind or f[2] in args.kind]
    for setting in args.setting or SETTINGS:
        rows = [run_one(p, s, k, setting, root, args.budget) for p, s, k in files]
        positive = [r for r in rows if not r.negative]
        print(f"\n## setting: {setting} ({len(rows)} files, corpus {root})\n")
        by_source: dict[str, list[Row]] = {}
        for r in positive:
            by_source.setdefault(r.source, []).append(r)
        checked = btcpp_loads.available()
        print(
            table(
                "by source (well-formed files)",
                ["source", "files", "convert+verify", "refused by BehaviorTree.CPP itself"],
                [
                    [
                        s,
                        len(rs),
                        share(sum(r.ok for r in rs), len(rs)),
                        sum(r.btcpp_refusal is not None for r in rs)
                        if checked and s.startswith("bt/")
                        else "-",
                    ]
                    for s, rs in sorted(by_source.items())
                ],
                args.markdown,
            )
        )
        reasons = Counter(r.reason for r in positive if not r.ok)
        print(
            table(
                "remaining first blockers (well-formed files)",
                ["files", "reason"],
                [[n, reason] for reason, n in reasons.most_common()],
                args.markdown,
            )
        )
        bt_rows = [r for r in positive if r.kind == "bt"]
        refused_by_engine = [r for r in bt_rows if r.btcpp_refusal is not None]
        if bt_rows and checked:
            print(
                table(
                    "refused by BehaviorTree.CPP itself (4.8.2, unknown nodes as dummies)",
                    ["file", "fsmbt", "BehaviorTree.CPP's message"],
                    [
                        [
                            r.path.relative_to(root),
                            "converts" if r.ok else "refuses",
                            (r.btcpp_refusal or "")[:120],
                        ]
                        for r in refused_by_engine
                    ],
                    args.markdown,
                )
            )
        elif bt_rows:
            print("refused by BehaviorTree.CPP itself: not checked (behaviortreepy missing)")
        for kind in KINDS:
            mine = [r for r in positive if r.kind == kind]
            if mine:
                print(
                    f"{kind}: {share(sum(r.ok for r in mine), len(mine))} well-formed files "
                    "convert and verify"
                )
            if kind == "bt" and mine and checked:
                loadable = [r for r in mine if r.btcpp_refusal is None]
                print(
                    f"bt: {share(sum(r.ok for r in loadable), len(loadable))} of the files "
                    f"BehaviorTree.CPP itself loads convert and verify ({len(refused_by_engine)} "
                    "refused by BehaviorTree.CPP itself)"
                )
        negatives = [r for r in rows if r.negative]
        refused = sum(not r.ok and not r.reason.startswith("CRASH") for r in negatives)
        lenient = [r for r in negatives if r.kind == "bt" and _comment_only(r.path)]
        print(
            f"negative inputs refused with an error: {refused}/{len(negatives)}; "
            f"{len(lenient)} BT file(s) among them are malformed only by '--' inside "
            "comments, which BehaviorTree.CPP's tinyxml2 loads: read with a warning "
            "(docs/formats/btcpp.md)"
        )
        slowest = max(rows, key=lambda r: r.seconds)
        print(
            f"time: {sum(r.seconds for r in rows):.1f} s in all, slowest "
            f"{slowest.seconds:.1f} s ({slowest.path.relative_to(root)})"
        )
        crashes = [r for r in rows if r.reason.startswith("CRASH")]
        for r in crashes:
            print(f"CRASH: {r.path.relative_to(root)}: {r.reason}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
