"""Nav2 trees with ``--nodes nav2``: leaf-machine states (faithful vs canonical) and the time of a whole ``convert`` (issue 12). Prints a table.

    FSMBT_CORPUS=/work/shared/corpus .venv/bin/python benchmarks/bench_nav2.py
        [--all] [--prove] [--minimal] [--limit 300] [FILE ...]

Rows: the two trees of issue 12 (``navigate_to_pose_w_replanning_goal_patience_and_recovery``,
``navigate_w_routing_global_planning_and_control_w_recovery``) from ``$FSMBT_CORPUS/bt/nav2``,
every tree of that folder with ``--all``, or the files given. Each is read as the CLI reads it
(``--nodes nav2 --node-models <corpus>/bt/nav2/models/nav2_tree_nodes.xml``).

Columns:
- ``path``: which leaf machine the tree runs on (``table`` / ``canonical`` / ``faithful``,
  docs/semantics.md §4 and §4a);
- ``faithful``: reachable states of the faithful interpreter's leaf machine
  (``LeafMachine(generic=True)``), the count before the canonical reduction;
- ``canonical``: reachable states of the machine the checker and the converter explore;
- ``minimal`` (``--minimal``): the states of the smallest machine with the same behaviour
  (partition refinement of the canonical machine): how much any further reduction could gain;
- ``convert s`` / ``verify s`` / ``write s``: the steps of ``fsmbt.api.convert_file`` to a
  temporary SCXML file, as ``fsmbt convert FILE -o out.xml`` does (``Outcome.timings``;
  ``write`` is the file write); ``total s``: the whole call (read, convert, the SCXML text,
  verify, write);
- ``method``: what the verdict's proof was (docs/verification.md §6: ``table``,
  ``canonical``, ``compositional``, ``whole product``);
- ``proof`` (``--prove``): the native checker run on the faithful machine against the canonical
  one (every input sequence): ``equal`` or the failing property.
Nothing is written into the repository; a row over ``--limit`` seconds prints ``stopped``.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from fsmbt import api
from fsmbt.model.bt import BTDocument
from fsmbt.semantics.leaf_machine import ExploredMachine, LeafMachine, StateLimitError, explore
from fsmbt.verify import native

ISSUE_12 = (
    "navigate_to_pose_w_replanning_goal_patience_and_recovery.xml",
    "navigate_w_routing_global_planning_and_control_w_recovery.xml",
)
MAX_STATES = 2_000_000


class _Timeout(Exception):
    pass


def _alarm(_signum: int, _frame: object) -> None:
    raise _Timeout


def minimal_states(machine: ExploredMachine[Any]) -> int:
    """States of the minimal machine: Moore partition refinement over (status, per input: the
    outputs and the target's block), iterated until the number of blocks stops growing."""
    index = {state: i for i, state in enumerate(machine.states)}
    block = [0] * len(machine.states)
    count = 1
    while True:
        signatures: dict[tuple[Any, ...], int] = {}
        refined = []
        for state in machine.states:
            moves = tuple(
                (symbol, outputs, block[index[target]])
                for symbol, (target, outputs) in machine.transitions[state].items()
            )
            key = (machine.statuses[state], block[index[state]], moves)
            refined.append(signatures.setdefault(key, len(signatures)))
        if len(signatures) == count:
            return count
        block, count = refined, len(signatures)


def _path(machine: LeafMachine) -> str:
    return "table" if machine.fast else "canonical" if machine.canonical else "faithful"


def run_row(path: Path, options: dict[str, object], args: argparse.Namespace) -> list[str]:
    """One table row for ``path`` (strings, in the header's order)."""
    doc = api.load(path, options=options).model
    assert isinstance(doc, BTDocument)
    cells = [path.stem[:58]]
    machine = LeafMachine(doc)
    cells.append(_path(machine))
    signal.alarm(args.limit)
    try:
        cells.append(str(len(explore(LeafMachine(doc, generic=True), MAX_STATES))))
    except (_Timeout, StateLimitError) as exc:
        cells.append("stopped" if isinstance(exc, _Timeout) else f">{MAX_STATES}")
    signal.alarm(0)
    signal.alarm(args.limit)
    try:
        explored = explore(machine, MAX_STATES)
        cells.append(str(len(explored)))
        cells.append(str(minimal_states(explored)) if args.minimal else "-")
    except (_Timeout, StateLimitError):
        cells.extend(["stopped", "-"])
    signal.alarm(0)
    with tempfile.TemporaryDirectory() as folder:
        signal.alarm(args.limit)
        try:
            started = time.perf_counter()
            outcome = api.convert_file(
                path, Path(folder) / "out.xml", overwrite=True, options=options
            )
            total = time.perf_counter() - started
            timings = outcome.timings
            cells.extend(f"{timings.get(step, 0.0):.1f}" for step in ("convert", "verify", "write"))
            cells.append(f"{total:.1f}")
            cells.append(api.verdict_word(outcome.report))
            cells.append(outcome.report.method if outcome.report is not None else "-")
        except _Timeout:
            cells.extend(["-", "-", "-", f">{args.limit}", "stopped", "-"])
        signal.alarm(0)
    if args.prove and machine.canonical:
        signal.alarm(args.limit)
        try:
            report = native.check(LeafMachine(doc, generic=True), machine, max_states=MAX_STATES)
            failed = [name for name, ok in report.verdicts().items() if not ok]
            cells.append("equal" if report.equivalent else ",".join(failed))
        except _Timeout:
            cells.append("stopped")
        signal.alarm(0)
    else:
        cells.append("-")
    return cells


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", type=Path, help="trees (default: issue 12's two)")
    parser.add_argument("--all", action="store_true", help="every tree of <corpus>/bt/nav2")
    parser.add_argument("--prove", action="store_true", help="check canonical == faithful")
    parser.add_argument("--minimal", action="store_true", help="count the minimal machine")
    parser.add_argument("--limit", type=int, default=300, help="seconds per step")
    args = parser.parse_args(argv)
    repo = Path(__file__).resolve().parents[1]
    root = Path(os.environ.get("FSMBT_CORPUS", repo / ".." / "shared" / "corpus")) / "bt" / "nav2"
    files: list[Path] = list(args.files)
    if not files:
        if not root.is_dir():
            print(f"no corpus at {root} (set FSMBT_CORPUS); nothing to measure")
            return 0
        files = sorted(root.glob("*.xml")) if args.all else [root / name for name in ISSUE_12]
    options: dict[str, object] = {"nodes": ["nav2"]}
    models = root / "models" / "nav2_tree_nodes.xml"
    if models.is_file():
        options["node_models"] = [str(models)]
    signal.signal(signal.SIGALRM, _alarm)
    header = [
        "tree",
        "path",
        "faithful",
        "canonical",
        "minimal",
        "convert s",
        "verify s",
        "write s",
        "total s",
        "verdict",
        "method",
        "proof",
    ]
    widths = [58, 9, 9, 9, 8, 9, 8, 7, 8, 14, 13, 6]
    print(
        " ".join(
            h.ljust(w) if i < 2 else h.rjust(w) for i, (h, w) in enumerate(zip(header, widths))
        )
    )
    print("-" * (sum(widths) + len(widths) - 1))
    for path in files:
        try:
            cells = run_row(path, options, args)
        except Exception as exc:  # a tree fsmbt refuses: the reason, not a traceback
            print(f"{path.stem[:58]:<58} refused: {type(exc).__name__}: {exc}", flush=True)
            continue
        print(
            " ".join(
                c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(cells, widths))
            ),
            flush=True,
        )
    print(
        "faithful = LeafMachine(generic=True) states; canonical = the states the converter and "
        "the checker explore (docs/semantics.md §4a); times: fsmbt.api.convert_file's steps"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
